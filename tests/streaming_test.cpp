// Queue roles, the Uploader (staging ring, tickets, ownership transfers,
// downloads), the per-frame ring and async compute. lavapipe has one queue
// family: the separate-family (ownership transfer) paths run where the
// device has a dedicated transfer family and skip otherwise.
#include "support/fault_injection.hpp"
#include "support/vk_test.hpp"
#include "support/watchdog.hpp"

#include "shaders/fill_pattern.comp.h"
#include "shaders/read_uniform.comp.h"
#include "shaders/sample_texels.comp.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

// The fixture's device with a transfer and a compute queue besides graphics.
class StreamingTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        device = vkrc::Device::create(physical_device, {.transfer_queue = true, .compute_queue = true});
        queue = device.queue_for(vkrc::QueueRole::graphics).queue;
        transfer = device.queue_for(vkrc::QueueRole::transfer).queue;
        compute = device.queue_for(vkrc::QueueRole::compute).queue;
    }
    void TearDown() override {
        transfer = {};
        compute = {};
        VulkanTest::TearDown();
    }

    vkrc::Buffer device_buffer(VkDeviceSize size, VkBufferUsageFlags usage = 0) {
        return vkrc::Buffer::create(
            device,
            {.size = size, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | usage});
    }

    vkrc::Queue transfer, compute;
};

std::vector<std::byte> random_bytes(std::mt19937& rng, std::size_t n) {
    std::vector<std::byte> out(n);
    for (auto& b : out) b = std::byte(rng() & 0xff);
    return out;
}

TEST_F(VulkanTest, StreamingQueuesDefaultDeviceSharesTheGraphicsQueue) {
    const auto graphics = device.queue_for(vkrc::QueueRole::graphics);
    EXPECT_TRUE(graphics.queue == device.default_queue());
    EXPECT_FALSE(graphics.shares_graphics_queue);
    for (auto role : {vkrc::QueueRole::transfer, vkrc::QueueRole::compute}) {
        const auto a = device.queue_for(role);
        // One queue requested: every role's work goes to it.
        EXPECT_TRUE(a.queue == graphics.queue);
        EXPECT_TRUE(a.shares_graphics_queue);
    }
}

TEST_F(StreamingTest, StreamingQueuesRolesAreReportedAsFound) {
    const auto& families = physical_device.queue_families();
    const auto graphics = device.queue_for(vkrc::QueueRole::graphics);
    EXPECT_TRUE(families[graphics.queue.family_index()].queueFlags & VK_QUEUE_GRAPHICS_BIT);
    const std::uint32_t graphics_queues = families[graphics.queue.family_index()].queueCount;
    std::uint32_t extra_queues = 0;  // besides graphics, in the graphics family
    for (auto role : {vkrc::QueueRole::transfer, vkrc::QueueRole::compute}) {
        const auto a = device.queue_for(role);
        const int dedicated = vkrc::find_dedicated_queue_family(physical_device, role);
        std::printf("role %d: family %u queue %u dedicated %d shared %d (graphics family has %u queues)\n",
                    static_cast<int>(role), a.queue.family_index(), a.queue.index(), a.dedicated_family,
                    a.shares_graphics_queue, graphics_queues);
        if (dedicated >= 0) {
            EXPECT_EQ(a.queue.family_index(), static_cast<std::uint32_t>(dedicated));
            EXPECT_TRUE(a.dedicated_family);
            EXPECT_FALSE(a.shares_graphics_queue);
        } else if (1 + ++extra_queues <= graphics_queues) {
            EXPECT_EQ(a.queue.family_index(), graphics.queue.family_index());
            EXPECT_FALSE(a.queue == graphics.queue);
            EXPECT_FALSE(a.shares_graphics_queue);
        } else {
            EXPECT_TRUE(a.queue == graphics.queue);
            EXPECT_TRUE(a.shares_graphics_queue);
        }
    }
    const auto t = vkrc::find_dedicated_queue_family(physical_device, vkrc::QueueRole::transfer);
    if (t >= 0) {
        EXPECT_FALSE(families[t].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT));
    }
}

