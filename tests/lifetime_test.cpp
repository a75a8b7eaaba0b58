// Objects dropped while a command buffer that records them is open (recording,
// or executable and not yet submitted for the last time) stay alive until it
// is submitted or closed, and then until the GPU is done (issue 13).
#include "support/vk_test.hpp"

#include <vkrc/extension_functions.hpp>

#include "shaders/fill_pattern.comp.h"
#include "shaders/sample_texels.comp.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <functional>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

constexpr VkDeviceSize words = 256;
constexpr VkDeviceSize bytes = words * sizeof(std::uint32_t);

vkrc::Buffer make_buffer(const vkrc::Device& device, VkBufferUsageFlags usage) {
    return vkrc::Buffer::create(device, {.size = bytes, .usage = usage});
}

// Host-visible, survives every drop: where the tests read results.
vkrc::Buffer make_readback(const vkrc::Device& device) {
    return vkrc::Buffer::create(
        device, {.size = bytes, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {vkrc::MemoryUsage::readback}});
}

void transfer_barrier(const vkrc::CommandBuffer& cmd) {
    auto b = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                                  VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    cmd.pipeline_barrier(std::span(&b, 1), {}, {});
}

// Fills buffer with value and copies it into readback.
void record_fill_copy(const vkrc::CommandBuffer& cmd, const vkrc::Buffer& buffer, const vkrc::Buffer& readback,
                      std::uint32_t value) {
    cmd.fill_buffer(buffer, 0, bytes, value);
    transfer_barrier(cmd);
    VkBufferCopy region{0, 0, bytes};
    cmd.copy_buffer(buffer, readback, std::span(&region, 1));
}

std::vector<std::uint32_t> read_all(const vkrc::Buffer& readback) {
    std::vector<std::uint32_t> out(words);
    readback.allocation().read(0, std::span(out));
    return out;
}

bool all_equal(const vkrc::Buffer& readback, std::uint32_t value) {
    auto v = read_all(readback);
    return std::all_of(v.begin(), v.end(), [&](std::uint32_t x) { return x == value; });
}

void clear_readback(const vkrc::Buffer& readback) {
    std::vector<std::uint32_t> zero(words, 0);
    readback.allocation().write(0, std::span<const std::uint32_t>(zero));
}

void submit_and_wait(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd) {
    auto fence = vkrc::Fence::create(queue.device());
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
}

// Submits cmd behind a gate only the host opens and runs while_held with the
// GPU held back (what was dropped is then certainly still in use: destroying
// it would be reported by the validation layer and spoil what it produces);
// then opens the gate and waits for the work.
void submit_gated_and_wait(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd,
                           const std::function<void()>& while_held) {
    const vkrc_test::GpuGate gate(queue.device());
    auto fence = vkrc::Fence::create(queue.device());
    gate.submit(queue, cmd, fence);
    EXPECT_EQ(fence.status(), VK_NOT_READY);
    while_held();
    gate.open();
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
}

// Images are side x side RGBA8; each recorded operation of a test copies
// its result (texels words, one per texel) into its own slot of readback.
constexpr std::uint32_t side = 8;
constexpr std::uint32_t texels = side * side;
constexpr int slots = static_cast<int>(words / texels);
constexpr VkDeviceSize slot_bytes = texels * sizeof(std::uint32_t);
constexpr VkImageSubresourceRange color_range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};

// A clear color whose RGBA8 encoding is exact, and that encoding as a copy
// to a buffer (and the sampling shader's packUnorm4x8) writes it.
struct Color {
    VkClearColorValue clear;
    std::uint32_t packed;
};

Color make_color(std::uint32_t packed) {
    Color c{{}, packed};
    for (int i = 0; i < 4; ++i) c.clear.float32[i] = static_cast<float>((packed >> (8 * i)) & 0xffu) / 255.0f;
    return c;
}

bool slot_holds(const vkrc::Buffer& readback, int slot, std::uint32_t value) {
    auto v = read_all(readback);
    const auto first = v.begin() + static_cast<std::ptrdiff_t>(slot) * texels;
    return std::all_of(first, first + texels, [&](std::uint32_t x) { return x == value; });
}

vkrc::Image make_image(const vkrc::Device& device) {
    return vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                        .extent = {side, side, 1},
                                        .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                                 VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
}

// What the tests may make, record and drop. The descriptor set points at
// view + sampler (binding 0) and storage (binding 1), which the pipeline
// (sample_texels.comp) reads and writes.
struct Objects {
    vkrc::Instance instance;
    vkrc::Device device;
    vkrc::Queue queue;
    vkrc::CommandPool pool;
    vkrc::CommandBuffer cmd;
    vkrc::CommandBuffer secondary;
    vkrc::Fence fence;
    vkrc::Buffer readback;
    vkrc::Buffer source;  // filled, then copied
    vkrc::Buffer storage;
    vkrc::Image image;  // cleared, then copied or sampled
    vkrc::ImageView view;
    vkrc::Sampler sampler;
    vkrc::DescriptorSetLayout set_layout;
    vkrc::DescriptorPool descriptor_pool;
    vkrc::DescriptorSet set;
    vkrc::PipelineLayout layout;
    vkrc::ComputePipeline pipeline;
};

