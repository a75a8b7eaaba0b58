#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"

#include <span>
#include <thread>
#include <utility>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

TEST_F(VulkanTest, CommandBufferKeepsItsPoolAlive) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    EXPECT_EQ(cmd.level(), VK_COMMAND_BUFFER_LEVEL_PRIMARY);
    EXPECT_EQ(pool.use_count(), 2u);
    pool.reset_commands();
    EXPECT_TRUE(cmd.pool());
    cmd.begin();
    cmd.end();
    cmd.reset_commands();
    cmd.begin(VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
    cmd.end();
    // Nothing was submitted, so the command buffer is freed at the next allocate.
    cmd.reset();
    EXPECT_EQ(pool.pending_free_count(), 1u);
    auto next = pool.allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
    EXPECT_EQ(pool.pending_free_count(), 0u);
    EXPECT_THROW(next.begin(), vkrc::UsageError);
}

// Everything the work uses (pipeline and its layouts, shader module,
// descriptor pool and set, the storage buffer it fills) is dropped while the
// GPU is held back by a gate only the host opens; the pattern then read back
// shows the work ran with every object intact.
TEST_F(VulkanTest, DroppingEverythingAfterSubmitDefersDestruction) {
    constexpr std::uint32_t count = 256, seed = 0x5eed;
    vkrc_test::GpuGate gate(device);
    auto fence = vkrc::Fence::create(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = vkrc::Buffer::create(device, {.size = count * 4,
                                                  .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                  .memory = {.usage = vkrc::MemoryUsage::readback}});
    {
        auto set_layout = vkrc::DescriptorSetLayout::create(
            device, {.bindings = {{.binding = 0,
                                   .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                   .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
        auto layout = vkrc::PipelineLayout::create(
            device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}});
        auto descriptors = vkrc::DescriptorPool::create(
            device, {.max_sets = 2, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}}});
        auto set = descriptors.allocate(set_layout);
        auto storage = vkrc::Buffer::create(
            device,
            {.size = count * 4, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
        set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storage);
        auto pipeline =
            vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp));
        auto cmd = pool.allocate();
        cmd.begin();
        cmd.bind_pipeline(pipeline);
        cmd.bind_descriptor_set(pipeline, 0, set);
        const std::uint32_t params[] = {count, seed};
        cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(params), params);
        cmd.dispatch(count / 64, 1);
        auto to_copy = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                                            VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        cmd.pipeline_barrier(std::span(&to_copy, 1), {}, {});
        const VkBufferCopy region{0, 0, count * 4};
        cmd.copy_buffer(storage, readback, std::span(&region, 1));
        auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                            VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
        cmd.end();
        gate.submit(queue, cmd, fence);
        // Every handle goes out of scope here, right after the submit.
    }
    EXPECT_EQ(pool.pending_free_count(), 1u);
    // Set layout, pipeline layout, descriptor pool, pipeline, storage buffer
    // and its memory (the shader module went before the submit, when nothing
    // was pending; the set goes with its pool).
    EXPECT_EQ(device.deferred_count(), 6u);
    EXPECT_EQ(fence.status(), VK_NOT_READY);
    gate.open();
    EXPECT_EQ(fence.wait(), VK_SUCCESS);  // a wait collects what completed
    EXPECT_EQ(device.deferred_count(), 0u);
    for (std::uint32_t i = 0; i < count; ++i) {
        ASSERT_EQ(readback.allocation().read_value<std::uint32_t>(i * 4), (i * 2654435761u) ^ seed) << "word " << i;
    }
    auto cmd = pool.allocate();  // frees the dropped command buffer
    EXPECT_EQ(pool.pending_free_count(), 0u);
}