TEST_F(VulkanTest, StreamingQueuesExplicitRequestsGetRoles) {
    const std::uint32_t family = queue.family_index();
    if (physical_device.queue_families()[family].queueCount < 2) {
        GTEST_SKIP() << "needs two queues in the graphics family (the device has one)";
    }
    device = vkrc::Device::create(physical_device, {.queue_requests = {{family, {1.0f, 0.5f}}}});
    const auto transfer = device.queue_for(vkrc::QueueRole::transfer);
    EXPECT_EQ(transfer.queue.index(), 1u);
    EXPECT_FALSE(transfer.shares_graphics_queue);
    // The compute role finds no third queue and shares graphics'.
    EXPECT_TRUE(device.queue_for(vkrc::QueueRole::compute).shares_graphics_queue ||
                vkrc::find_dedicated_queue_family(physical_device, vkrc::QueueRole::compute) >= 0);
    queue = device.default_queue();
}

// Uploads of random sizes, batches of ten submitted without a wait, each
// batch into a destination of its own (so that each is one ownership
// transfer when the families differ) and consumed by a graphics submission
// (a clear of an image: the rendering stand-in, and a copy of the batch's
// bytes into a result) that waits on the batch's ticket; a 256 KiB ring
// wraps and waits for its oldest batch many times.
TEST_F(StreamingTest, UploaderThousandRandomUploadsInFlightWithRendering) {
    vkrc_test::Watchdog watchdog("1000 uploads");
    std::mt19937 rng(vkrc_test::test_seed());
    constexpr int uploads = 1000, per_batch = 10;
    std::vector<std::size_t> sizes(uploads);
    VkDeviceSize total = 0;
    for (auto& s : sizes) total += s = 4 * (1 + rng() % 8192);  // 4 B to 32 KiB
    std::vector<std::byte> expected = random_bytes(rng, total);
    auto result = device_buffer(total);
    auto image = vkrc::Image::create(
        device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .extent = {32, 32, 1}, .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    auto uploader = vkrc::Uploader::create({.queue = transfer, .staging_size = 256 << 10});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkDeviceSize offset = 0;
    for (int batch = 0; batch < uploads / per_batch; ++batch) {
        const VkDeviceSize batch_start = offset;
        for (int i = batch * per_batch; i < (batch + 1) * per_batch; ++i) offset += sizes[i];
        auto dst = device_buffer(offset - batch_start);
        for (VkDeviceSize at = batch_start, i = batch * per_batch; at < offset; at += sizes[i++]) {
            uploader.upload_buffer(dst, at - batch_start, std::span(expected).subspan(at, sizes[i]));
        }
        const vkrc::Ticket ticket = uploader.submit();
        auto cmd = pool.allocate();
        cmd.begin();
        ticket.record_acquire(cmd);
        auto to_dst = vkrc::image_barrier(image.vk(), layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                          VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                          VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        cmd.pipeline_barrier({}, {}, {&to_dst, 1});
        layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        const VkClearColorValue color{{float(batch % 7) / 7.0f, 0.0f, 0.0f, 1.0f}};
        const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        cmd.fn().vkCmdClearColorImage(cmd.vk(), image.vk(), layout, &color, 1, &range);
        const VkBufferCopy region{0, batch_start, offset - batch_start};
        cmd.copy_buffer(dst, result, {&region, 1});
        cmd.end();
        const vkrc::SemaphoreSubmit wait = ticket.wait(VK_PIPELINE_STAGE_2_COPY_BIT);
        vkrc::submit(queue, {.waits = {&wait, 1}, .command_buffers = {&cmd, 1}});
    }
    queue.wait_idle();
    const auto got = vkrc::download_buffer(queue, result, 0, total);
    ASSERT_EQ(got.size(), expected.size());
    EXPECT_EQ(std::memcmp(got.data(), expected.data(), expected.size()), 0);
}

// Ownership transfer from a dedicated transfer family to the graphics
// family: the release in the Uploader's batch, the acquire from the ticket.
TEST_F(StreamingTest, OwnershipTransferToTheGraphicsFamily) {
    if (transfer.family_index() == queue.family_index()) {
        GTEST_SKIP() << "needs a transfer queue of another family than graphics (a dedicated transfer family)";
    }
    std::mt19937 rng(vkrc_test::test_seed());
    const auto data = random_bytes(rng, 1 << 16);
    auto dst = device_buffer(data.size());
    auto uploader = vkrc::Uploader::create({.queue = transfer});
    uploader.upload_buffer(dst, 0, data);
    const auto ticket = uploader.submit();
    EXPECT_EQ(ticket.buffer_acquires.size(), 1u);
    auto readback = vkrc::Uploader::create({.queue = queue});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    ticket.record_acquire(cmd);
    cmd.end();
    const auto wait = ticket.wait();
    vkrc::submit(queue, {.waits = {&wait, 1}, .command_buffers = {&cmd, 1}});
    auto download = readback.download_buffer(dst, 0, data.size());
    readback.submit();
    const auto got = download.read();
    EXPECT_EQ(std::memcmp(got.data(), data.data(), data.size()), 0);
}

// Texel value of level, layer 0, at x, y: distinct per level and position.
std::uint32_t texel(std::uint32_t level, std::uint32_t x, std::uint32_t y) {
    return 0xff000000u | (level * 37u) << 16 | (y & 0xff) << 8 | (x & 0xff);
}

// Every level of a 64x32 texture uploaded through the ring, then fetched
// through a sampler by a compute shader on the graphics queue, which waits
// on the ticket; each texel is compared.
TEST_F(StreamingTest, UploaderEveryMipUploadedAsynchronouslyIsSampledTexelByTexel) {
    const VkExtent3D extent{64, 32, 1};
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                              .extent = extent,
                                              .mip_levels = 7,
                                              .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
    std::vector<std::uint32_t> texels;
    std::vector<std::uint32_t> level_base;
    for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
        level_base.push_back(static_cast<std::uint32_t>(texels.size()));
        const auto e = image.extent(level);
        for (std::uint32_t y = 0; y < e.height; ++y)
            for (std::uint32_t x = 0; x < e.width; ++x) texels.push_back(texel(level, x, y));
    }
    auto uploader = vkrc::Uploader::create({.queue = transfer, .staging_size = 1 << 16});
    uploader.upload_image(image, std::as_bytes(std::span(texels)));
    const auto ticket = uploader.submit();

    auto view = vkrc::ImageView::create(image);
    auto sampler = vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST, .min_filter = VK_FILTER_NEAREST});
    auto out = device_buffer(texels.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    auto set_layout = vkrc_test::sample_texels_set_layout(device);
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 16}}});
    auto descriptors = vkrc::DescriptorPool::create(
        device,
        {.max_sets = 1,
         .pool_sizes = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptors.allocate(set_layout);
    set.write_image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    sampler);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::sample_texels_comp));
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    ticket.record_acquire(cmd);
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
        const auto e = image.extent(level);
        const std::uint32_t params[4] = {level, e.width, e.height, level_base[level]};
        cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof params, params);
        cmd.dispatch((e.width + 7) / 8, (e.height + 7) / 8);
    }
    cmd.end();
    const auto wait = ticket.wait(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    vkrc::submit(queue, {.waits = {&wait, 1}, .command_buffers = {&cmd, 1}});
    const auto got = vkrc::download_buffer(queue, out, 0, texels.size() * 4);
    std::vector<std::uint32_t> fetched(texels.size());
    std::memcpy(fetched.data(), got.data(), got.size());
    for (std::size_t i = 0; i < texels.size(); ++i) ASSERT_EQ(fetched[i], texels[i]) << "texel " << i;
}