// The view, sampler, storage buffer, descriptor objects and pipeline over o.image.
void make_sampling_objects(Objects& o, const vkrc::Device& device) {
    o.view = vkrc::ImageView::create(o.image);
    o.sampler = vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST, .min_filter = VK_FILTER_NEAREST});
    o.storage = vkrc::Buffer::create(
        device, {.size = slot_bytes, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    o.set_layout = vkrc_test::sample_texels_set_layout(device);
    o.descriptor_pool = vkrc::DescriptorPool::create(
        device,
        {.max_sets = 1,
         .pool_sizes = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    o.set = o.descriptor_pool.allocate(o.set_layout);
    o.set.write_image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, o.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      o.sampler);
    o.set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, o.storage);
    o.layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {o.set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 16}}});
    o.pipeline =
        vkrc::ComputePipeline::create(o.layout, vkrc::ShaderModule::create(device, vkrc_shaders::sample_texels_comp));
}

// Clears image to color (whatever it held before) and leaves it in layout
// for the stage and access that read it next.
void record_clear(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, const VkClearColorValue& color,
                  VkImageLayout layout, VkPipelineStageFlags2 stage, VkAccessFlags2 access) {
    auto to_dst = vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                      VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_dst, 1));
    cmd.clear_color_image(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, color, std::span(&color_range, 1));
    auto to_use =
        vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, layout,
                            VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, stage, access);
    cmd.pipeline_barrier({}, {}, std::span(&to_use, 1));
}

// Clears the image to color and copies it into readback's slot.
void record_clear_copy(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, const VkClearColorValue& color,
                       int slot, const vkrc::Buffer& readback) {
    record_clear(cmd, image, color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                 VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy region{};
    region.bufferOffset = static_cast<VkDeviceSize>(slot) * slot_bytes;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {side, side, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, std::span(&region, 1));
    transfer_barrier(cmd);
}

// Clears o's image to color, samples every texel through o.set (view and
// sampler) into o.storage with o.pipeline, and copies that into readback's
// slot. The image is reached through the view, which keeps it alive, and
// the pipeline layout through the pipeline when o.layout was dropped.
void record_sample(const vkrc::CommandBuffer& cmd, const Objects& o, const VkClearColorValue& color, int slot,
                   const vkrc::Buffer& readback) {
    record_clear(cmd, o.view.image(), color, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    cmd.bind_pipeline(o.pipeline);
    cmd.bind_descriptor_set(o.pipeline, 0, o.set);
    const std::uint32_t params[4] = {0, side, side, 0};  // level, width, height, base
    cmd.push_constants(o.layout ? o.layout : o.pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(params),
                       params);
    cmd.dispatch(1, 1);
    transfer_barrier(cmd);
    VkBufferCopy region{0, static_cast<VkDeviceSize>(slot) * slot_bytes, slot_bytes};
    cmd.copy_buffer(o.storage, readback, std::span(&region, 1));
    transfer_barrier(cmd);
}

// The snippet, with a copy into a buffer that stays alive.
TEST_F(VulkanTest, BufferDroppedBetweenRecordAndSubmit) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto cmd = pool.allocate();
    {
        auto buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        cmd.begin();
        record_fill_copy(cmd, buffer, readback, 7);
        cmd.end();
    }                                        // buffer dropped here
    EXPECT_GE(device.deferred_count(), 1u);  // held, not destroyed
    submit_gated_and_wait(queue, cmd, [&] { EXPECT_GE(device.deferred_count(), 1u); });
    EXPECT_TRUE(all_equal(readback, 7));
    EXPECT_EQ(device.deferred_count(), 0u);
}

// The physical device for a second device: another GPU of the same name
// when the machine has one (two NVIDIA GPUs), else the test's own (two
// logical devices of one GPU, as on lavapipe).
vkrc::PhysicalDevice second_physical_device(const vkrc::Instance& instance, const vkrc::PhysicalDevice& first) {
    for (const auto& other : instance.physical_devices()) {
        if (other.vk() != first.vk() && std::string(other.name()) == first.name()) return other;
    }
    return first;
}

// Two devices, each with work held behind its own gate while its buffer,
// command pool and (for the second) the Device handle itself are dropped
// (issue 33's never-tested scenario): each device's deferred destruction
// waits for its own timeline, and the gates open in the reverse order of
// submission. On two GPUs where the machine has them.
TEST_F(VulkanTest, WorkInFlightOnTwoDevicesWithDropsOnBoth) {
    const vkrc::PhysicalDevice other = second_physical_device(instance, physical_device);
    std::printf("second device: %s\n", other.vk() == physical_device.vk() ? "the same GPU" : "another GPU");
    std::optional<vkrc::Device> second = vkrc::Device::create(other);
    struct Work {
        vkrc::Queue queue;
        vkrc::Buffer readback;
        vkrc::CommandBuffer cmd;
        std::optional<vkrc_test::GpuGate> gate;
        vkrc::Fence fence;
    };
    Work works[2];
    const vkrc::Device* devices[2] = {&device, &*second};
    for (int i = 0; i < 2; ++i) {
        Work& w = works[i];
        w.queue = devices[i]->default_queue();
        w.readback = make_readback(*devices[i]);
        auto buffer = make_buffer(*devices[i], VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        auto pool = vkrc::CommandPool::create(*devices[i], {.queue_family_index = w.queue.family_index()});
        w.cmd = pool.allocate();
        w.cmd.begin();
        record_fill_copy(w.cmd, buffer, w.readback, 40u + static_cast<std::uint32_t>(i));
        w.cmd.end();
        w.gate.emplace(*devices[i]);
        w.fence = vkrc::Fence::create(*devices[i]);
        w.gate->submit(w.queue, w.cmd, w.fence);
    }                // each iteration drops its buffer and its command pool's handle
    second.reset();  // the second Device's handle: its children keep it
    for (Work& w : works) {
        EXPECT_EQ(w.fence.status(), VK_NOT_READY);
        EXPECT_GE(w.queue.device().deferred_count(), 1u);
    }
    for (int i = 1; i >= 0; --i) {
        works[i].gate->open();
        ASSERT_EQ(works[i].fence.wait(), VK_SUCCESS);
        EXPECT_TRUE(all_equal(works[i].readback, 40u + static_cast<std::uint32_t>(i))) << "device " << i;
    }
    for (Work& w : works) {
        w.queue.device().collect_garbage();
        EXPECT_EQ(w.queue.device().deferred_count(), 0u);
    }
}

// Dropped during recording, before end().
TEST_F(VulkanTest, BufferDroppedWhileRecording) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto cmd = pool.allocate();
    cmd.begin();
    {
        auto buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        record_fill_copy(cmd, buffer, readback, 7);
    }
    cmd.end();
    submit_gated_and_wait(queue, cmd, [&] { EXPECT_GE(device.deferred_count(), 1u); });
    EXPECT_TRUE(all_equal(readback, 7));
    EXPECT_EQ(device.deferred_count(), 0u);
}

// Every kind the recorded work uses: an image cleared and then sampled
// through its view and a sampler, a descriptor set pointing at them and at
// a storage buffer the dispatch writes, the set's layout and pool, the
// pipeline layout and the compute pipeline. All dropped between recording
// and submission; the texels must still arrive in readback.
TEST_F(VulkanTest, EveryKindDroppedBetweenRecordAndSubmit) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto cmd = pool.allocate();
    const auto color = make_color(0x11c0407f);
    {
        Objects o;
        o.image = make_image(device);
        make_sampling_objects(o, device);
        cmd.begin();
        record_sample(cmd, o, color.clear, 0, readback);
        cmd.end();
        const auto before = device.deferred_count();
        o = Objects{};
        EXPECT_GE(device.deferred_count(), before + 9);  // held, not destroyed
    }
    submit_gated_and_wait(queue, cmd, [&] { EXPECT_GE(device.deferred_count(), 9u); });
    EXPECT_TRUE(slot_holds(readback, 0, color.packed));
    EXPECT_EQ(device.deferred_count(), 0u);
}

