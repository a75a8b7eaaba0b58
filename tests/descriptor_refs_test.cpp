// Descriptor references (issue 30): a descriptor set keeps alive what is
// written into it, whichever way it was written, and releases it, through
// deferred destruction, when the descriptor is overwritten or the set is
// freed, reset or dropped.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/descriptor_types.comp.h"
#include "shaders/descriptor_types.frag.h"
#include "shaders/fullscreen.vert.h"

#include <span>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

// A host-written buffer holding value.
vkrc::Buffer value_buffer(const vkrc::Device& device, VkBufferUsageFlags usage, std::uint32_t value) {
    auto buffer =
        vkrc::Buffer::create(device, {.size = 256, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::upload}});
    buffer.allocation().write_value(0, value);
    return buffer;
}

vkrc::Buffer readback_buffer(const vkrc::Device& device, VkDeviceSize size) {
    return vkrc::Buffer::create(device, {.size = size,
                                         .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                         .memory = {.usage = vkrc::MemoryUsage::readback}});
}

using vkrc_test::uint_image;

vkrc::Sampler nearest_sampler(const vkrc::Device& device) {
    return vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST,
                                          .min_filter = VK_FILTER_NEAREST,
                                          .mipmap_mode = VK_SAMPLER_MIPMAP_MODE_NEAREST});
}