// A BC1 texture with every level: uploaded in whole 4x4 blocks (the 2x2 and
// 1x1 levels take one block each), read back block for block.
TEST_F(StreamingTest, UploaderBlockCompressedImageByBlockSize) {
    VkFormatProperties props{};
    instance.fn().vkGetPhysicalDeviceFormatProperties(physical_device.vk(), VK_FORMAT_BC1_RGBA_UNORM_BLOCK, &props);
    constexpr VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_TRANSFER_DST_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    if ((props.optimalTilingFeatures & needed) != needed) {
        GTEST_SKIP() << "the device has no BC1 (textureCompressionBC) transfer support";
    }
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_BC1_RGBA_UNORM_BLOCK,
                                     .extent = {16, 8, 1},
                                     .mip_levels = 5,
                                     .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    // 4x2 + 2x1 + 1 + 1 + 1 blocks of 8 bytes.
    ASSERT_EQ(vkrc::image_data_size(image), (8u + 2 + 1 + 1 + 1) * 8);
    std::mt19937 rng(vkrc_test::test_seed());
    const auto data = random_bytes(rng, vkrc::image_data_size(image));
    auto uploader = vkrc::Uploader::create({.queue = transfer, .consumer_family = transfer.family_index()});
    uploader.upload_image(image, data, {.new_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL});
    std::vector<vkrc::Download> levels;
    for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
        levels.push_back(uploader.download_image(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, level));
    }
    uploader.submit();
    std::size_t at = 0;
    for (const auto& d : levels) {
        const auto got = d.read();
        EXPECT_EQ(std::memcmp(got.data(), data.data() + at, got.size()), 0);
        at += got.size();
    }
    EXPECT_EQ(at, data.size());
}