// A reusable command buffer keeps what it records alive between its
// submissions, until it is reset.
TEST_F(VulkanTest, DroppedBetweenSubmissionsOfAReusableCommandBuffer) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto cmd = pool.allocate();
    auto buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    cmd.begin(0);
    record_fill_copy(cmd, buffer, readback, 7);
    cmd.end();
    submit_and_wait(queue, cmd);
    EXPECT_TRUE(all_equal(readback, 7));
    clear_readback(readback);
    buffer.reset();
    submit_gated_and_wait(queue, cmd, [&] { EXPECT_GE(device.deferred_count(), 1u); });
    EXPECT_TRUE(all_equal(readback, 7));
    EXPECT_GE(device.deferred_count(), 1u);  // still held by cmd
    cmd.reset_commands();
    device.collect_garbage();
    EXPECT_EQ(device.deferred_count(), 0u);
}

// A secondary records the work and is dropped, with the buffer, before the
// primary that executes it is submitted.
TEST_F(VulkanTest, DroppedInsideASecondary) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto cmd = pool.allocate();
    {
        auto secondary = pool.allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        auto buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        secondary.begin_secondary();
        record_fill_copy(secondary, buffer, readback, 7);
        secondary.end();
        cmd.begin();
        cmd.execute_commands(std::span(&secondary, 1));
        cmd.end();
    }
    EXPECT_EQ(pool.pending_free_count(), 1u);  // the secondary, held by cmd
    submit_gated_and_wait(queue, cmd, [&] {
        EXPECT_EQ(pool.pending_free_count(), 1u);
        EXPECT_GE(device.deferred_count(), 1u);  // the buffer
    });
    EXPECT_TRUE(all_equal(readback, 7));
    auto next = pool.allocate();  // frees the secondary
    EXPECT_EQ(pool.pending_free_count(), 0u);
}

// Never submitted: dropping the command buffer releases what it held.
TEST_F(VulkanTest, NeverSubmittedCommandBufferReleasesOnFree) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto cmd = pool.allocate();
    auto buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    cmd.begin();
    record_fill_copy(cmd, buffer, readback, 7);
    cmd.end();
    buffer.reset();
    EXPECT_EQ(device.deferred_count(), 2u);  // the buffer and its memory
    cmd.reset();
    EXPECT_EQ(device.deferred_count(), 0u);  // nothing pending on the GPU: destroyed at once
    // A pool reset closes its command buffers too.
    auto again = pool.allocate();
    buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    again.begin();
    record_fill_copy(again, buffer, readback, 7);
    again.end();
    buffer.reset();
    EXPECT_EQ(device.deferred_count(), 2u);
    pool.reset_commands();
    EXPECT_EQ(device.deferred_count(), 0u);
}