// Commands recorded through a CommandRecorder taken by value (the recording
// part of a CommandBuffer, two pointers) land in that command buffer, mixin
// methods (fill_buffer) and its own (pipeline_barrier) alike; it holds the
// same table and raw handle and keeps nothing alive.
void fill_through_recorder(vkrc::CommandRecorder rec, const vkrc::Buffer& target) {
    rec.fill_buffer(target, 0, 8, 0x600df00d);
    rec.fill_buffer(target, 8, 8, 0x0ddba11);
    const auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                              VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    rec.pipeline_barrier(std::span(&to_host, 1), {}, {});
}

TEST_F(VulkanTest, RecordingThroughACommandRecorderCopy) {
    static_assert(sizeof(vkrc::CommandRecorder) == 2 * sizeof(void*));
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto target = vkrc::Buffer::create(
        device,
        {.size = 16, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto cmd = pool.allocate();
    const vkrc::CommandRecorder& rec = cmd;
    EXPECT_EQ(rec.vk(), cmd.vk());
    EXPECT_EQ(&rec.fn(), &cmd.fn());
    EXPECT_EQ(pool.use_count(), 2u);  // the recorder counts nothing
    cmd.begin();
    fill_through_recorder(cmd, target);
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    EXPECT_EQ(target.allocation().read_value<std::uint32_t>(0), 0x600df00du);
    EXPECT_EQ(target.allocation().read_value<std::uint32_t>(12), 0x0ddba11u);
}

#if VKRC_RUNTIME_CHECKS
// A default recorder, and the recorder part of a moved-from or reset()
// CommandBuffer, hold no handle: recording through them throws UsageError
// naming the call rather than reaching Vulkan with a stale handle.
TEST_F(VulkanTest, EmptyRecordersThrowUsageError) {
    const vkrc::CommandRecorder none;
    vkrc_test::expect_usage_error([&] { none.draw(3); }, {"vkrc::CommandBuffer::draw"});
    vkrc_test::expect_usage_error([&] { none.set_line_width(1.0f); }, {"vkrc::CommandBuffer::set_line_width"});
    vkrc_test::expect_usage_error([&] { (void)none.vk(); }, {"vkrc::CommandRecorder::vk"});
    vkrc_test::expect_usage_error([&] { (void)none.fn(); }, {"vkrc::CommandRecorder::fn"});

    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    const VkCommandBuffer raw = cmd.vk();
    vkrc::CommandBuffer moved = std::move(cmd);
    EXPECT_EQ(moved.vk(), raw);
    vkrc_test::expect_usage_error([&] { cmd.dispatch(1); }, {"vkrc::CommandBuffer::dispatch"});
    vkrc_test::expect_usage_error([&] { vkrc::CommandRecorder(cmd).dispatch(1); }, {"vkrc::CommandBuffer::dispatch"});
    vkrc_test::expect_usage_error([&] { (void)static_cast<const vkrc::CommandRecorder&>(cmd).vk(); },
                                  {"vkrc::CommandRecorder::vk"});
    cmd = std::move(moved);
    EXPECT_EQ(cmd.vk(), raw);
    vkrc_test::expect_usage_error([&] { moved.fill_buffer(VK_NULL_HANDLE, 0, 4, 0); },
                                  {"vkrc::CommandBuffer::fill_buffer"});
    vkrc::CommandBuffer copy = cmd;
    copy.reset();
    vkrc_test::expect_usage_error([&] { copy.end_rendering(); }, {"vkrc::CommandBuffer::end_rendering"});
    EXPECT_EQ(cmd.vk(), raw);  // the reset dropped only copy's reference
}
#endif

// A descriptor pool without FREE_DESCRIPTOR_SET_BIT reclaims sets only by reset.
TEST_F(VulkanTest, DescriptorSetsOfAPoolWithoutFreeBit) {
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    auto pool = vkrc::DescriptorPool::create(
        device, {.flags = 0, .max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = pool.allocate(set_layout);
    set.reset();
    EXPECT_EQ(pool.pending_free_count(), 0u);
    pool.reset_sets();
    auto again = pool.allocate(set_layout);
    EXPECT_TRUE(again.pool() == pool);
    pool.reset_sets();
    again.reset();  // a set from before a reset is already gone: nothing to free
    EXPECT_EQ(pool.pending_free_count(), 0u);
}

TEST_F(VulkanTest, FreedDescriptorSetsReturnToTheirPool) {
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    // A pool of one set serves any number of allocate/drop rounds.
    for (int i = 0; i < 4; ++i) {
        auto set = pool.allocate(set_layout);
        EXPECT_NE(set.vk(), VK_NULL_HANDLE);
    }
}

vkrc::DescriptorSetLayout storage_set_layout(const vkrc::Device& device) {
    return vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
}

// A set dropped from a FREE_DESCRIPTOR_SET pool is handed out again by an
// allocate of its layout, with no driver call, once the GPU is done with
// the work submitted before the drop.
TEST_F(VulkanTest, DroppedDescriptorSetsAreReusedOnceTheGpuIsDone) {
    auto layout = storage_set_layout(device);
    auto other = storage_set_layout(device);  // the same bindings, another layout
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 4, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4}}});
    auto buffer = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    vkrc_test::CountSetCalls calls(device);
    VkDescriptorSet first = VK_NULL_HANDLE;
    for (int i = 0; i < 4; ++i) {
        auto set = pool.allocate(layout);
        if (i == 0) first = set.vk();
        EXPECT_EQ(set.vk(), first);
        set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer);
    }
    EXPECT_EQ(calls.allocated(), 1);
    EXPECT_EQ(layout.use_count(), 2u) << "the dropped set keeps its layout";
    EXPECT_NE(pool.allocate(other).vk(), first);
    EXPECT_EQ(calls.allocated(), 2);

    vkrc_test::GpuGate gate(device);
    auto fence = vkrc::Fence::create(device);
    auto command_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = command_pool.allocate();
    {
        auto set = pool.allocate(layout);
        EXPECT_EQ(set.vk(), first);
        cmd.begin();
        cmd.end();
        gate.submit(queue, cmd, fence);
    }
    EXPECT_EQ(pool.pending_free_count(), 1u);
    EXPECT_NE(pool.allocate(layout).vk(), first) << "a set reused while the GPU may still use it";
    EXPECT_EQ(calls.allocated(), 3);
    gate.open();
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    auto one = pool.allocate(layout);
    auto two = pool.allocate(layout);
    EXPECT_EQ(pool.pending_free_count(), 0u);
    EXPECT_EQ(calls.allocated(), 3);
    EXPECT_EQ(calls.freed(), 0);
}

