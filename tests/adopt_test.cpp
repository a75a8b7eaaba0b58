// Adopt: objects made with the raw API enter vkrc, owned (vkrc destroys them;
// the validation layer reports a leak at vkDestroyDevice otherwise) or
// borrowed (their maker destroys them; a double destroy would be reported).
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/spec_fill.comp.h"

#include <functional>
#include <span>
#include <string>

namespace {

using vkrc_test::VulkanTest;

// Records through record, submits and waits.
void run(const vkrc::Queue& queue, const std::function<void(const vkrc::CommandBuffer&)>& record) {
    auto pool = vkrc::CommandPool::create(queue.device(), {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    record(cmd);
    cmd.end();
    auto fence = vkrc::Fence::create(queue.device());
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
}

// A compute pipeline made entirely with the raw API, as another library would.
struct RawCompute {
    VkShaderModule module = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
};

RawCompute make_raw_compute(const vkrc::Device& device, VkDescriptorSetLayout set_layout) {
    const auto& fn = device.fn();
    RawCompute raw;
    VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module_info.codeSize = vkrc_shaders::spec_fill_comp.size_bytes();
    module_info.pCode = vkrc_shaders::spec_fill_comp.data();
    EXPECT_EQ(fn.vkCreateShaderModule(device.vk(), &module_info, nullptr, &raw.module), VK_SUCCESS);
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout;
    EXPECT_EQ(fn.vkCreatePipelineLayout(device.vk(), &layout_info, nullptr, &raw.layout), VK_SUCCESS);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = raw.module;
    ci.stage.pName = "main";
    ci.layout = raw.layout;
    EXPECT_EQ(fn.vkCreateComputePipelines(device.vk(), VK_NULL_HANDLE, 1, &ci, nullptr, &raw.pipeline), VK_SUCCESS);
    return raw;
}

TEST_F(VulkanTest, AdoptedPipelineBindsThroughVkrc) {
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto raw = make_raw_compute(device, set_layout.vk());
    // Owned: vkrc destroys all three once the GPU is done with them.
    auto module = vkrc::ShaderModule::adopt(device, raw.module, vkrc::Ownership::owned);
    auto layout = vkrc::PipelineLayout::adopt(device, raw.layout, vkrc::Ownership::owned);
    auto pipeline = vkrc::Pipeline::adopt(layout, raw.pipeline, VK_PIPELINE_BIND_POINT_COMPUTE, vkrc::Ownership::owned);
    module.reset();  // a pipeline does not need its module after creation
    EXPECT_EQ(pipeline.layout().vk(), raw.layout);
    EXPECT_EQ(pipeline.bind_point(), VK_PIPELINE_BIND_POINT_COMPUTE);

    auto buffer = vkrc::Buffer::create(
        device,
        {.size = 4, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto descriptors =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptors.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer);
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        cmd.bind_pipeline(pipeline);
        cmd.bind_descriptor_set(pipeline, 0, set);
        cmd.dispatch(1);
        auto to_host = vkrc::buffer_barrier(buffer.vk(), VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                                            VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
    });
    EXPECT_EQ(buffer.allocation().read_value<std::uint32_t>(0), 1u);  // the constants' defaults: 1 + 1 * 0
}

TEST_F(VulkanTest, AdoptedBorrowedObjectsAreLeftToTheirMaker) {
    const auto& fn = device.fn();
    VkSamplerCreateInfo sampler_info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    VkSampler sampler = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateSampler(device.vk(), &sampler_info, nullptr, &sampler), VK_SUCCESS);
    VkEventCreateInfo event_info{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
    VkEvent event = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateEvent(device.vk(), &event_info, nullptr, &event), VK_SUCCESS);
    VkPipelineCacheCreateInfo cache_info{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    VkPipelineCache cache = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreatePipelineCache(device.vk(), &cache_info, nullptr, &cache), VK_SUCCESS);

    auto borrowed_event = vkrc::Event::adopt(device, event, vkrc::Ownership::borrowed);
    borrowed_event.set();
    EXPECT_EQ(borrowed_event.status(), VK_EVENT_SET);
    vkrc::Sampler::adopt(device, sampler, vkrc::Ownership::borrowed).reset();
    vkrc::PipelineCache::adopt(device, cache, vkrc::Ownership::borrowed).reset();
    borrowed_event.reset();
    device.wait_idle();  // runs any (wrongly) deferred destruction before the raw ones
    fn.vkDestroySampler(device.vk(), sampler, nullptr);
    fn.vkDestroyEvent(device.vk(), event, nullptr);
    fn.vkDestroyPipelineCache(device.vk(), cache, nullptr);
}

TEST_F(VulkanTest, AdoptedOwnedObjectsAreDestroyedByVkrc) {
    const auto& fn = device.fn();
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                     .extent = {4, 4, 1},
                                     .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT});
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT});

    VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view_info.image = image.vk();
    view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view_info.format = VK_FORMAT_R8G8B8A8_UNORM;
    view_info.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateImageView(device.vk(), &view_info, nullptr, &view), VK_SUCCESS);
    auto image_view =
        vkrc::ImageView::adopt(image, view, view_info.format, view_info.subresourceRange, vkrc::Ownership::owned);
    EXPECT_EQ(image_view.format(), VK_FORMAT_R8G8B8A8_UNORM);
    EXPECT_EQ(image_view.image().vk(), image.vk());

    VkBufferViewCreateInfo buffer_view_info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    buffer_view_info.buffer = buffer.vk();
    buffer_view_info.format = VK_FORMAT_R32_UINT;
    buffer_view_info.range = VK_WHOLE_SIZE;
    VkBufferView buffer_view = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateBufferView(device.vk(), &buffer_view_info, nullptr, &buffer_view), VK_SUCCESS);
    vkrc::BufferView::adopt(buffer, buffer_view, vkrc::Ownership::owned);

    VkQueryPoolCreateInfo query_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = 2;
    VkQueryPool raw_pool = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateQueryPool(device.vk(), &query_info, nullptr, &raw_pool), VK_SUCCESS);
    auto queries = vkrc::QueryPool::adopt(device, raw_pool, {.query_count = 2}, vkrc::Ownership::owned);
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        cmd.reset_query_pool(queries, 0, 2);
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 0);
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 1);
    });
    std::uint64_t stamps[2] = {};
    EXPECT_EQ(queries.results(0, stamps, VK_QUERY_RESULT_WAIT_BIT), VK_SUCCESS);
    EXPECT_LE(stamps[0], stamps[1]);

    VkAttachmentDescription attachment{0,
                                       VK_FORMAT_R8G8B8A8_UNORM,
                                       VK_SAMPLE_COUNT_1_BIT,
                                       VK_ATTACHMENT_LOAD_OP_CLEAR,
                                       VK_ATTACHMENT_STORE_OP_STORE,
                                       VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                       VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                       VK_IMAGE_LAYOUT_UNDEFINED,
                                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkAttachmentReference color{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &color;
    VkRenderPassCreateInfo pass_info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    pass_info.attachmentCount = 1;
    pass_info.pAttachments = &attachment;
    pass_info.subpassCount = 1;
    pass_info.pSubpasses = &subpass;
    VkRenderPass raw_pass = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateRenderPass(device.vk(), &pass_info, nullptr, &raw_pass), VK_SUCCESS);
    const std::uint32_t color_counts[] = {1};
    auto pass = vkrc::RenderPass::adopt(device, raw_pass, color_counts, vkrc::Ownership::owned);
    EXPECT_EQ(pass.color_attachment_count(0), 1u);
    VkFramebufferCreateInfo fb_info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb_info.renderPass = raw_pass;
    fb_info.attachmentCount = 1;
    fb_info.pAttachments = &view;
    fb_info.width = fb_info.height = 4;
    fb_info.layers = 1;
    VkFramebuffer raw_fb = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateFramebuffer(device.vk(), &fb_info, nullptr, &raw_fb), VK_SUCCESS);
    auto framebuffer = vkrc::Framebuffer::adopt(pass, raw_fb, {4, 4}, vkrc::Ownership::owned);
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        VkClearValue clear{};
        cmd.begin_render_pass(pass, framebuffer, {{0, 0}, {4, 4}}, std::span(&clear, 1));
        cmd.end_render_pass();
    });
    // The image view must outlive the framebuffer: dropped last.
    framebuffer.reset();
    image_view.reset();
}