// One frame of the bounded-hold tests: a buffer made and dropped, then cmd
// submitted. Returns the drops pending after the submit; the caller waits.
std::size_t submit_dropping_a_buffer(const vkrc::Device& device, const vkrc::Queue& queue,
                                     const vkrc::CommandBuffer& cmd, const vkrc::Fence& fence) {
    auto scratch = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT});
    scratch.reset();
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    return device.deferred_count();
}

// A reusable command buffer recorded once and submitted every frame holds
// only objects made before its end(): what is made and dropped each frame
// goes the normal deferred way.
TEST_F(VulkanTest, ReusableCommandBufferHoldsABoundedSet) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto source = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    auto cmd = pool.allocate();
    cmd.begin(0);
    record_fill_copy(cmd, source, readback, 7);
    cmd.end();
    source.reset();  // held for as long as cmd is open
    auto fence = vkrc::Fence::create(device);
    std::size_t most = 0;
    for (int frame = 0; frame < 10000; ++frame) {
        most = std::max(most, submit_dropping_a_buffer(device, queue, cmd, fence));
        ASSERT_EQ(fence.wait(), VK_SUCCESS);
        fence.unsignal();
    }
    EXPECT_LE(most, 6u);
    EXPECT_TRUE(all_equal(readback, 7));
}

// The same bound for a ONE_TIME_SUBMIT command buffer that never closes:
// submitted through Queue::submit (a raw submit, which closes nothing) and
// kept. Objects made after its end() are not held by it, so a frame loop
// that makes and drops a buffer each frame keeps the pending drops bounded
// (an end() that did not move the epoch on held them all).
TEST_F(VulkanTest, KeptOneTimeCommandBufferHoldsABoundedSet) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto source = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    auto kept = pool.allocate();
    kept.begin();
    record_fill_copy(kept, source, readback, 7);
    kept.end();
    const VkCommandBufferSubmitInfo kept_info{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
                                              .commandBuffer = kept.vk()};
    const VkSubmitInfo2 raw{
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = 1, .pCommandBufferInfos = &kept_info};
    queue.submit({&raw, 1});
    queue.wait_idle();
    auto frames = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = frames.allocate();
    auto fence = vkrc::Fence::create(device);
    std::size_t most = 0;
    for (int frame = 0; frame < 1000; ++frame) {
        frames.reset_commands();
        cmd.begin();
        record_fill_copy(cmd, source, readback, 9);
        cmd.end();
        most = std::max(most, submit_dropping_a_buffer(device, queue, cmd, fence));
        ASSERT_EQ(fence.wait(), VK_SUCCESS);
        fence.unsignal();
    }
    EXPECT_LE(most, 6u);
    EXPECT_TRUE(all_equal(readback, 9));
}

// An adopted buffer's cleanup runs once the GPU is done with it, even when
// it is dropped between recording and submission.
TEST_F(VulkanTest, AdoptedBufferCleanupRunsAfterTheGpu) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    auto real = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    bool cleaned = false;
    auto cmd = pool.allocate();
    {
        auto adopted = vkrc::Buffer::adopt(device, real.vk(), bytes, real.usage(), vkrc::Ownership::borrowed,
                                           [&cleaned] { cleaned = true; });
        EXPECT_FALSE(adopted.allocation());
        cmd.begin();
        record_fill_copy(cmd, adopted, readback, 7);
        cmd.end();
    }
    EXPECT_FALSE(cleaned);
    submit_gated_and_wait(queue, cmd, [&] { EXPECT_FALSE(cleaned); });
    EXPECT_TRUE(cleaned);
    EXPECT_TRUE(all_equal(readback, 7));
}

// An adopted instance knows what it was created with.
TEST_F(VulkanTest, AdoptedInstanceKnowsItsExtensionsAndLayers) {
    const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
    const char* layers[] = {"VK_LAYER_KHRONOS_validation"};
    auto adopted = vkrc::Instance::adopt(instance.vk(), vkrc::Ownership::borrowed, instance.api_version(), nullptr,
                                         extensions, layers);
    EXPECT_TRUE(adopted.extension_enabled(VK_EXT_DEBUG_UTILS_EXTENSION_NAME));
    EXPECT_TRUE(adopted.layer_enabled("VK_LAYER_KHRONOS_validation"));
    EXPECT_FALSE(adopted.extension_enabled(VK_KHR_SURFACE_EXTENSION_NAME));
    EXPECT_TRUE(instance.layer_enabled("VK_LAYER_KHRONOS_validation"));
}