// Level 0 alone (ImageUploadInfo::level_count), the rest filled on the GPU
// by generate_mipmaps: every level reads back, level 0 as uploaded and each
// smaller one the average of a uniform colour (the same colour).
TEST_F(StreamingTest, UploaderBaseLevelThenGeneratedMips) {
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                              .extent = {16, 8, 1},
                                              .mip_levels = 5,
                                              .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                                       VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
    ASSERT_EQ(vkrc::image_data_size(image, 1), 16u * 8 * 4);
    const std::vector<std::uint32_t> base(16 * 8, 0x80402010u);
    auto uploader = vkrc::Uploader::create({.queue = queue});
    EXPECT_THROW(uploader.upload_image(image, std::as_bytes(std::span(base)), {.level_count = 0}), vkrc::UsageError);
    EXPECT_THROW(uploader.upload_image(image, std::as_bytes(std::span(base)), {.level_count = 6}), vkrc::UsageError);
    EXPECT_THROW(uploader.upload_image(image, std::as_bytes(std::span(base)), {.level_count = 2}), vkrc::UsageError);
    uploader.upload_image(image, std::as_bytes(std::span(base)),
                          {.new_layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, .level_count = 1});
    const auto ticket = uploader.submit();
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    vkrc::generate_mipmaps(cmd, image,
                           {.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            .dst_stage = VK_PIPELINE_STAGE_2_COPY_BIT,
                            .dst_access = VK_ACCESS_2_TRANSFER_READ_BIT});
    cmd.end();
    const auto wait = ticket.wait(VK_PIPELINE_STAGE_2_BLIT_BIT);
    vkrc::submit(queue, {.waits = {&wait, 1}, .command_buffers = {&cmd, 1}});
    for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
        const auto got = vkrc::download_image(queue, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, level);
        ASSERT_EQ(got.size(), std::size_t(image.extent(level).width) * image.extent(level).height * 4);
        for (std::size_t i = 0; i < got.size(); i += 4) {
            std::uint32_t texel;
            std::memcpy(&texel, got.data() + i, 4);
            ASSERT_EQ(texel, 0x80402010u) << "level " << level << " byte " << i;
        }
    }
}

TEST_F(StreamingTest, UploaderDownloadIsNonBlocking) {
    std::mt19937 rng(vkrc_test::test_seed());
    const auto data = random_bytes(rng, 4096);
    auto buffer = device_buffer(data.size());
    vkrc::upload_buffer(transfer, buffer, 0, data);
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto uploader = vkrc::Uploader::create({.queue = transfer, .consumer_family = transfer.family_index()});
    auto download = uploader.download_buffer(buffer, 16, 1024);
    EXPECT_THROW(download.read(), vkrc::UsageError);  // not submitted yet
    const vkrc::SemaphoreSubmit wait{gate, 1};
    const auto ticket = uploader.submit({&wait, 1});
    EXPECT_FALSE(ticket.done());  // held back by the gate: the submit did not wait
    gate.signal(1);
    const auto got = download.read();
    EXPECT_TRUE(ticket.done());
    EXPECT_EQ(std::memcmp(got.data(), data.data() + 16, 1024), 0);
}

TEST_F(StreamingTest, UploaderRejectsBadInput) {
    auto uploader = vkrc::Uploader::create({.queue = transfer, .staging_size = 1024});
    auto buffer = device_buffer(4096);
    std::vector<std::byte> big(2048);
    try {
        uploader.upload_buffer(buffer, 0, big);
        FAIL() << "no UsageError";
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("vkrc::Uploader::upload_buffer"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("staging ring"), std::string::npos) << e.what();
    }
    EXPECT_THROW(uploader.upload_buffer(buffer, 4000, std::span(big).first(200)), vkrc::UsageError);
    EXPECT_THROW(vkrc::Uploader::create({}), vkrc::UsageError);
    EXPECT_THROW(vkrc::Ticket{}.wait(), vkrc::UsageError);
    EXPECT_FALSE(uploader.submit());  // nothing recorded, nothing submitted before
}