// A pool made elsewhere: vkrc allocates from it and records; borrowed, the
// maker destroys it (with its command buffers) after the GPU is done.
TEST_F(VulkanTest, AdoptedCommandPoolAllocatesAndRecords) {
    VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    info.queueFamilyIndex = queue.family_index();
    VkCommandPool raw = VK_NULL_HANDLE;
    ASSERT_EQ(device.fn().vkCreateCommandPool(device.vk(), &info, nullptr, &raw), VK_SUCCESS);
    for (auto ownership : {vkrc::Ownership::borrowed, vkrc::Ownership::owned}) {
        auto pool = vkrc::CommandPool::adopt(device, raw, queue.family_index(), ownership);
        EXPECT_EQ(pool.queue_family_index(), queue.family_index());
        auto cmd = pool.allocate();
        cmd.begin();
        cmd.end();
        auto fence = vkrc::Fence::create(device);
        vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
        ASSERT_EQ(fence.wait(), VK_SUCCESS);
    }
    // The owned round destroyed the pool: a second destroy (or a leak) would be reported.
    EXPECT_THROW(vkrc::CommandPool::adopt(device, VK_NULL_HANDLE, 0, vkrc::Ownership::owned), vkrc::UsageError);
}

// A buffer that transfers fill and the host reads back.
vkrc::Buffer fill_target(const vkrc::Device& device) {
    return vkrc::Buffer::create(
        device,
        {.size = 16, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
}

VkMemoryBarrier2 transfer_to_host() {
    return vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

VkCommandBuffer allocate_raw(const vkrc::Device& device, VkCommandPool pool, VkCommandBufferLevel level) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = level;
    ai.commandBufferCount = 1;
    VkCommandBuffer raw = VK_NULL_HANDLE;
    EXPECT_EQ(device.fn().vkAllocateCommandBuffers(device.vk(), &ai, &raw), VK_SUCCESS);
    return raw;
}

// Command buffers allocated with the raw API from a pool made elsewhere: a
// primary and a secondary record through vkrc and are submitted. Owned, they
// go back to the pool when dropped; borrowed, their maker frees them (a
// double free would be reported by the layer).
TEST_F(VulkanTest, AdoptedCommandBufferRecordsAndIsSubmitted) {
    const auto& fn = device.fn();
    VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    info.queueFamilyIndex = queue.family_index();
    VkCommandPool raw_pool = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateCommandPool(device.vk(), &info, nullptr, &raw_pool), VK_SUCCESS);
    auto pool = vkrc::CommandPool::adopt(device, raw_pool, queue.family_index(), vkrc::Ownership::borrowed);
    auto target = fill_target(device);
    const VkCommandBuffer spare = allocate_raw(device, raw_pool, VK_COMMAND_BUFFER_LEVEL_PRIMARY);
    EXPECT_THROW(vkrc::CommandBuffer::adopt(pool, spare, VK_COMMAND_BUFFER_LEVEL_MAX_ENUM, vkrc::Ownership::owned),
                 vkrc::UsageError);
    fn.vkFreeCommandBuffers(device.vk(), raw_pool, 1, &spare);
    std::uint32_t value = 0x1000;
    for (const auto ownership : {vkrc::Ownership::owned, vkrc::Ownership::borrowed}) {
        const VkCommandBuffer raw_primary = allocate_raw(device, raw_pool, VK_COMMAND_BUFFER_LEVEL_PRIMARY);
        const VkCommandBuffer raw_secondary = allocate_raw(device, raw_pool, VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        ++value;
        {
            auto cmd = vkrc::CommandBuffer::adopt(pool, raw_primary, VK_COMMAND_BUFFER_LEVEL_PRIMARY, ownership);
            auto secondary =
                vkrc::CommandBuffer::adopt(pool, raw_secondary, VK_COMMAND_BUFFER_LEVEL_SECONDARY, ownership);
            EXPECT_EQ(cmd.vk(), raw_primary);
            EXPECT_EQ(cmd.level(), VK_COMMAND_BUFFER_LEVEL_PRIMARY);
            EXPECT_EQ(cmd.pool().vk(), raw_pool);
            EXPECT_THROW(secondary.begin(), vkrc::UsageError) << "a secondary needs begin_secondary";
            secondary.begin_secondary();
            secondary.fill_buffer(target, 8, 8, value + 1);
            secondary.end();
            cmd.begin();
            cmd.fill_buffer(target, 0, 8, value);
            cmd.execute_commands(std::span(&secondary, 1));
            const auto to_host = transfer_to_host();
            cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
            cmd.end();
            auto fence = vkrc::Fence::create(device);
            vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
            ASSERT_EQ(fence.wait(), VK_SUCCESS);
            EXPECT_EQ(target.allocation().read_value<std::uint32_t>(4), value);
            EXPECT_EQ(target.allocation().read_value<std::uint32_t>(12), value + 1);
        }
        if (ownership == vkrc::Ownership::owned) {
            EXPECT_EQ(pool.pending_free_count(), 2u) << "both dropped, to be freed once the GPU is done";
            device.wait_idle();
            pool.reset_commands();  // frees the completed ones
        } else {
            const VkCommandBuffer both[] = {raw_primary, raw_secondary};
            fn.vkFreeCommandBuffers(device.vk(), raw_pool, 2, both);
        }
        EXPECT_EQ(pool.pending_free_count(), 0u);
    }
    pool.reset();
    device.wait_idle();
    fn.vkDestroyCommandPool(device.vk(), raw_pool, nullptr);
}

// A command buffer of another device (two logical devices here, as on
// lavapipe) is refused, in both directions, naming the problem; the same raw
// command buffer adopted with a pool of its own device records and runs.
TEST_F(VulkanTest, AdoptRefusesACommandBufferOfAnotherDevice) {
    auto other = vkrc::Device::create(physical_device);
    auto other_queue = other.default_queue();
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto other_pool = vkrc::CommandPool::create(other, {.queue_family_index = other_queue.family_index()});
    const VkCommandBuffer raw = allocate_raw(other, other_pool.vk(), VK_COMMAND_BUFFER_LEVEL_PRIMARY);
    const std::string refused = vkrc_test::usage_error_of(
        [&] { vkrc::CommandBuffer::adopt(pool, raw, VK_COMMAND_BUFFER_LEVEL_PRIMARY, vkrc::Ownership::owned); });
    EXPECT_NE(refused.find("vkrc::CommandBuffer::adopt"), std::string::npos) << refused;
    EXPECT_NE(refused.find("allocated on another device than the CommandPool's"), std::string::npos) << refused;
    auto mine = pool.allocate();
    EXPECT_NE(vkrc_test::usage_error_of([&] {
                  vkrc::CommandBuffer::adopt(other_pool, mine.vk(), VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                             vkrc::Ownership::borrowed);
              }).find("another device"),
              std::string::npos);

    auto cmd = vkrc::CommandBuffer::adopt(other_pool, raw, VK_COMMAND_BUFFER_LEVEL_PRIMARY, vkrc::Ownership::owned);
    auto target = fill_target(other);
    cmd.begin();
    cmd.fill_buffer(target, 0, 16, 0x5ca1ab1e);
    const auto to_host = transfer_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    auto fence = vkrc::Fence::create(other);
    vkrc::submit(other_queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    EXPECT_EQ(target.allocation().read_value<std::uint32_t>(12), 0x5ca1ab1eu);
}

// A non-dispatchable handle carries no device vkrc could read, and its value
// is unique only within its device: a raw buffer of another device is
// adopted without complaint (docs/guide.md says so), and the validation
// layer reports its first use on this device, once.
TEST_F(VulkanTest, AdoptingARawBufferOfAnotherDeviceIsReportedByTheLayerAtItsFirstUse) {
    auto other = vkrc::Device::create(physical_device);
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = 16;
    info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer raw = VK_NULL_HANDLE;
    ASSERT_EQ(other.fn().vkCreateBuffer(other.vk(), &info, nullptr, &raw), VK_SUCCESS);
    {
        auto adopted =
            vkrc::Buffer::adopt(device, raw, info.size, info.usage, vkrc::Ownership::borrowed);  // vkrc cannot know
        EXPECT_TRUE(log->take().empty()) << "nothing is reported before the buffer is used";
        auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
        auto cmd = pool.allocate();
        cmd.begin();
        cmd.fill_buffer(adopted, 0, 16, 1);  // the layer reports it and does not pass it on
        cmd.end();
        EXPECT_TRUE(log->take_expected("VUID-vkCmdFillBuffer-commonparent", 1));
        // The layer's thread-safety checker does not find the buffer among
        // this device's objects either, at the call's start and its end.
        EXPECT_TRUE(log->take_expected("UNASSIGNED-Threading-Info", 2));
    }
    other.fn().vkDestroyBuffer(other.vk(), raw, nullptr);
}

// Secondaries recorded entirely by other code run inside a vkrc primary.
TEST_F(VulkanTest, RawInteropExecutesRawSecondaries) {
    const auto& fn = device.fn();
    auto target = fill_target(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    VkCommandBuffer raw[2] = {};
    for (std::uint32_t i = 0; i < 2; ++i) {
        raw[i] = allocate_raw(device, pool.vk(), VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.pInheritanceInfo = &inheritance;
        ASSERT_EQ(fn.vkBeginCommandBuffer(raw[i], &begin), VK_SUCCESS);
        fn.vkCmdFillBuffer(raw[i], target.vk(), 8 * i, 8, 0xabc0 + i);
        ASSERT_EQ(fn.vkEndCommandBuffer(raw[i]), VK_SUCCESS);
    }
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        cmd.execute_commands(std::span<const VkCommandBuffer>(raw));
        const auto to_host = transfer_to_host();
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    });
    EXPECT_EQ(target.allocation().read_value<std::uint32_t>(0), 0xabc0u);
    EXPECT_EQ(target.allocation().read_value<std::uint32_t>(8), 0xabc1u);
    fn.vkFreeCommandBuffers(device.vk(), pool.vk(), 2, raw);
}

// RawInterop: the recording methods that take query pools, events, render
// passes and framebuffers also take their raw handles.
TEST_F(VulkanTest, RawInteropQueriesAndEventsByRawHandle) {
    const auto& fn = device.fn();
    auto queries = vkrc::QueryPool::create(device, {.query_count = 2});
    auto event = vkrc::Event::create(device);
    auto results = vkrc::Buffer::create(
        device,
        {.size = 16, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    const VkQueryPool raw_pool = queries.vk();
    const VkEvent raw_event = event.vk();
    const VkBuffer raw_results = results.vk();
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        cmd.reset_query_pool(raw_pool, 0, 2);
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, raw_pool, 0);
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, raw_pool, 1);
        cmd.copy_query_results(raw_pool, 0, 2, raw_results, 0, 8);
        auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                            VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dependency.memoryBarrierCount = 1;
        dependency.pMemoryBarriers = &to_host;
        cmd.set_event(raw_event, dependency);
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    });
    EXPECT_EQ(fn.vkGetEventStatus(device.vk(), raw_event), VK_EVENT_SET);
    auto first = results.allocation().read_value<std::uint64_t>(0);
    auto second = results.allocation().read_value<std::uint64_t>(8);
    EXPECT_NE(second, 0u);
    EXPECT_LE(first, second);
    run(queue,
        [&](const vkrc::CommandBuffer& cmd) { cmd.reset_event(raw_event, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT); });
    EXPECT_EQ(fn.vkGetEventStatus(device.vk(), raw_event), VK_EVENT_RESET);
}

// The pass clears its attachment; the texels read back show it ran with the
// raw pass and framebuffer (final layout TRANSFER_SRC, so no extra barrier).
TEST_F(VulkanTest, RawInteropRenderPassByRawHandle) {
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                     .extent = {4, 4, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto view = vkrc::ImageView::create(image);
    auto readback = vkrc::Buffer::create(
        device,
        {.size = 64, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto pass = vkrc_test::clear_to_copy_render_pass(device, VK_FORMAT_R8G8B8A8_UNORM);
    auto framebuffer =
        vkrc::Framebuffer::create(device, {.render_pass = pass, .attachments = {view}, .width = 4, .height = 4});
    const VkRenderPass raw_pass = pass.vk();
    const VkFramebuffer raw_framebuffer = framebuffer.vk();
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        VkClearValue clear{};
        clear.color = {{1.0f, 0.0f, 1.0f, 1.0f}};
        cmd.begin_render_pass(raw_pass, raw_framebuffer, {{0, 0}, {4, 4}}, std::span(&clear, 1));
        cmd.end_render_pass();
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {4, 4, 1};
        cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, std::span(&region, 1));
        auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                            VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    });
    for (VkDeviceSize texel = 0; texel < 16; ++texel) {
        EXPECT_EQ(readback.allocation().read_value<std::uint32_t>(texel * 4), 0xffff00ffu) << "texel " << texel;
    }
}

// Descriptor objects made with the raw API: vkrc checks writes against the
// bindings it is told, writes and frees through them; owned ones are
// destroyed by vkrc (the layer reports a leak otherwise), borrowed ones by
// their maker (a double destroy would be reported).
TEST_F(VulkanTest, AdoptedDescriptorObjectsWriteAndFree) {
    const auto& fn = device.fn();
    const vkrc::DescriptorSetLayoutCreateInfo layout_info{
        .bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}}};
    VkDescriptorSetLayoutBinding raw_binding{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_ALL, nullptr};
    VkDescriptorSetLayoutCreateInfo raw_layout_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    raw_layout_info.bindingCount = 1;
    raw_layout_info.pBindings = &raw_binding;
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 4};
    VkDescriptorPoolCreateInfo raw_pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    raw_pool_info.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    raw_pool_info.maxSets = 4;
    raw_pool_info.poolSizeCount = 1;
    raw_pool_info.pPoolSizes = &size;
    auto buffer = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT});

    for (const auto ownership : {vkrc::Ownership::owned, vkrc::Ownership::borrowed}) {
        VkDescriptorSetLayout raw_layout = VK_NULL_HANDLE;
        ASSERT_EQ(fn.vkCreateDescriptorSetLayout(device.vk(), &raw_layout_info, nullptr, &raw_layout), VK_SUCCESS);
        VkDescriptorPool raw_pool = VK_NULL_HANDLE;
        ASSERT_EQ(fn.vkCreateDescriptorPool(device.vk(), &raw_pool_info, nullptr, &raw_pool), VK_SUCCESS);
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = raw_pool;
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &raw_layout;
        VkDescriptorSet raw_set = VK_NULL_HANDLE;
        ASSERT_EQ(fn.vkAllocateDescriptorSets(device.vk(), &ai, &raw_set), VK_SUCCESS);
        {
            auto layout = vkrc::DescriptorSetLayout::adopt(device, raw_layout, layout_info, ownership);
            auto pool = vkrc::DescriptorPool::adopt(device, raw_pool, raw_pool_info.flags, ownership);
            auto set = vkrc::DescriptorSet::adopt(pool, layout, raw_set, ownership);
            EXPECT_EQ(set.vk(), raw_set);
            set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer);
            EXPECT_THROW(set.write_buffer(1, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer), vkrc::UsageError);
            auto allocated = pool.allocate(layout);  // vkrc allocates from the adopted pool too
            allocated.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer);
        }
        device.wait_idle();  // runs the deferred frees and destructions
        if (ownership == vkrc::Ownership::borrowed) {
            EXPECT_EQ(fn.vkFreeDescriptorSets(device.vk(), raw_pool, 1, &raw_set), VK_SUCCESS);
            fn.vkDestroyDescriptorPool(device.vk(), raw_pool, nullptr);
            fn.vkDestroyDescriptorSetLayout(device.vk(), raw_layout, nullptr);
        }
    }
}