// An adopted image on its maker's memory, owned: vkrc destroys it once the
// GPU is done, even when dropped between recording and submission, and only
// then runs the cleanup that frees the memory. A cleanup run too early frees
// memory the GPU still uses (reported by the validation layer); one never
// run leaks it (reported at the device's destruction).
TEST_F(VulkanTest, AdoptedImageCleanupRunsAfterTheGpu) {
    const auto& fn = device.fn();
    const vkrc::ImageCreateInfo info{.format = VK_FORMAT_R8G8B8A8_UNORM,
                                     .extent = {side, side, 1},
                                     .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT};
    VkImageCreateInfo raw_info{};
    raw_info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    raw_info.imageType = VK_IMAGE_TYPE_2D;
    raw_info.format = info.format;
    raw_info.extent = info.extent;
    raw_info.mipLevels = 1;
    raw_info.arrayLayers = 1;
    raw_info.samples = VK_SAMPLE_COUNT_1_BIT;
    raw_info.tiling = VK_IMAGE_TILING_OPTIMAL;
    raw_info.usage = info.usage;
    VkImage raw = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkCreateImage(device.vk(), &raw_info, nullptr, &raw), VK_SUCCESS);
    VkMemoryRequirements requirements{};
    fn.vkGetImageMemoryRequirements(device.vk(), raw, &requirements);
    VkMemoryAllocateInfo alloc_info{};
    alloc_info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    alloc_info.allocationSize = requirements.size;
    while (!(requirements.memoryTypeBits & (1u << alloc_info.memoryTypeIndex))) ++alloc_info.memoryTypeIndex;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    ASSERT_EQ(fn.vkAllocateMemory(device.vk(), &alloc_info, nullptr, &memory), VK_SUCCESS);
    ASSERT_EQ(fn.vkBindImageMemory(device.vk(), raw, memory, 0), VK_SUCCESS);

    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto readback = make_readback(device);
    const auto color = make_color(0xff204080);
    bool cleaned = false;
    auto cmd = pool.allocate();
    {
        auto adopted = vkrc::Image::adopt(device, raw, info, vkrc::Ownership::owned,
                                          [&cleaned, &fn, vk_device = device.vk(), memory] {
                                              fn.vkFreeMemory(vk_device, memory, nullptr);
                                              cleaned = true;
                                          });
        EXPECT_FALSE(adopted.allocation());
        cmd.begin();
        record_clear_copy(cmd, adopted, color.clear, 0, readback);
        cmd.end();
    }
    EXPECT_FALSE(cleaned);
    submit_gated_and_wait(queue, cmd, [&] { EXPECT_FALSE(cleaned); });
    EXPECT_TRUE(cleaned);
    EXPECT_TRUE(slot_holds(readback, 0, color.packed));
}

// A device made elsewhere with VK_KHR_push_descriptor. Adopted with its
// extension list, vkrc sees the extension: it makes a push-descriptor set
// layout, loads the extension's command and a pushed descriptor reaches the
// dispatch. Adopted without the list, it refuses the layout.
TEST_F(VulkanTest, AdoptedDeviceKnowsItsExtensions) {
    if (!physical_device.supports_extension(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME)) {
        GTEST_SKIP() << "the device lacks VK_KHR_push_descriptor";
    }
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = queue.family_index();
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    // What vkrc is built on (see DeviceCreateInfo).
    VkPhysicalDeviceVulkan13Features f13{};
    f13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    f13.synchronization2 = VK_TRUE;
    f13.dynamicRendering = VK_TRUE;
    f13.maintenance4 = VK_TRUE;
    VkPhysicalDeviceVulkan12Features f12{};
    f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    f12.pNext = &f13;
    f12.timelineSemaphore = VK_TRUE;
    const char* extensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
    VkDeviceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    info.pNext = &f12;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue_info;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
    VkDevice raw = VK_NULL_HANDLE;
    ASSERT_EQ(physical_device.fn().vkCreateDevice(physical_device.vk(), &info, nullptr, &raw), VK_SUCCESS);
    const std::vector<vkrc::QueueRequest> queues{{queue.family_index(), {1.0f}}};
    const vkrc::DescriptorSetLayoutCreateInfo push_layout{
        .flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR,
        .bindings = {{.binding = 0,
                      .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                      .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}};
    {
        auto unaware = vkrc::Device::adopt(physical_device, raw, vkrc::Ownership::borrowed, queues);
        EXPECT_FALSE(unaware.extension_enabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME));
        EXPECT_THROW(vkrc::DescriptorSetLayout::create(unaware, push_layout), vkrc::UsageError);
    }
    auto adopted = vkrc::Device::adopt(physical_device, raw, vkrc::Ownership::owned, queues, extensions);
    EXPECT_TRUE(adopted.extension_enabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME));
    EXPECT_FALSE(adopted.extension_enabled(VK_KHR_SWAPCHAIN_EXTENSION_NAME));
    ASSERT_NE(adopted.ext_fn().vkCmdPushDescriptorSetKHR, nullptr);
    auto set_layout = vkrc::DescriptorSetLayout::create(adopted, push_layout);
    auto layout = vkrc::PipelineLayout::create(
        adopted, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(adopted, vkrc_shaders::fill_pattern_comp));
    auto out = vkrc::Buffer::create(
        adopted, {.size = bytes, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {vkrc::MemoryUsage::readback}});
    auto pool = vkrc::CommandPool::create(adopted, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    cmd.bind_pipeline(pipeline);
    const VkDescriptorBufferInfo buffer_info{out.vk(), 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet write{};
    write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    write.dstBinding = 0;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    write.pBufferInfo = &buffer_info;
    cmd.push_descriptor_set(VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, std::span(&write, 1));
    const std::uint32_t params[2] = {static_cast<std::uint32_t>(words), 5};
    cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(params), params);
    cmd.dispatch(static_cast<std::uint32_t>(words / 64));
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    submit_and_wait(adopted.default_queue(), cmd);
    auto v = read_all(out);
    for (std::uint32_t i = 0; i < words; ++i) ASSERT_EQ(v[i], (i * 2654435761u) ^ 5u) << i;
}