// The layout of shaders/descriptor_types.comp (.frag with input_attachment):
// one binding per descriptor type, the output, then the input attachment.
vkrc::DescriptorSetLayout every_type_layout(const vkrc::Device& device,
                                            VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT,
                                            bool input_attachment = false) {
    const VkDescriptorType types[] = {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
                                      VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                      VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC,
                                      VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC,
                                      VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
                                      VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
                                      VK_DESCRIPTOR_TYPE_SAMPLER,
                                      VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
                                      VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                      VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
                                      VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    vkrc::DescriptorSetLayoutCreateInfo info;
    for (std::uint32_t b = 0; b < std::size(types); ++b)
        info.bindings.push_back({.binding = b, .descriptor_type = types[b], .stage_flags = stages});
    if (input_attachment)
        info.bindings.push_back(
            {.binding = 11, .descriptor_type = VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT, .stage_flags = stages});
    return vkrc::DescriptorSetLayout::create(device, info);
}

vkrc::DescriptorPool every_type_pool(const vkrc::Device& device, std::uint32_t sets) {
    vkrc::DescriptorPoolCreateInfo info{.max_sets = sets};
    for (VkDescriptorType t :
         {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
          VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC,
          VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_SAMPLER,
          VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
          VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT})
        info.pool_sizes.push_back({t, 2 * sets});
    return vkrc::DescriptorPool::create(device, info);
}

// Submits cmd behind a wait on gate's value 1, which only the host signals:
// the work is really in flight (not started) until gate.signal(1).
void submit_gated(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd, const vkrc::Semaphore& gate,
                  const vkrc::Fence& fence) {
    const vkrc::SemaphoreSubmit wait(gate, 1);
    vkrc::submit(queue, {.waits = std::span(&wait, 1), .command_buffers = std::span(&cmd, 1)}, fence);
}

// Writes bindings 0 to 10 of an every_type_layout set (values 100 to 109,
// skipping 106: the sampler reads the sampled image), each object's last
// handle dropped right after its write: the set alone keeps them.
void write_every_type_and_drop(const vkrc::Device& device, const vkrc::Queue& queue, const vkrc::DescriptorSet& set,
                               const vkrc::Buffer& out) {
    vkrc_test::OneShotCommands prepare(queue);
    auto sampled =
        uint_image(device, prepare.cmd, 107, VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    auto combined =
        uint_image(device, prepare.cmd, 108, VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    auto storage = uint_image(device, prepare.cmd, 109, VK_IMAGE_USAGE_STORAGE_BIT, VK_IMAGE_LAYOUT_GENERAL);
    prepare.run(queue);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
                     value_buffer(device, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 100));
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                     value_buffer(device, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 101));
    // The raw-handle forms, of objects vkrc made: found by handle, counted the same.
    {
        auto dynamic_uniform = value_buffer(device, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 102);
        set.write_buffer(2, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, dynamic_uniform.vk(), 0, 16);
        auto dynamic_storage = value_buffer(device, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 103);
        const VkDescriptorBufferInfo info{dynamic_storage.vk(), 0, 16};
        set.write_buffers(3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC, std::span(&info, 1));
    }
    set.write_buffer_view(4, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
                          vkrc::BufferView::create(value_buffer(device, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT, 104),
                                                   {.format = VK_FORMAT_R32_UINT}));
    {
        auto view = vkrc::BufferView::create(value_buffer(device, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT, 105),
                                             {.format = VK_FORMAT_R32_UINT});
        const VkBufferView raw = view.vk();
        set.write_buffer_views(5, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, std::span(&raw, 1));
    }
    set.write_image(6, VK_DESCRIPTOR_TYPE_SAMPLER, vkrc::ImageView{}, VK_IMAGE_LAYOUT_UNDEFINED,
                    nearest_sampler(device));
    set.write_image(7, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, vkrc::ImageView::create(sampled),
                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    {
        auto view = vkrc::ImageView::create(combined);
        auto sampler = nearest_sampler(device);
        const VkDescriptorImageInfo info{sampler.vk(), view.vk(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
        set.write_images(8, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, std::span(&info, 1));
        EXPECT_EQ(view.use_count(), 2u) << "the set keeps the view written by raw handle";
        EXPECT_EQ(sampler.use_count(), 2u) << "and its sampler";
    }
    set.write_image(9, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, vkrc::ImageView::create(storage), VK_IMAGE_LAYOUT_GENERAL);
    set.write_buffer(10, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
    device.collect_garbage();
}

void expect_every_value(const vkrc::Buffer& out, std::uint32_t count) {
    std::uint32_t data[10] = {};
    out.allocation().read(0, data, count);
    const std::uint32_t expected[10] = {100, 101, 102, 103, 104, 105, 107, 108, 109, 110};
    for (std::uint32_t i = 0; i < count; ++i) EXPECT_EQ(data[i], expected[i]) << "binding " << i;
}

// Every descriptor type a compute shader reads, each object dropped after
// its write and before any command buffer records the set.
TEST_F(VulkanTest, EveryDescriptorTypeDroppedAfterTheWriteIsStillRead) {
    auto set_layout = every_type_layout(device);
    auto layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::descriptor_types_comp));
    auto pool = every_type_pool(device, 1);
    auto set = pool.allocate(set_layout);
    auto out = readback_buffer(device, 9 * sizeof(std::uint32_t));
    write_every_type_and_drop(device, queue, set, out);
    vkrc_test::OneShotCommands use(queue);
    use.cmd.bind_pipeline(pipeline);
    const std::uint32_t offsets[] = {0, 0};
    use.cmd.bind_descriptor_set(pipeline, 0, set, offsets);
    use.cmd.dispatch(1);
    const auto to_host = vkrc_test::compute_to_host();
    use.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    use.run(queue);
    expect_every_value(out, 9);
}

// The same from a fragment shader, plus an input attachment (which the
// framebuffer holds too): one fragment reads them all.
TEST_F(VulkanTest, EveryDescriptorTypeDroppedAfterTheWriteIsStillReadByAFragmentShader) {
    if (!vkrc_test::supported_features(physical_device).core.features.fragmentStoresAndAtomics)
        GTEST_SKIP() << "the device lacks fragmentStoresAndAtomics";
    vkrc::DeviceCreateInfo info;
    info.enabled_features.fragmentStoresAndAtomics = VK_TRUE;
    device = vkrc::Device::create(physical_device, info);
    queue = device.default_queue();
    auto set_layout = every_type_layout(device, VK_SHADER_STAGE_FRAGMENT_BIT, true);
    auto pool = every_type_pool(device, 1);
    auto set = pool.allocate(set_layout);
    auto out = readback_buffer(device, 10 * sizeof(std::uint32_t));
    write_every_type_and_drop(device, queue, set, out);
    VkAttachmentDescription input{0,
                                  VK_FORMAT_R32_UINT,
                                  VK_SAMPLE_COUNT_1_BIT,
                                  VK_ATTACHMENT_LOAD_OP_LOAD,
                                  VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                  VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                  VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    auto render_pass = vkrc::RenderPass::create(
        device, {.attachments = {input},
                 .subpasses = {{.input_attachments = {{0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}}}}});
    vkrc::Framebuffer framebuffer;
    {
        vkrc_test::OneShotCommands prepare(queue);
        auto image = uint_image(device, prepare.cmd, 110, VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT,
                                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        prepare.run(queue);
        auto view = vkrc::ImageView::create(image);
        set.write_image(11, VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        framebuffer = vkrc::Framebuffer::create(
            device, {.render_pass = render_pass, .attachments = {view}, .width = 1, .height = 1});
    }
    auto layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::fullscreen_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT,
                    vkrc::ShaderModule::create(device, vkrc_shaders::descriptor_types_frag))
            .cull_mode(VK_CULL_MODE_NONE)  // the full-viewport triangle is clockwise
            .render_pass(render_pass)
            .build();
    vkrc_test::OneShotCommands use(queue);
    use.cmd.begin_render_pass(render_pass, framebuffer, {{0, 0}, {1, 1}}, {});
    use.cmd.bind_pipeline(pipeline);
    use.cmd.set_viewport_and_scissor(framebuffer.extent());
    const std::uint32_t offsets[] = {0, 0};
    use.cmd.bind_descriptor_set(pipeline, 0, set, offsets);
    use.cmd.draw(3);
    use.cmd.end_render_pass();
    const auto to_host =
        vkrc::memory_barrier(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    use.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    use.run(queue);
    expect_every_value(out, 10);
}

// Overwriting a descriptor releases the old object as a drop does: while
// submitted work still reads it (here a copy, held back by a gate), its
// destruction waits; the validation layer reports a buffer destroyed in use.
TEST_F(VulkanTest, OverwritingADescriptorWhileItsObjectIsInFlightWaitsForTheGpu) {
    auto set_layout = every_type_layout(device);
    auto pool = every_type_pool(device, 1);
    auto set = pool.allocate(set_layout);
    auto out = readback_buffer(device, 16);
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto fence = vkrc::Fence::create(device);
    auto command_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = command_pool.allocate();
    {
        auto old_buffer =
            value_buffer(device, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, 7);
        set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, old_buffer);
        cmd.begin();
        const VkBufferCopy region{0, 0, 4};
        cmd.copy_buffer(old_buffer, out, std::span(&region, 1));
        cmd.end();
        submit_gated(queue, cmd, gate, fence);
    }
    const std::size_t before = device.deferred_count();
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, value_buffer(device, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 8));
    EXPECT_GE(device.deferred_count(), before + 1) << "the overwritten buffer waits for the gated copy";
    gate.signal(1);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    std::uint32_t value = 0;
    out.allocation().read(0, &value, 1);
    EXPECT_EQ(value, 7u);
}

// Dropping or freeing a set, and resetting its pool, release what it holds
// the same way: while gated work reads the objects, nothing is destroyed;
// after the gate opens the results are those of the dropped objects.
class SetReleaseInFlight : public VulkanTest, public ::testing::WithParamInterface<int> {};

TEST_P(SetReleaseInFlight, ReleasesThroughDeferredDestruction) {
    const int how = GetParam();  // 0: drop the set, 1: reset its pool
    auto set_layout = every_type_layout(device);
    auto layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::descriptor_types_comp));
    auto pool = every_type_pool(device, 2);
    auto out = readback_buffer(device, 9 * sizeof(std::uint32_t));
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto fence = vkrc::Fence::create(device);
    auto command_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = command_pool.allocate();
    {
        auto set = pool.allocate(set_layout);
        vkrc_test::OneShotCommands prepare(queue);
        auto sampled =
            uint_image(device, prepare.cmd, 7, VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        auto storage = uint_image(device, prepare.cmd, 9, VK_IMAGE_USAGE_STORAGE_BIT, VK_IMAGE_LAYOUT_GENERAL);
        prepare.run(queue);
        for (std::uint32_t b = 0; b < 4; ++b) {
            const VkDescriptorType types[] = {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                              VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC,
                                              VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC};
            const VkBufferUsageFlags usage =
                b % 2 ? VK_BUFFER_USAGE_STORAGE_BUFFER_BIT : VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
            set.write_buffer(b, types[b], value_buffer(device, usage, 10 + b), 0, 16);
        }
        set.write_buffer_view(
            4, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
            vkrc::BufferView::create(value_buffer(device, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT, 14),
                                     {.format = VK_FORMAT_R32_UINT}));
        set.write_buffer_view(
            5, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
            vkrc::BufferView::create(value_buffer(device, VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT, 15),
                                     {.format = VK_FORMAT_R32_UINT}));
        auto view = vkrc::ImageView::create(sampled);
        set.write_image(6, VK_DESCRIPTOR_TYPE_SAMPLER, vkrc::ImageView{}, VK_IMAGE_LAYOUT_UNDEFINED,
                        nearest_sampler(device));
        set.write_image(7, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        set.write_image(8, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                        nearest_sampler(device));
        set.write_image(9, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, vkrc::ImageView::create(storage), VK_IMAGE_LAYOUT_GENERAL);
        set.write_buffer(10, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
        cmd.begin();
        cmd.bind_pipeline(pipeline);
        const std::uint32_t offsets[] = {0, 0};
        cmd.bind_descriptor_set(pipeline, 0, set, offsets);
        cmd.dispatch(1);
        const auto to_host = vkrc_test::compute_to_host();
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
        cmd.end();
        submit_gated(queue, cmd, gate, fence);
        if (how == 1) {
            // vkResetDescriptorPool needs the pool's sets out of use: reset a
            // second pool whose set holds the same objects.
            auto other_pool = every_type_pool(device, 1);
            auto other = other_pool.allocate(set_layout);
            other.write_image(7, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            view.reset();
            set.reset();
            EXPECT_EQ(other.state()->refs.empty(), false);
            other_pool.reset_sets();
            EXPECT_TRUE(other.state()->refs.empty()) << "reset_sets released the set's references";
            EXPECT_THROW(other.write_image(7, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, vkrc::ImageView{},
                                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL),
                         vkrc::UsageError)
                << "a write to a set invalidated by reset_sets";
        }
    }
    EXPECT_GT(device.deferred_count(), 0u) << "the dropped objects wait for the gated dispatch";
    EXPECT_EQ(pool.pending_free_count(), 1u) << "the dropped set waits too";
    gate.signal(1);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    std::uint32_t data[9] = {};
    out.allocation().read(0, data, 9);
    const std::uint32_t expected[9] = {10, 11, 12, 13, 14, 15, 7, 7, 9};
    for (std::uint32_t i = 0; i < 9; ++i) EXPECT_EQ(data[i], expected[i]) << "binding " << i;
    device.wait_idle();
    EXPECT_EQ(device.deferred_count(), 0u);
}

INSTANTIATE_TEST_SUITE_P(DescriptorRefs, SetReleaseInFlight, ::testing::Values(0, 1), [](const auto& info) {
    return info.param == 0 ? std::string("DropSet") : std::string("ResetPool");
});

// Every write form counts its objects once, and an overwrite gives the old one back.
TEST_F(VulkanTest, EveryWriteFormCountsAndOverwritesRelease) {
    auto set_layout = every_type_layout(device);
    auto pool = every_type_pool(device, 1);
    auto set = pool.allocate(set_layout);
    auto a = value_buffer(device, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1);
    auto b = value_buffer(device, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 2);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, a);
    EXPECT_EQ(a.use_count(), 2u);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, b.vk());
    EXPECT_EQ(a.use_count(), 1u) << "the overwrite released a";
    EXPECT_EQ(b.use_count(), 2u);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, b);
    EXPECT_EQ(b.use_count(), 2u) << "the same object again: still one reference";

    // A raw handle vkrc did not make keeps its documented contract: it is
    // written, not counted (and what the descriptor held is released).
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = 256;
    ci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer raw = VK_NULL_HANDLE;
    ASSERT_EQ(device.fn().vkCreateBuffer(device.vk(), &ci, nullptr, &raw), VK_SUCCESS);
    VkMemoryRequirements requirements;
    device.fn().vkGetBufferMemoryRequirements(device.vk(), raw, &requirements);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = requirements.size;
    ai.memoryTypeIndex = static_cast<std::uint32_t>(__builtin_ctz(requirements.memoryTypeBits));
    VkDeviceMemory memory = VK_NULL_HANDLE;
    ASSERT_EQ(device.fn().vkAllocateMemory(device.vk(), &ai, nullptr, &memory), VK_SUCCESS);
    ASSERT_EQ(device.fn().vkBindBufferMemory(device.vk(), raw, memory, 0), VK_SUCCESS);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, raw);
    EXPECT_EQ(b.use_count(), 1u);
    // Adopted, the same handle is vkrc's: counted.
    auto borrowed = vkrc::Buffer::adopt(device, raw, 256, ci.usage, vkrc::Ownership::borrowed);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, raw);
    EXPECT_EQ(borrowed.use_count(), 2u);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, a);
    EXPECT_EQ(borrowed.use_count(), 1u);

    // Update templates count from their entries.
    auto update_template = vkrc::DescriptorUpdateTemplate::create(
        device, {.entries = {{1, 0, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 0, sizeof(VkDescriptorBufferInfo)},
                             {8, 0, 1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, sizeof(VkDescriptorBufferInfo), 0}},
                 .descriptor_set_layout = set_layout});
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R32_UINT, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto view = vkrc::ImageView::create(image);
    auto sampler = nearest_sampler(device);
    struct {
        VkDescriptorBufferInfo buffer;
        VkDescriptorImageInfo image;
    } data{{b.vk(), 0, VK_WHOLE_SIZE}, {sampler.vk(), view.vk(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}};
    set.update_with_template(update_template, &data);
    EXPECT_EQ(a.use_count(), 1u);
    EXPECT_EQ(b.use_count(), 2u);
    EXPECT_EQ(view.use_count(), 2u);
    EXPECT_EQ(sampler.use_count(), 2u);
    set.reset();
    EXPECT_EQ(b.use_count(), 1u) << "dropping the set released everything";
    EXPECT_EQ(view.use_count(), 1u);
    EXPECT_EQ(sampler.use_count(), 1u);
    borrowed.reset();
    device.wait_idle();
    device.fn().vkDestroyBuffer(device.vk(), raw, nullptr);
    device.fn().vkFreeMemory(device.vk(), memory, nullptr);
}

TEST_F(VulkanTest, DescriptorWriteMisuseIsAUsageError) {
    auto set_layout = every_type_layout(device);
    auto pool = every_type_pool(device, 1);
    auto set = pool.allocate(set_layout);
    auto buffer = value_buffer(device, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT, 1);
    auto view = vkrc::BufferView::create(buffer, {.format = VK_FORMAT_R32_UINT});
    auto message = [](auto&& f) {
        try {
            f();
        } catch (const vkrc::UsageError& e) {
            return std::string(e.what());
        }
        return std::string("no UsageError");
    };
    EXPECT_EQ(message([&] { set.write_buffer_view(4, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, view); }),
              "vkrc::DescriptorSet::write_buffer_view: descriptor type VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER is not a "
              "texel buffer type");
    EXPECT_EQ(message([&] { set.write_buffer_view(5, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, view); }),
              "vkrc::DescriptorSet::write_buffer_view: binding 5 has descriptor type "
              "VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER in the set layout, the write has type "
              "VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER");
    EXPECT_EQ(message([&] { set.write_buffer_view(4, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, vkrc::BufferView{}); }),
              "vkrc::DescriptorSet::write_buffer_view: the BufferView handle is empty");
    auto update_template = vkrc::DescriptorUpdateTemplate::create(
        device, {.entries = {{1, 0, 2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 0, sizeof(VkDescriptorBufferInfo)}},
                 .descriptor_set_layout = set_layout});
    const VkDescriptorBufferInfo two[2] = {};
    EXPECT_EQ(message([&] { set.update_with_template(update_template, two); }),
              "vkrc::DescriptorSet::update_with_template: array elements 0 to 1 are past binding 1's 1 descriptors");
}

}  // namespace
