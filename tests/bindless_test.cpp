// Descriptor indexing ("bindless"): binding flags, update-after-bind pools,
// variable-count sets and array writes at an offset.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/bindless.comp.h"

#include <span>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

constexpr VkDescriptorBindingFlags bindless_flags =
    VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT | VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT |
    VK_DESCRIPTOR_BINDING_UPDATE_UNUSED_WHILE_PENDING_BIT | VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT;
constexpr std::uint32_t max_textures = 1024;

// The descriptor indexing features the tests use that the device lacks.
std::string missing_bindless_features(const vkrc::PhysicalDevice& physical) {
    const auto f = vkrc_test::supported_features(physical).v12;
    return vkrc_test::missing_features({
        {"runtimeDescriptorArray", f.runtimeDescriptorArray},
        {"shaderSampledImageArrayNonUniformIndexing", f.shaderSampledImageArrayNonUniformIndexing},
        {"descriptorBindingPartiallyBound", f.descriptorBindingPartiallyBound},
        {"descriptorBindingSampledImageUpdateAfterBind", f.descriptorBindingSampledImageUpdateAfterBind},
        {"descriptorBindingUpdateUnusedWhilePending", f.descriptorBindingUpdateUnusedWhilePending},
        {"descriptorBindingVariableDescriptorCount", f.descriptorBindingVariableDescriptorCount},
    });
}

vkrc::Device bindless_device(const vkrc::PhysicalDevice& physical) {
    vkrc::DeviceCreateInfo info;
    info.vulkan12_features.runtimeDescriptorArray = VK_TRUE;
    info.vulkan12_features.shaderSampledImageArrayNonUniformIndexing = VK_TRUE;
    info.vulkan12_features.descriptorBindingPartiallyBound = VK_TRUE;
    info.vulkan12_features.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
    info.vulkan12_features.descriptorBindingUpdateUnusedWhilePending = VK_TRUE;
    info.vulkan12_features.descriptorBindingVariableDescriptorCount = VK_TRUE;
    return vkrc::Device::create(physical, info);
}

// Output buffer, sampler, and a large bindless array of sampled images last.
vkrc::DescriptorSetLayout bindless_layout(const vkrc::Device& device) {
    return vkrc::DescriptorSetLayout::create(
        device,
        {.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT,
         .bindings = {
             {.binding = 0,
              .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
              .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT},
             {.binding = 1, .descriptor_type = VK_DESCRIPTOR_TYPE_SAMPLER, .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT},
             {.binding = 2,
              .descriptor_type = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
              .descriptor_count = max_textures,
              .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT,
              .binding_flags = bindless_flags}}});
}

vkrc::DescriptorPool bindless_pool(const vkrc::Device& device) {
    return vkrc::DescriptorPool::create(device, {.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT |
                                                          VK_DESCRIPTOR_POOL_CREATE_UPDATE_AFTER_BIND_BIT,
                                                 .max_sets = 1,
                                                 .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1},
                                                                {VK_DESCRIPTOR_TYPE_SAMPLER, 1},
                                                                {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 64}}});
}

// A 1x1 R32_UINT texture holding value, cleared and made shader-readable by cmd.
vkrc::Image uint_texture(const vkrc::Device& device, const vkrc::CommandBuffer& cmd, std::uint32_t value) {
    return vkrc_test::uint_image(device, cmd, value, VK_IMAGE_USAGE_SAMPLED_BIT,
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

// shaders/bindless.comp bound to a variable-count set of 64 textures whose
// output buffer and sampler are written; the textures are the test's.
struct BindlessCompute {
    explicit BindlessCompute(const vkrc::Device& device)
        : set_layout(bindless_layout(device)),
          pipeline(vkrc::ComputePipeline::create(vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}}),
                                                 vkrc::ShaderModule::create(device, vkrc_shaders::bindless_comp))),
          pool(bindless_pool(device)),
          set(pool.allocate(set_layout, 64)),
          out(vkrc::Buffer::create(device, {.size = 8 * sizeof(std::uint32_t),
                                            .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                            .memory = {.usage = vkrc::MemoryUsage::readback}})) {
        const auto nearest = vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST,
                                                            .min_filter = VK_FILTER_NEAREST,
                                                            .mipmap_mode = VK_SAMPLER_MIPMAP_MODE_NEAREST});
        set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
        set.write_image(1, VK_DESCRIPTOR_TYPE_SAMPLER, vkrc::ImageView{}, VK_IMAGE_LAYOUT_UNDEFINED, nearest);
    }
    // Binds the set and dispatches, then makes the output visible to the host.
    void record(const vkrc::CommandBuffer& cmd) const {
        cmd.bind_pipeline(pipeline);
        cmd.bind_descriptor_set(pipeline, 0, set);
        cmd.dispatch(1);
        const auto to_host = vkrc_test::compute_to_host();
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    }
    // What each of the 8 invocations read.
    std::vector<std::uint32_t> results() const {
        std::vector<std::uint32_t> data(8);
        out.allocation().read(0, std::span(data));
        return data;
    }

    vkrc::DescriptorSetLayout set_layout;
    vkrc::ComputePipeline pipeline;
    vkrc::DescriptorPool pool;
    vkrc::DescriptorSet set;
    vkrc::Buffer out;
};