// A full pool gives back its dropped sets: when vkAllocateDescriptorSets
// refuses, all of them; before it is called, those whose layout is gone.
TEST_F(VulkanTest, AFullDescriptorPoolFreesItsDroppedSets) {
    auto layout = storage_set_layout(device);
    auto other = storage_set_layout(device);
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    vkrc_test::CountSetCalls calls(device, 1);
    pool.allocate(layout);
    EXPECT_NE(pool.allocate(other).vk(), VK_NULL_HANDLE);
    EXPECT_EQ(calls.refused(), 1) << "the dropped set of layout was kept for it";
    EXPECT_EQ(calls.freed(), 1);
    EXPECT_EQ(layout.use_count(), 1u);

    other.reset();  // its dropped set now holds the last reference
    EXPECT_NE(pool.allocate(layout).vk(), VK_NULL_HANDLE);
    EXPECT_EQ(calls.refused(), 1) << "a set of a layout no one can ask for again was kept";
    EXPECT_EQ(calls.freed(), 2);

    pool.reset_sets();  // a reset drops the dropped sets with the rest
    EXPECT_EQ(layout.use_count(), 1u);
}

// Secondaries recorded in parallel, one pool per thread, executed by one
// primary. Under the multi-thread policy they are also dropped on their threads.
TEST_F(VulkanTest, SecondariesFromFourThreads) {
    constexpr int threads = 4;
    constexpr std::uint32_t per_thread = 2;
    if (physical_device.properties().limits.timestampComputeAndGraphics == VK_FALSE)
        GTEST_SKIP() << "the device lacks timestampComputeAndGraphics (lavapipe has it)";
    auto queries = vkrc::QueryPool::create(device, {.query_count = threads * per_thread});
    std::vector<vkrc::CommandPool> pools;
    for (int t = 0; t < threads; ++t) {
        pools.push_back(vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()}));
    }
    std::vector<vkrc::CommandBuffer> secondaries(threads);
    auto record = [&](int t) {
        auto cmd = pools[t].allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        cmd.begin_secondary();
        std::uint32_t first = static_cast<std::uint32_t>(t) * per_thread;
        for (std::uint32_t q = first; q < first + per_thread; ++q) {
            cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, q);
        }
        cmd.end();
        secondaries[t] = std::move(cmd);
    };
