// Push descriptors (VK_KHR_push_descriptor) and descriptor update templates,
// each proved by a compute dispatch that writes through the descriptors.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"

#include <span>

namespace {

using vkrc_test::VulkanTest;

constexpr std::uint32_t count = 256;

std::uint32_t pattern(std::uint32_t i, std::uint32_t seed) { return (i * 2654435761u) ^ seed; }

vkrc::Buffer output_buffer(const vkrc::Device& device) {
    return vkrc::Buffer::create(device, {.size = count * 4,
                                         .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                         .memory = {.usage = vkrc::MemoryUsage::readback}});
}

// Whether every element of buffer holds fill_pattern.comp's value for seed.
::testing::AssertionResult holds_pattern(const vkrc::Buffer& buffer, std::uint32_t seed) {
    for (std::uint32_t i = 0; i < count; ++i) {
        const auto v = buffer.allocation().read_value<std::uint32_t>(4 * i);
        if (v != pattern(i, seed)) return ::testing::AssertionFailure() << "element " << i << " is " << v;
    }
    return ::testing::AssertionSuccess();
}

vkrc::DescriptorSetLayout storage_layout(const vkrc::Device& device, VkDescriptorSetLayoutCreateFlags flags) {
    return vkrc::DescriptorSetLayout::create(device,
                                             {.flags = flags,
                                              .bindings = {{.binding = 0,
                                                            .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                            .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
}

// fill_pattern.comp with set 0 of set_layout.
struct FillPipeline {
    vkrc::PipelineLayout layout;
    vkrc::ComputePipeline pipeline;
    explicit FillPipeline(const vkrc::DescriptorSetLayout& set_layout)
        : layout(vkrc::PipelineLayout::create(
              set_layout.device(),
              {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}})),
          pipeline(vkrc::ComputePipeline::create(
              layout, vkrc::ShaderModule::create(set_layout.device(), vkrc_shaders::fill_pattern_comp))) {}
    void dispatch(const vkrc::CommandBuffer& cmd, std::uint32_t seed) const {
        const std::uint32_t params[] = {count, seed};
        cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, params);
        cmd.dispatch(count / 64);
    }
};

// The fixture's device replaced by one with VK_KHR_push_descriptor.
class PushDescriptorTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (!physical_device.supports_extension(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
            GTEST_SKIP() << "the device lacks VK_KHR_push_descriptor";
        device =
            vkrc::Device::create(physical_device, {.enabled_extension_names = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME}});
        queue = device.default_queue();
    }
};

// Two dispatches, each with its own buffer pushed: both are written.
TEST_F(PushDescriptorTest, PushDescriptorSetPerDispatch) {
    auto set_layout = storage_layout(device, VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR);
    FillPipeline fill(set_layout);
    auto a = output_buffer(device);
    auto b = output_buffer(device);
    vkrc_test::OneShotCommands s(queue);
    s.cmd.bind_pipeline(fill.pipeline);
    for (auto [buffer, seed] : {std::pair{&a, 11u}, std::pair{&b, 22u}}) {
        const VkDescriptorBufferInfo info{buffer->vk(), 0, VK_WHOLE_SIZE};
        VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        write.dstBinding = 0;
        write.descriptorCount = 1;
        write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        write.pBufferInfo = &info;
        s.cmd.push_descriptor_set(VK_PIPELINE_BIND_POINT_COMPUTE, fill.layout, 0, std::span(&write, 1));
        fill.dispatch(s.cmd, seed);
    }
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    EXPECT_TRUE(holds_pattern(a, 11));
    EXPECT_TRUE(holds_pattern(b, 22));
}

TEST_F(VulkanTest, PushDescriptorLayoutNeedsTheExtension) {
    if (device.extension_enabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME)) GTEST_SKIP() << "enabled by default";
    EXPECT_THROW(storage_layout(device, VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR), vkrc::UsageError);
}

// One entry: a storage buffer descriptor at the start of the data.
vkrc::List<VkDescriptorUpdateTemplateEntry> buffer_entry() {
    return {{0, 0, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 0, sizeof(VkDescriptorBufferInfo)}};
}

TEST_F(VulkanTest, UpdateTemplateWritesASet) {
    auto set_layout = storage_layout(device, 0);
    FillPipeline fill(set_layout);
    auto update = vkrc::DescriptorUpdateTemplate::create(
        device, {.entries = buffer_entry(), .descriptor_set_layout = set_layout});
    EXPECT_EQ(update.template_type(), VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET);
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = pool.allocate(set_layout);
    auto out = output_buffer(device);
    const VkDescriptorBufferInfo data{out.vk(), 0, VK_WHOLE_SIZE};
    set.update_with_template(update, &data);
    vkrc_test::OneShotCommands s(queue);
    s.cmd.bind_pipeline(fill.pipeline);
    s.cmd.bind_descriptor_set(fill.pipeline, 0, set);
    fill.dispatch(s.cmd, 33);
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    EXPECT_TRUE(holds_pattern(out, 33));
}

TEST_F(VulkanTest, UpdateTemplateMisuseIsAUsageError) {
    auto set_layout = storage_layout(device, 0);
    auto other_layout = storage_layout(device, 0);
    EXPECT_THROW(vkrc::DescriptorUpdateTemplate::create(device, {.descriptor_set_layout = set_layout}),
                 vkrc::UsageError)
        << "no entries";
    EXPECT_THROW(vkrc::DescriptorUpdateTemplate::create(device, {.entries = buffer_entry()}), vkrc::UsageError)
        << "no layout";
    auto update = vkrc::DescriptorUpdateTemplate::create(
        device, {.entries = buffer_entry(), .descriptor_set_layout = other_layout});
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = pool.allocate(set_layout);
    const VkDescriptorBufferInfo data{VK_NULL_HANDLE, 0, VK_WHOLE_SIZE};
    EXPECT_THROW(set.update_with_template(update, &data), vkrc::UsageError) << "a template of another layout";
}

// A push template, dropped while the command buffer that pushes through it
// is still recording: the drop is held until the work is done.
TEST_F(PushDescriptorTest, UpdateTemplatePushedAndDroppedWhileRecorded) {
    auto set_layout = storage_layout(device, VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR);
    FillPipeline fill(set_layout);
    auto out = output_buffer(device);
    vkrc_test::OneShotCommands s(queue);
    s.cmd.bind_pipeline(fill.pipeline);
    {
        auto push = vkrc::DescriptorUpdateTemplate::create(
            device, {.entries = buffer_entry(),
                     .template_type = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR,
                     .descriptor_set_layout = set_layout,
                     .pipeline_bind_point = VK_PIPELINE_BIND_POINT_COMPUTE,
                     .pipeline_layout = fill.layout,
                     .set = 0});
        const VkDescriptorBufferInfo data{out.vk(), 0, VK_WHOLE_SIZE};
        s.cmd.push_descriptor_set_with_template(push, &data);
    }
    EXPECT_EQ(device.deferred_count(), 1u) << "the template's destruction is held";
    fill.dispatch(s.cmd, 44);
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    EXPECT_TRUE(holds_pattern(out, 44));
    EXPECT_EQ(device.deferred_count(), 0u) << "destroyed once the work completed";
}

// A template made with the raw API for set_layout (and, for push templates,
// set 0 of pipeline_layout), as another library would.
VkDescriptorUpdateTemplate make_raw_template(const vkrc::Device& device, VkDescriptorUpdateTemplateType type,
                                             VkDescriptorSetLayout set_layout, VkPipelineLayout pipeline_layout) {
    const VkDescriptorUpdateTemplateEntry entry{
        0, 0, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 0, sizeof(VkDescriptorBufferInfo)};
    VkDescriptorUpdateTemplateCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
    ci.descriptorUpdateEntryCount = 1;
    ci.pDescriptorUpdateEntries = &entry;
    ci.templateType = type;
    ci.descriptorSetLayout = set_layout;
    ci.pipelineBindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;
    ci.pipelineLayout = pipeline_layout;
    ci.set = 0;
    VkDescriptorUpdateTemplate raw = VK_NULL_HANDLE;
    EXPECT_EQ(device.fn().vkCreateDescriptorUpdateTemplate(device.vk(), &ci, nullptr, &raw), VK_SUCCESS);
    return raw;
}

// A template made elsewhere updates a set through vkrc. Owned, vkrc destroys
// it (the layer reports a leak otherwise); borrowed, its maker does (a double
// destroy would be reported).
TEST_F(VulkanTest, AdoptedUpdateTemplateWritesASet) {
    auto set_layout = storage_layout(device, 0);
    FillPipeline fill(set_layout);
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = pool.allocate(set_layout);
    std::uint32_t seed = 50;
    for (const auto ownership : {vkrc::Ownership::owned, vkrc::Ownership::borrowed}) {
        const VkDescriptorUpdateTemplate raw = make_raw_template(
            device, VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET, set_layout.vk(), VK_NULL_HANDLE);
        auto out = output_buffer(device);
        {
            auto update =
                vkrc::DescriptorUpdateTemplate::adopt(device, raw, {.descriptor_set_layout = set_layout}, ownership);
            EXPECT_EQ(update.vk(), raw);
            EXPECT_EQ(update.template_type(), VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET);
            EXPECT_EQ(update.descriptor_set_layout(), set_layout);
            const VkDescriptorBufferInfo data{out.vk(), 0, VK_WHOLE_SIZE};
            set.update_with_template(update, &data);
        }
        vkrc_test::OneShotCommands s(queue);
        s.cmd.bind_pipeline(fill.pipeline);
        s.cmd.bind_descriptor_set(fill.pipeline, 0, set);
        fill.dispatch(s.cmd, ++seed);
        const auto to_host = vkrc_test::compute_to_host();
        s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
        s.run(queue);
        EXPECT_TRUE(holds_pattern(out, seed));
        device.wait_idle();  // runs any deferred destruction before the raw one
        if (ownership == vkrc::Ownership::borrowed)
            device.fn().vkDestroyDescriptorUpdateTemplate(device.vk(), raw, nullptr);
    }
    EXPECT_THROW(vkrc::DescriptorUpdateTemplate::adopt(device, VK_NULL_HANDLE, {.descriptor_set_layout = set_layout},
                                                       vkrc::Ownership::owned),
                 vkrc::UsageError);
}

// Push descriptors by raw handles: a pipeline layout and a push template made
// by other code (here read out of vkrc objects and made raw).
TEST_F(PushDescriptorTest, RawInteropPushDescriptorsByRawHandles) {
    auto set_layout = storage_layout(device, VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR);
    FillPipeline fill(set_layout);
    const VkPipelineLayout raw_layout = fill.layout.vk();
    const VkDescriptorUpdateTemplate raw_template =
        make_raw_template(device, VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR, set_layout.vk(), raw_layout);
    auto a = output_buffer(device);
    auto b = output_buffer(device);
    vkrc_test::OneShotCommands s(queue);
    s.cmd.bind_pipeline(VK_PIPELINE_BIND_POINT_COMPUTE, fill.pipeline.vk());
    const VkDescriptorBufferInfo info{a.vk(), 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstBinding = 0;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    write.pBufferInfo = &info;
    s.cmd.push_descriptor_set(VK_PIPELINE_BIND_POINT_COMPUTE, raw_layout, 0, std::span(&write, 1));
    fill.dispatch(s.cmd, 61);
    const VkDescriptorBufferInfo data{b.vk(), 0, VK_WHOLE_SIZE};
    s.cmd.push_descriptor_set_with_template(raw_template, raw_layout, 0, &data);
    fill.dispatch(s.cmd, 62);
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    EXPECT_TRUE(holds_pattern(a, 61));
    EXPECT_TRUE(holds_pattern(b, 62));
    device.fn().vkDestroyDescriptorUpdateTemplate(device.vk(), raw_template, nullptr);
}

// An adopted push template pushes through the typed overload, to the layout
// and set it was described with.
TEST_F(PushDescriptorTest, AdoptedPushTemplatePushes) {
    auto set_layout = storage_layout(device, VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR);
    FillPipeline fill(set_layout);
    auto push = vkrc::DescriptorUpdateTemplate::adopt(
        device,
        make_raw_template(device, VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR, set_layout.vk(),
                          fill.layout.vk()),
        {.template_type = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR,
         .descriptor_set_layout = set_layout,
         .pipeline_bind_point = VK_PIPELINE_BIND_POINT_COMPUTE,
         .pipeline_layout = fill.layout,
         .set = 0},
        vkrc::Ownership::owned);
    EXPECT_EQ(push.pipeline_layout(), fill.layout);
    auto out = output_buffer(device);
    vkrc_test::OneShotCommands s(queue);
    s.cmd.bind_pipeline(fill.pipeline);
    const VkDescriptorBufferInfo data{out.vk(), 0, VK_WHOLE_SIZE};
    s.cmd.push_descriptor_set_with_template(push, &data);
    fill.dispatch(s.cmd, 71);
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    EXPECT_TRUE(holds_pattern(out, 71));
}

}  // namespace