// Everything dropped, in several orders, while batches are in flight and held
// back by a gate only the host opens: nothing may be destroyed early (the
// validation layer would report it) and teardown does not hang.
TEST_F(StreamingTest, UploaderDropEverythingWhileUploadsInFlight) {
    vkrc_test::Watchdog watchdog("dropping uploads in flight");
    auto gate = vkrc::Semaphore::create_timeline(device);
    // The destinations stay; the Uploader (with its staging ring), the
    // batches and a download go while the gate holds them back.
    std::vector<vkrc::Buffer> buffers;
    std::vector<std::vector<std::byte>> uploaded;
    {
        std::mt19937 rng(vkrc_test::test_seed());
        auto uploader = vkrc::Uploader::create(
            {.queue = transfer, .consumer_family = transfer.family_index(), .staging_size = 1 << 20});
        const vkrc::SemaphoreSubmit wait{gate, 1};
        for (int i = 0; i < 20; ++i) {
            buffers.push_back(device_buffer(16 << 10));
            uploaded.push_back(random_bytes(rng, 16 << 10));
            uploader.upload_buffer(buffers.back(), 0, uploaded.back());
            if (i % 4 == 3) uploader.submit({&wait, 1});
        }
        uploader.download_buffer(device_buffer(64), 0, 64);
        uploader.submit({&wait, 1});
    }
    EXPECT_GT(device.deferred_count(), 0u);
    gate.signal(1);
    device.wait_idle();
    EXPECT_EQ(device.deferred_count(), 0u);
    // What the dropped staging ring carried arrived.
    for (std::size_t i = 0; i < buffers.size(); ++i) {
        const auto got = vkrc::download_buffer(transfer, buffers[i], 0, 16 << 10);
        EXPECT_TRUE(std::equal(got.begin(), got.end(), uploaded[i].begin(), uploaded[i].end())) << "upload " << i;
    }
}

// Device lost while batches are in flight: the next submit reports it, the
// tickets stop waiting, and every handle drops without a hang.
TEST(UploaderDeviceLoss, DeviceLossDuringAnUpload) {
    namespace faults = vkrc_test::faults;
    vkrc_test::Watchdog watchdog("device loss during an upload");
    faults::arm(0, VK_SUCCESS);
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    auto info = vkrc_test::validated_instance_info(log);
    info.get_instance_proc_addr = faults::get_instance_proc_addr();
    auto instance = vkrc::Instance::create(info);
    auto physical = vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements());
    auto device = vkrc::Device::create(physical, {.transfer_queue = true});
    auto transfer = device.queue_for(vkrc::QueueRole::transfer).queue;
    auto uploader = vkrc::Uploader::create({.queue = transfer, .staging_size = 1 << 16});
    // Room for every upload below at its own offset: uploads of one batch are
    // not ordered against each other (synchronization validation reports
    // overlapping ones as a write-after-write hazard).
    auto buffer = vkrc::Buffer::create(device, {.size = 10 << 14, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT});
    std::vector<std::byte> data(1 << 14, std::byte{7});
    uploader.upload_buffer(buffer, 0, data);
    const auto first = uploader.submit();
    uploader.upload_buffer(buffer, 1 << 14, data);
    faults::lose_device();
    EXPECT_THROW(uploader.submit(), vkrc::DeviceLostError);
    EXPECT_TRUE(device.lost());
    try {
        first.wait_on_host();  // returns or reports the loss; never hangs
    } catch (const vkrc::DeviceLostError&) {}
    // The ring keeps working as far as the host goes: space is reclaimed without waiting.
    for (int i = 0; i < 8; ++i) {
        try {
            uploader.upload_buffer(buffer, VkDeviceSize(i + 2) << 14, data);
        } catch (const vkrc::DeviceLostError&) {}
    }
    uploader = {};
    buffer = {};
    transfer = {};
    device = {};
    physical = {};
    instance = {};
    faults::arm(0, VK_SUCCESS);
    vkrc_test::expect_no_validation_messages(*log);
}