// A variable-count set of 64 textures, 8 of them written in one call at
// array element 10 after the set was bound (update after bind); the shader
// picks them with a non-uniform index.
TEST_F(VulkanTest, BindlessArrayIndexedNonUniformly) {
    if (auto missing = missing_bindless_features(physical_device); !missing.empty())
        GTEST_SKIP() << "the device lacks descriptor indexing features: " << missing;
    device = bindless_device(physical_device);
    queue = device.default_queue();
    const BindlessCompute compute(device);

    vkrc_test::OneShotCommands s(queue);
    std::vector<vkrc::Image> textures;
    std::vector<vkrc::ImageView> views;
    for (std::uint32_t k = 0; k < 8; ++k) {
        textures.push_back(uint_texture(device, s.cmd, 100 + k));
        views.push_back(vkrc::ImageView::create(textures.back()));
    }
    compute.record(s.cmd);

    std::vector<VkDescriptorImageInfo> infos;
    for (const auto& view : views)
        infos.push_back({VK_NULL_HANDLE, view.vk(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    compute.set.write_images(2, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, infos, 10);
    s.run(queue);

    const auto data = compute.results();
    for (std::uint32_t i = 0; i < 8; ++i) EXPECT_EQ(data[i], 100 + (i * 3) % 8) << "invocation " << i;
}

// An update-after-bind write of textures made after the command buffer's
// end() and dropped before its submission (issue 33's never-tested
// scenario): the set keeps what was written into it, so the GPU, held back
// behind a gate until after the drop, still samples them.
TEST_F(VulkanTest, BindlessWriteAfterEndOfObjectsDroppedBeforeSubmit) {
    if (auto missing = missing_bindless_features(physical_device); !missing.empty())
        GTEST_SKIP() << "the device lacks descriptor indexing features: " << missing;
    device = bindless_device(physical_device);
    queue = device.default_queue();
    const BindlessCompute compute(device);

    auto cmd_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = cmd_pool.allocate();
    cmd.begin();
    compute.record(cmd);
    cmd.end();
    {
        vkrc_test::OneShotCommands clear(queue);
        std::vector<vkrc::Image> textures;
        std::vector<vkrc::ImageView> views;
        std::vector<VkDescriptorImageInfo> infos;
        for (std::uint32_t k = 0; k < 8; ++k) {
            textures.push_back(uint_texture(device, clear.cmd, 200 + k));
            views.push_back(vkrc::ImageView::create(textures.back()));
            infos.push_back({VK_NULL_HANDLE, views.back().vk(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
        }
        clear.run(queue);
        compute.set.write_images(2, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, infos, 10);
    }  // the textures and their views dropped: only the set holds them
    const vkrc_test::GpuGate gate(device);
    auto fence = vkrc::Fence::create(device);
    gate.submit(queue, cmd, fence);
    EXPECT_EQ(fence.status(), VK_NOT_READY);
    gate.open();
    ASSERT_EQ(fence.wait(), VK_SUCCESS);

    const auto data = compute.results();
    for (std::uint32_t i = 0; i < 8; ++i) EXPECT_EQ(data[i], 200 + (i * 3) % 8) << "invocation " << i;
}

TEST_F(VulkanTest, BindlessMisuseIsAUsageError) {
    if (auto missing = missing_bindless_features(physical_device); !missing.empty())
        GTEST_SKIP() << "the device lacks descriptor indexing features: " << missing;
    device = bindless_device(physical_device);
    queue = device.default_queue();
    const vkrc::DescriptorSetLayoutBinding textures{.binding = 2,
                                                    .descriptor_type = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
                                                    .descriptor_count = max_textures,
                                                    .binding_flags = bindless_flags};
    EXPECT_THROW(vkrc::DescriptorSetLayout::create(device, {.bindings = {textures}}), vkrc::UsageError)
        << "UPDATE_AFTER_BIND without UPDATE_AFTER_BIND_POOL";
    auto variable_first = textures;
    variable_first.binding_flags = VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT;
    EXPECT_THROW(
        vkrc::DescriptorSetLayout::create(
            device, {.bindings = {variable_first, {.binding = 3, .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}}),
        vkrc::UsageError)
        << "VARIABLE_DESCRIPTOR_COUNT on a binding below the highest";

    auto set_layout = bindless_layout(device);
    auto pool = bindless_pool(device);
    EXPECT_THROW(pool.allocate(set_layout, max_textures + 1), vkrc::UsageError);
    auto plain = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    EXPECT_THROW(pool.allocate(plain, 4), vkrc::UsageError) << "a variable count for a layout without one";

    auto set = pool.allocate(set_layout, 16);
    const std::vector<VkDescriptorImageInfo> four(4, {VK_NULL_HANDLE, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED});
    try {
        set.write_images(2, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, four, 14);
        ADD_FAILURE() << "a write past the set's variable count did not throw";
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("array elements 14 to 17 are past binding 2's 16 descriptors"),
                  std::string::npos)
            << e.what();
    }
}

// A dropped variable-count set is handed out again only for its own count.
TEST_F(VulkanTest, DroppedVariableCountSetsAreReusedForTheirCount) {
    if (auto missing = missing_bindless_features(physical_device); !missing.empty())
        GTEST_SKIP() << "the device lacks descriptor indexing features: " << missing;
    device = bindless_device(physical_device);
    queue = device.default_queue();
    auto set_layout = bindless_layout(device);
    auto pool = bindless_pool(device);
    vkrc_test::CountSetCalls calls(device);
    const VkDescriptorSet sixteen = pool.allocate(set_layout, 16).vk();
    EXPECT_NE(pool.allocate(set_layout, 32).vk(), sixteen);
    EXPECT_EQ(pool.allocate(set_layout, 16).vk(), sixteen);
    EXPECT_EQ(calls.allocated(), 2);
}

}  // namespace