#if VKRC_IS_MULTI_THREAD
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t) workers.emplace_back(record, t);
    for (auto& w : workers) w.join();
#else
    for (int t = 0; t < threads; ++t) record(t);
#endif
    auto primary_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto primary = primary_pool.allocate();
    primary.begin();
    primary.reset_query_pool(queries, 0, threads * per_thread);
    primary.execute_commands(secondaries);
    primary.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&primary, 1)}, fence);
#if VKRC_IS_MULTI_THREAD
    // Each thread drops its secondary while the GPU may still run it.
    std::vector<std::thread> droppers;
    for (int t = 0; t < threads; ++t) droppers.emplace_back([&, t] { secondaries[t].reset(); });
    for (auto& d : droppers) d.join();
#else
    secondaries.clear();
#endif
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    std::vector<std::uint64_t> ticks(threads * per_thread);
    ASSERT_EQ(queries.results(0, ticks), VK_SUCCESS);
    for (auto t : ticks) EXPECT_GT(t, 0u);
    // The next round of recording frees the dropped secondaries.
    for (auto& p : pools) {
        auto cmd = p.allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        EXPECT_EQ(p.pending_free_count(), 0u);
    }
}

// Past what fits on the stack (4 batches, 4 semaphores and 8 command
// buffers per batch), submit builds its Vulkan structures on the heap.
TEST_F(VulkanTest, SubmitBeyondTheStackArraysRuns) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    std::vector<vkrc::CommandBuffer> many;
    for (int i = 0; i < 40; ++i) {
        many.push_back(pool.allocate());
        many.back().begin(0);  // the first 20 are submitted twice
        many.back().end();
    }
    std::vector<vkrc::Semaphore> signals;
    std::vector<vkrc::SemaphoreSubmit> signal_infos;
    for (int i = 0; i < 6; ++i) {
        signals.push_back(vkrc::Semaphore::create_timeline(device, 0));
        signal_infos.emplace_back(signals.back(), 1);
    }
    auto fence = vkrc::Fence::create(device);
    // One batch with 20 command buffers and 6 signals, then 5 more batches.
    std::vector<vkrc::SubmitBatch> batches{{.command_buffers = std::span(many).first(20), .signals = signal_infos}};
    for (int b = 0; b < 5; ++b) batches.push_back({.command_buffers = std::span(many).subspan(20 + 4 * b, 4)});
    vkrc::submit(queue, std::span<const vkrc::SubmitBatch>(batches), fence);
    EXPECT_EQ(fence.wait(), VK_SUCCESS);
    for (const auto& s : signals) EXPECT_EQ(s.value(), 1u);
    fence.unsignal();
    vkrc::submit(queue, {.command_buffers = std::span(many).first(20)}, fence);  // one batch, on the heap
    EXPECT_EQ(fence.wait(), VK_SUCCESS);
}

}  // namespace