// Three frames in flight, each held on the GPU by a gate the host opens
// later; the fourth begin_frame must wait for the first frame only, and no
// frame's data is overwritten while its copy is pending.
TEST_F(StreamingTest, RingWrapsWhileOlderFramesAreStillOnTheGpu) {
    vkrc_test::Watchdog watchdog("frame ring");
    constexpr std::uint32_t frames = 3;
    constexpr VkDeviceSize slice = 256;
    auto ring = vkrc::FrameRing::create({.queue = queue,
                                         .frame_size = 4 * slice,
                                         .frames_in_flight = frames,
                                         .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    auto result = device_buffer(slice * 8);
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    std::atomic<int> opened{0};
    std::thread opener;
    for (std::uint32_t frame = 0; frame < 8; ++frame) {
        if (frame == frames) {
            // Frames 0..2 wait for the gate; begin_frame of frame 3 reuses frame 0's block.
            opener = std::thread([&] {
                std::this_thread::sleep_for(std::chrono::milliseconds(100));
                opened.store(1);
                gate.signal(1);
            });
        }
        ring.begin_frame();
        if (frame == frames) EXPECT_EQ(opened.load(), 1) << "the block was reused before its frame completed";
        EXPECT_EQ(ring.frame_index(), frame % frames);
        auto a = ring.allocate(slice);
        EXPECT_EQ(a.offset % physical_device.properties().limits.minUniformBufferOffsetAlignment, 0u);
        std::vector<std::uint8_t> bytes(slice, static_cast<std::uint8_t>(frame + 1));
        a.view.write(0, std::span<const std::uint8_t>(bytes));
        EXPECT_THROW(ring.allocate(4 * slice), vkrc::UsageError);  // no room left in the block
        auto cmd = pool.allocate();
        cmd.begin();
        const VkBufferCopy region{a.offset, frame * slice, slice};
        cmd.copy_buffer(a.buffer, result.vk(), {&region, 1});
        cmd.end();
        const vkrc::SemaphoreSubmit wait{gate, 1};
        vkrc::submit(queue, {.waits = {&wait, 1}, .command_buffers = {&cmd, 1}});
        ring.end_frame();
    }
    opener.join();
    queue.wait_idle();
    const auto got = vkrc::download_buffer(queue, result, 0, slice * 8);
    for (std::uint32_t frame = 0; frame < 8; ++frame) {
        EXPECT_EQ(static_cast<std::uint8_t>(got[frame * slice]), frame + 1) << "frame " << frame;
        EXPECT_EQ(static_cast<std::uint8_t>(got[frame * slice + slice - 1]), frame + 1) << "frame " << frame;
    }
    // A layer false positive: with synchronization validation on, the
    // Khronos layer 1.3.239 may miss the gate's value signalled from the host
    // on the opener thread while this one waits in begin_frame; it then gives
    // up after its timeout and reports "Timeout waiting for timeline
    // semaphore state to update. This is most likely a validation bug." How
    // often depends on timing (on lavapipe 0, 3 or 4 times: the two
    // semaphores waited on, each at most twice), so at most 4 of exactly
    // that id are allowed. The values above show the frames ran after the
    // gate and in order; any other message still fails the test.
    const auto messages = log->take();
    const auto timeouts = std::count_if(messages.begin(), messages.end(), [](const std::string& m) {
        return m.starts_with("UNASSIGNED-VkSemaphore-state-timeout: ");
    });
    EXPECT_LE(timeouts, 4) << "layer timeouts";
    EXPECT_EQ(messages.size(), std::size_t(timeouts)) << messages.front();
    EXPECT_THROW(ring.end_frame(), vkrc::UsageError);
    EXPECT_THROW(ring.allocate(4), vkrc::UsageError);
}

// Three dispatches read their own ring allocation through one dynamic
// uniform descriptor; each copies what it read into its slot of out.
TEST_F(StreamingTest, RingDynamicUniformDescriptor) {
    auto ring = vkrc::FrameRing::create({.queue = queue});
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT},
                              {.binding = 1,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto descriptors = vkrc::DescriptorPool::create(
        device,
        {.max_sets = 1,
         .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptors.allocate(set_layout);
    auto out = vkrc::Buffer::create(
        device, {.size = 16, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {vkrc::MemoryUsage::readback}});
    vkrc::write_dynamic_buffer(set, 0, ring, 64);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 4}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::read_uniform_comp));
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    ring.begin_frame();
    cmd.begin();
    cmd.bind_pipeline(pipeline);
    for (std::uint32_t draw = 0; draw < 3; ++draw) {
        auto a = ring.allocate(64);
        a.view.write_value(0, 100 + draw);
        const VkDescriptorSet raw = set.vk();
        const std::uint32_t offset = a.dynamic_offset();
        cmd.fn().vkCmdBindDescriptorSets(cmd.vk(), VK_PIPELINE_BIND_POINT_COMPUTE, layout.vk(), 0, 1, &raw, 1, &offset);
        cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, draw);
        cmd.dispatch(1, 1);
        // Each writes its own word of out, but through the same descriptor:
        // ordered, as synchronization validation tracks the whole range.
        auto after = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        cmd.pipeline_barrier(std::span(&after, 1), {}, {});
    }
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    vkrc::submit(queue, {.command_buffers = {&cmd, 1}});
    ring.end_frame();
    queue.wait_idle();
    for (std::uint32_t draw = 0; draw < 3; ++draw) {
        EXPECT_EQ(out.allocation().read_value<std::uint32_t>(draw * 4), 100 + draw) << "dispatch " << draw;
    }
}