// A surface on an instance made elsewhere with VK_KHR_surface and
// VK_EXT_headless_surface (here by vkrc, so that the validation layer's
// messages reach the fixture's log). Adopted with its extension list, the
// instance loads the extension's command, takes the surface (and destroys
// it, owned) and answers its queries; adopted without it, Surface::adopt
// refuses.
TEST_F(VulkanTest, SurfaceOnAnAdoptedInstance) {
    const auto available = vkrc::Instance::available_extensions();
    if (std::find(available.begin(), available.end(), VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME) == available.end()) {
        GTEST_SKIP() << "the loader offers no VK_EXT_headless_surface";
    }
    const char* extensions[] = {VK_KHR_SURFACE_EXTENSION_NAME, VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME};
    auto info = vkrc_test::validated_instance_info(log);
    info.enabled_extension_names = {extensions[0], extensions[1]};
    auto maker = vkrc::Instance::create(info);

    auto adopted =
        vkrc::Instance::adopt(maker.vk(), vkrc::Ownership::borrowed, maker.api_version(), nullptr, extensions);
    ASSERT_NE(adopted.ext_fn().vkCreateHeadlessSurfaceEXT, nullptr);
    VkHeadlessSurfaceCreateInfoEXT surface_info{};
    surface_info.sType = VK_STRUCTURE_TYPE_HEADLESS_SURFACE_CREATE_INFO_EXT;
    VkSurfaceKHR raw = VK_NULL_HANDLE;
    ASSERT_EQ(adopted.ext_fn().vkCreateHeadlessSurfaceEXT(adopted.vk(), &surface_info, nullptr, &raw), VK_SUCCESS);
    {
        auto unaware = vkrc::Instance::adopt(maker.vk(), vkrc::Ownership::borrowed, maker.api_version());
        EXPECT_THROW(vkrc::Surface::adopt(unaware, raw, vkrc::Ownership::borrowed), vkrc::UsageError);
    }
    auto surface = vkrc::Surface::adopt(adopted, raw, vkrc::Ownership::owned);
    auto requirements = vkrc_test::test_device_requirements();
    requirements.present_surface = surface.vk();
    auto physical = vkrc::PhysicalDevice::select(adopted, requirements);
    EXPECT_GE(physical.default_queue_family(), 0);
    EXPECT_GE(surface.capabilities(physical).minImageCount, 1u);
    EXPECT_FALSE(surface.formats(physical).empty());
    EXPECT_FALSE(surface.present_modes(physical).empty());
    // The borrowed instance goes with its maker, after everything made on it.
    physical.reset();
    surface.reset();
    adopted.reset();
    maker.reset();
}

#if VKRC_RUNTIME_CHECKS
// Accessors and recording through an empty handle name the type and the call.
TEST(EmptyHandle, AccessorsAndRecordingThrowUsageError) {
    vkrc::CommandBuffer cmd;
    vkrc::Buffer buffer;
    vkrc::Allocation allocation;
    vkrc_test::expect_usage_error([&] { cmd.draw(3); }, {"vkrc::CommandBuffer::draw", "empty"});
    vkrc_test::expect_usage_error([&] { cmd.begin(); }, {"vkrc::CommandBuffer::begin", "empty"});
    vkrc_test::expect_usage_error([&] { (void)cmd.vk(); }, {"vkrc::CommandBuffer::vk", "empty"});
    vkrc_test::expect_usage_error([&] { (void)buffer.size(); }, {"vkrc::Buffer::size", "empty"});
    vkrc_test::expect_usage_error([&] { allocation.write_value(0, 1u); }, {"vkrc::Allocation::write", "empty"});
    vkrc_test::expect_usage_error([&] { (void)vkrc::Device().vk(); }, {"vkrc::Device::vk", "empty"});
    vkrc_test::expect_usage_error([] { vkrc::Device().wait_idle(); }, {"vkrc::Device::wait_idle", "empty"});
    vkrc_test::expect_usage_error([] { (void)vkrc::Device().queue_for(vkrc::QueueRole::transfer); },
                                  {"vkrc::Device::queue_for", "empty"});
}
#endif

// ---------------------------------------------------------------- randomized

enum class DropPoint { before_begin, while_recording, after_end, after_submit, after_wait };
constexpr int drop_points = 5;

// What the rounds of one test recorded, to show that each kind of work ran.
struct Coverage {
    int fills = 0;
    int image_copies = 0;
    int dispatches = 0;
    int secondaries = 0;
    int fresh_devices = 0;
    int unwaited = 0;
    int drops[drop_points] = {};
};

// One round: random objects, one command buffer (its work possibly in a
// secondary) recording random operations on those still alive, submitted
// behind a gate only the host opens, and every handle, the round's instance,
// device and queue included, dropped at a random point in a random order:
// those dropped after the submit go while the GPU is certainly held. Then
// the gate opens and every round checks each operation's result in its slot
// of readback, which (with the gate and the completion semaphore) is the one
// thing kept. A round that waits waits on its fence; one that does not may
// drop the fence with the work in flight and waits on the completion value.
// A round's completion semaphore and gate; the gate goes first, waiting for
// the device to be idle before either is destroyed (see GpuGate).
struct RoundSync {
    vkrc::Semaphore done;
    vkrc_test::GpuGate gate;
    explicit RoundSync(const vkrc::Device& device) : done(vkrc::Semaphore::create_timeline(device)), gate(device) {}
};