TEST_F(VulkanTest, AdoptRejectsNullHandles) {
    EXPECT_THROW(vkrc::Sampler::adopt(device, VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
    EXPECT_THROW(vkrc::ShaderModule::adopt(device, VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
    EXPECT_THROW(vkrc::Event::adopt(device, VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
    EXPECT_THROW(vkrc::PipelineLayout::adopt(device, VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
    EXPECT_THROW(vkrc::PipelineCache::adopt(vkrc::Device(), VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
    EXPECT_THROW(vkrc::Pipeline::adopt(vkrc::PipelineLayout(), VK_NULL_HANDLE, VK_PIPELINE_BIND_POINT_COMPUTE,
                                       vkrc::Ownership::owned),
                 vkrc::UsageError);
    EXPECT_THROW(vkrc::QueryPool::adopt(device, VK_NULL_HANDLE, {.query_count = 1}, vkrc::Ownership::owned),
                 vkrc::UsageError);
    EXPECT_THROW(vkrc::QueryPool::adopt(device, VK_NULL_HANDLE, {}, vkrc::Ownership::owned), vkrc::UsageError);
    EXPECT_THROW(vkrc::DescriptorSetLayout::adopt(device, VK_NULL_HANDLE, {}, vkrc::Ownership::owned),
                 vkrc::UsageError);
    EXPECT_THROW(vkrc::DescriptorPool::adopt(device, VK_NULL_HANDLE, 0, vkrc::Ownership::owned), vkrc::UsageError);
    auto layout = vkrc::DescriptorSetLayout::create(device, {});
    EXPECT_THROW(vkrc::DescriptorSet::adopt(vkrc::DescriptorPool(), layout, VK_NULL_HANDLE, vkrc::Ownership::owned),
                 vkrc::UsageError);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    EXPECT_THROW(vkrc::CommandBuffer::adopt(vkrc::CommandPool(), VK_NULL_HANDLE, VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                            vkrc::Ownership::owned),
                 vkrc::UsageError);
    EXPECT_THROW(
        vkrc::CommandBuffer::adopt(pool, VK_NULL_HANDLE, VK_COMMAND_BUFFER_LEVEL_PRIMARY, vkrc::Ownership::owned),
        vkrc::UsageError);
    EXPECT_THROW(vkrc::DescriptorUpdateTemplate::adopt(device, VK_NULL_HANDLE, {.descriptor_set_layout = layout},
                                                       vkrc::Ownership::owned),
                 vkrc::UsageError);
}

}  // namespace