// fill_pattern on the compute queue, behind a host gate; the graphics queue
// waits on the compute submission's timeline value and copies the result.
// The buffer, dropped while both are pending, waits for both queues.
TEST_F(StreamingTest, AsyncComputeBesideGraphicsWithTimelineWaits) {
    constexpr std::uint32_t count = 4096;
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp));
    auto descriptors =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    // Used by both queues: concurrent when they are of two families.
    vkrc::BufferCreateInfo shared_info{.size = count * 4,
                                       .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT};
    if (compute.family_index() != queue.family_index()) {
        shared_info.sharing_mode = VK_SHARING_MODE_CONCURRENT;
        shared_info.queue_family_indices = {queue.family_index(), compute.family_index()};
    }
    auto shared = vkrc::Buffer::create(device, shared_info);
    auto result = device_buffer(count * 4);
    auto set = descriptors.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, shared);
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto done = vkrc::Semaphore::create_timeline(device);
    auto compute_pool = vkrc::CommandPool::create(device, {.queue_family_index = compute.family_index()});
    auto graphics_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto c = compute_pool.allocate();
    c.begin();
    c.bind_pipeline(pipeline);
    c.bind_descriptor_set(pipeline, 0, set);
    const std::uint32_t params[2] = {count, 0x5eed};
    c.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof params, params);
    c.dispatch(count / 64);
    c.end();
    const vkrc::SemaphoreSubmit gate1{gate, 1}, signal_done{done, 1};
    vkrc::submit(compute, {.waits = {&gate1, 1}, .command_buffers = {&c, 1}, .signals = {&signal_done, 1}});
    auto g = graphics_pool.allocate();
    g.begin();
    const VkBufferCopy region{0, 0, count * 4};
    g.copy_buffer(shared, result, {&region, 1});
    g.end();
    const vkrc::SemaphoreSubmit waits[] = {{done, 1, VK_PIPELINE_STAGE_2_COPY_BIT}, {gate, 2}};
    vkrc::submit(queue, {.waits = waits, .command_buffers = {&g, 1}});
    shared.reset();
    set.reset();
    const std::size_t pending = device.deferred_count();
    EXPECT_GT(pending, 0u);
    gate.signal(1);  // compute runs; graphics still waits for 2
    done.wait(1);
    device.collect_garbage();
    EXPECT_EQ(device.deferred_count(), pending) << "destroyed before the graphics queue was done with it";
    gate.signal(2);
    queue.wait_idle();
    compute.wait_idle();
    EXPECT_EQ(device.deferred_count(), 0u);
    const auto got = vkrc::download_buffer(queue, result, 0, count * 4);
    std::vector<std::uint32_t> values(count);
    std::memcpy(values.data(), got.data(), got.size());
    for (std::uint32_t i = 0; i < count; ++i) ASSERT_EQ(values[i], (i * 2654435761u) ^ 0x5eedu) << i;
}

}  // namespace