struct Round {
    std::mt19937& rng;
    Coverage& coverage;
    Objects o;

    int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }
    DropPoint point_in(DropPoint first, DropPoint last) {
        return static_cast<DropPoint>(static_cast<int>(first) +
                                      pick(static_cast<int>(last) - static_cast<int>(first) + 1));
    }

    void run(bool wait) {
        auto& device = o.device;
        const RoundSync sync(device);
        const auto& [done, gate] = sync;
        o.pool = vkrc::CommandPool::create(device, {.queue_family_index = o.queue.family_index()});
        o.cmd = o.pool.allocate();
        o.fence = vkrc::Fence::create(device);
        o.readback = make_readback(device);
        if (pick(4) != 0) {
            o.source = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        }
        if (pick(5) != 0) {
            o.image = make_image(device);
            if (pick(8) != 0) make_sampling_objects(o, device);
        }
        if (pick(4) == 0) o.secondary = o.pool.allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        const int ops = 1 + pick(slots);

        // Each handle's drop: a point, and for while_recording the operation
        // it comes before (ops: after the last, before end()).
        struct Item {
            std::function<void()> drop;
            DropPoint point;
            int before_op;
        };
        std::vector<Item> items;
        auto add = [&](auto& handle, DropPoint first, DropPoint last) {
            if (!handle) return;
            const auto point = point_in(first, last);
            items.push_back(
                {[&handle] { handle = {}; }, point, point == DropPoint::while_recording ? pick(ops + 1) : 0});
        };
        constexpr auto any_first = DropPoint::before_begin;
        constexpr auto any_last = DropPoint::after_wait;
        add(o.instance, any_first, any_last);
        add(o.device, any_first, any_last);
        add(o.queue, any_first, any_last);
        add(o.pool, any_first, any_last);
        add(o.cmd, DropPoint::after_submit, any_last);  // needed to submit
        add(o.fence, wait ? DropPoint::after_wait : DropPoint::after_submit, any_last);
        // Every operation copies into readback, which every round reads after the work.
        add(o.source, any_first, any_last);
        add(o.storage, any_first, any_last);
        add(o.image, any_first, any_last);
        add(o.view, any_first, any_last);
        add(o.sampler, any_first, any_last);
        add(o.set_layout, any_first, any_last);
        add(o.descriptor_pool, any_first, any_last);
        add(o.set, any_first, any_last);
        add(o.layout, any_first, any_last);
        add(o.pipeline, any_first, any_last);
        if (o.secondary) {
            // Not while it records: the drop comes after the primary executed it.
            const auto point = point_in(any_first, any_last);
            items.push_back({[this] { o.secondary = {}; }, point, point == DropPoint::while_recording ? ops : 0});
        }
        std::shuffle(items.begin(), items.end(), rng);
        for (const auto& item : items) ++coverage.drops[static_cast<int>(item.point)];
        auto drop_at = [&](DropPoint p, int before_op = 0) {
            for (auto& item : items) {
                if (item.point == p && item.before_op == before_op) item.drop();
            }
        };

        // What each slot of readback should hold; unset: no operation wrote it.
        std::optional<std::uint32_t> expected[slots];
        drop_at(DropPoint::before_begin);
        o.cmd.begin(pick(2) ? VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT : 0);
        const bool in_secondary = bool(o.secondary);
        if (in_secondary) {
            o.secondary.begin_secondary();
            ++coverage.secondaries;
        }
        const vkrc::CommandBuffer& recorder = in_secondary ? o.secondary : o.cmd;
        for (int op = 0; op < ops; ++op) {
            drop_at(DropPoint::while_recording, op);
            expected[op] = record_one(recorder, op);
        }
        if (in_secondary) {
            o.secondary.end();
            o.cmd.execute_commands(std::span(&o.secondary, 1));
        }
        drop_at(DropPoint::while_recording, ops);
        o.cmd.end();
        drop_at(DropPoint::after_end);
        const auto queue = o.queue ? o.queue : o.cmd.pool().device().default_queue();
        const auto held = gate.wait();
        const vkrc::SemaphoreSubmit finished{done, 1};
        vkrc::submit(
            queue,
            {.waits = std::span(&held, 1), .command_buffers = std::span(&o.cmd, 1), .signals = std::span(&finished, 1)},
            o.fence);
        drop_at(DropPoint::after_submit);
        ASSERT_EQ(done.value(), 0u) << "the work ran before the gate opened";
        gate.open();
        if (wait) {
            ASSERT_EQ(o.fence.wait(), VK_SUCCESS);
        } else {
            ASSERT_EQ(done.wait(1), VK_SUCCESS);
            ++coverage.unwaited;
        }
        for (int slot = 0; slot < slots; ++slot) {
            if (expected[slot]) {
                ASSERT_TRUE(slot_holds(o.readback, slot, *expected[slot])) << "slot " << slot;
            }
        }
        drop_at(DropPoint::after_wait);
    }

    // Records one operation on objects still alive into slot; what the slot
    // will hold, or nothing when no operation's objects are alive.
    std::optional<std::uint32_t> record_one(const vkrc::CommandBuffer& cmd, int slot) {
        enum Kind { fill, image_copy, dispatch };
        std::vector<Kind> kinds;
        if (o.source) kinds.push_back(fill);
        if (o.image || o.view) kinds.push_back(image_copy);
        // The set keeps none of what it points at alive: each must be.
        if (o.view && o.sampler && o.storage && o.set && o.pipeline) kinds.push_back(dispatch);
        if (kinds.empty()) return std::nullopt;
        const auto color = make_color(static_cast<std::uint32_t>(rng()));
        // The dispatch, which needs the most objects alive, is picked first half the time.
        const auto kind = kinds.back() == dispatch && pick(2) == 0
                              ? dispatch
                              : kinds[static_cast<std::size_t>(pick(static_cast<int>(kinds.size())))];
        switch (kind) {
            case fill: {
                const auto value = static_cast<std::uint32_t>(rng());
                cmd.fill_buffer(o.source, 0, slot_bytes, value);
                transfer_barrier(cmd);
                VkBufferCopy region{0, static_cast<VkDeviceSize>(slot) * slot_bytes, slot_bytes};
                cmd.copy_buffer(o.source, o.readback, std::span(&region, 1));
                transfer_barrier(cmd);
                ++coverage.fills;
                return value;
            }
            case image_copy:
                record_clear_copy(cmd, o.image ? o.image : o.view.image(), color.clear, slot, o.readback);
                ++coverage.image_copies;
                return color.packed;
            case dispatch:
                record_sample(cmd, o, color.clear, slot, o.readback);
                ++coverage.dispatches;
                return color.packed;
        }
        return std::nullopt;
    }
};

// Every 20th round makes its own instance and device, so that the round's
// handles to them may go at any point (its gate, completion semaphore and
// readback keep the Vulkan objects until the round's end); the other
// rounds drop their copies of the fixture's. One round in eight (one in
// two of those with a fresh device) does not wait on its fence. The seed
// comes from VKRC_TEST_SEED when set (test_seed), to replay a failing run.
TEST_F(VulkanTest, RandomDropPointsAndOrders) {
    const auto seed = vkrc_test::test_seed();
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    Coverage coverage;
    for (int round = 0; round < 500; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        Round r{rng, coverage, {}};
        if (round % 20 == 19) {
            r.o.instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
            r.o.device =
                vkrc::Device::create(vkrc::PhysicalDevice::select(r.o.instance, vkrc_test::test_device_requirements()));
            ++coverage.fresh_devices;
        } else {
            r.o.instance = instance;
            r.o.device = device;
        }
        r.o.queue = r.o.device.default_queue();
        // Half the fresh devices go with their work in flight.
        r.run(round % 20 == 19 ? r.pick(2) != 0 : r.pick(8) != 0);
        if (HasFatalFailure()) return;
        // Here rather than at TearDown, to name the round.
        const auto messages = log->take();
        ASSERT_TRUE(messages.empty()) << messages.front();
    }
    std::printf(
        "fills %d, image copies %d, dispatches %d, in a secondary %d, fresh devices %d, unwaited %d; drops before "
        "begin %d, while recording %d, after end %d, after submit %d, after wait %d\n",
        coverage.fills, coverage.image_copies, coverage.dispatches, coverage.secondaries, coverage.fresh_devices,
        coverage.unwaited, coverage.drops[0], coverage.drops[1], coverage.drops[2], coverage.drops[3],
        coverage.drops[4]);
    // 500 rounds reach every kind of work and every drop point (a seed that
    // did not would say little).
    EXPECT_GT(coverage.fills, 0);
    EXPECT_GT(coverage.image_copies, 0);
    EXPECT_GT(coverage.dispatches, 0);
    EXPECT_GT(coverage.secondaries, 0);
    for (int d : coverage.drops) EXPECT_GT(d, 0);
    device.wait_idle();
    EXPECT_EQ(device.deferred_count(), 0u);
}

#if VKRC_IS_MULTI_THREAD
// Eight threads record into their own pools and drop what they recorded at
// random points, on a shared device and queue.
TEST_F(VulkanTest, EightThreadsRecordAndDrop) {
    const auto seed = vkrc_test::test_seed();
    std::vector<std::thread> threads;
    std::atomic<int> failures{0};
    for (unsigned t = 0; t < 8; ++t) {
        threads.emplace_back([&, t] {
            std::mt19937 rng(seed + t);
            auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
            auto readback = make_readback(device);
            auto fence = vkrc::Fence::create(device);
            for (int i = 0; i < 40; ++i) {
                auto buffer = make_buffer(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
                auto cmd = pool.allocate();
                const int drop = static_cast<int>(rng() % 3);
                cmd.begin();
                record_fill_copy(cmd, buffer, readback, i + 1);
                if (drop == 0) buffer.reset();
                cmd.end();
                if (drop == 1) buffer.reset();
                vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
                if (drop == 2) cmd.reset();
                buffer.reset();
                if (fence.wait() != VK_SUCCESS || !all_equal(readback, i + 1)) failures.fetch_add(1);
                fence.unsignal();
            }
        });
    }
    for (auto& t : threads) t.join();
    EXPECT_EQ(failures.load(), 0);
    device.wait_idle();
    EXPECT_EQ(device.deferred_count(), 0u);
}
#endif

}  // namespace
