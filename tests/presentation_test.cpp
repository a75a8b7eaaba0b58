// Presentation: a GLFW window on a private Xvfb, its Swapchain re-created
// while rendering (under the multi-thread policy also while three other
// threads record and drop), minimised (zero extent), and the headless presenter
// rendering the same pixels through the same frame loop; and device loss
// reported by present or acquire.
#include "support/fault_injection.hpp"
#include "support/vk_test.hpp"
#include "support/watchdog.hpp"
#include "support/xvfb.hpp"

#include "shaders/triangle.frag.h"
#include "shaders/triangle.vert.h"

#include <vkrc/glfw.hpp>

#include <GLFW/glfw3.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace {

using vkrc_test::ValidationLog;

struct Vertex {
    float position[2];
    float color[3];
};

// Everything a frame loop needs besides the presenter: two frames in flight.
struct Renderer {
    static constexpr int frames_in_flight = 2;

    Renderer(const vkrc::Queue& q, VkFormat format) : queue(q) {
        const auto& device = q.device();
        const Vertex vertices[] = {{{0.0f, -0.6f}, {1, 0, 0}}, {{-0.6f, 0.6f}, {0, 1, 0}}, {{0.6f, 0.6f}, {0, 0, 1}}};
        vertex_buffer = vkrc::Buffer::create(device, {.size = sizeof vertices,
                                                      .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                                                      .memory = {.usage = vkrc::MemoryUsage::upload}});
        vertex_buffer.allocation().write(0, vertices, 3);
        pipeline =
            vkrc::GraphicsPipelineBuilder(vkrc::PipelineLayout::create(device))
                .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_vert))
                .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_frag))
                .vertex_binding(0, sizeof(Vertex))
                .vertex_attribute(0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, position))
                .vertex_attribute(1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, color))
                .rendering(std::array{format})
                .build();
        for (auto& slot : slots) {
            slot.pool = vkrc::CommandPool::create(device, {.queue_family_index = q.family_index()});
            slot.cmd = slot.pool.allocate();
            slot.fence = vkrc::Fence::create(device, true);
        }
    }

    // One iteration of the frame loop; the status of acquire, or of present
    // when an image was rendered. With readback, the image is also copied
    // there (the presenter's images need TRANSFER_SRC).
    vkrc::PresentStatus frame(vkrc::Presenter& presenter, const vkrc::Buffer* readback = nullptr) {
        auto& slot = slots[count % frames_in_flight];
        EXPECT_EQ(slot.fence.wait(), VK_SUCCESS);
        vkrc::Frame frame;
        presenter.acquire(frame);
        if (!frame) return frame.status;
        slot.fence.unsignal();
        record(slot.cmd, frame, readback);
        vkrc::submit(queue,
                     {.waits = frame.waits(), .command_buffers = std::span(&slot.cmd, 1), .signals = frame.signals()},
                     slot.fence);
        ++count;
        auto status = presenter.present(frame);
        return frame.status == vkrc::PresentStatus::success ? status : frame.status;
    }

    void record(const vkrc::CommandBuffer& cmd, const vkrc::Frame& frame, const vkrc::Buffer* readback) {
        cmd.begin();
        auto to_attachment =
            vkrc::image_barrier(frame.image().vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                vkrc::Frame::acquire_stage, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        cmd.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
        vkrc::RenderingAttachment target{.image_view = frame.view().vk()};
        target.clear_value.color = {{0.1f, 0.2f, 0.3f, 1.0f}};
        cmd.begin_rendering({.render_area = {{0, 0}, frame.extent}, .color_attachments = std::span(&target, 1)});
        cmd.bind_pipeline(pipeline);
        cmd.set_viewport_and_scissor(frame.extent);
        cmd.bind_vertex_buffer(0, vertex_buffer);
        cmd.draw(3);
        cmd.end_rendering();
        VkImageLayout layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
        VkAccessFlags2 access = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
        if (readback) {
            auto to_copy = vkrc::image_barrier(frame.image().vk(), layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, stage,
                                               access, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
            cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {frame.extent.width, frame.extent.height, 1};
            cmd.copy_image_to_buffer(frame.image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, *readback,
                                     std::span(&region, 1));
            auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
            cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
            layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
            stage = VK_PIPELINE_STAGE_2_COPY_BIT;
            access = 0;
        }
        auto to_present = vkrc::image_barrier(frame.image().vk(), layout, frame.present_layout, stage, access,
                                              VK_PIPELINE_STAGE_2_NONE, 0);
        cmd.pipeline_barrier({}, {}, std::span(&to_present, 1));
        cmd.end();
    }

    void wait() {
        for (auto& slot : slots) EXPECT_EQ(slot.fence.wait(), VK_SUCCESS);
    }

    struct Slot {
        vkrc::CommandPool pool;
        vkrc::CommandBuffer cmd;
        vkrc::Fence fence;
    };
    vkrc::Queue queue;
    vkrc::Buffer vertex_buffer;
    vkrc::GraphicsPipeline pipeline;
    std::array<Slot, frames_in_flight> slots;
    std::uint64_t count = 0;
};

class PresentationTest : public ::testing::Test {
protected:
    void SetUp() override {
        xvfb = std::make_unique<vkrc_test::Xvfb>();
        ASSERT_TRUE(xvfb->running()) << xvfb->error();
        window = vkrc::glfw::create_window_surface({.width = 320, .height = 240, .title = "vkrc presentation test"},
                                                   vkrc_test::validated_instance_info(log));
        auto requirements = vkrc_test::test_device_requirements();
        requirements.present_surface = window.surface.vk();
        requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
        auto physical = vkrc::PhysicalDevice::select(window.instance, requirements);
        device = vkrc::Device::create(physical, {.enabled_extension_names = {VK_KHR_SWAPCHAIN_EXTENSION_NAME}});
        queue = device.default_queue();
    }

    void TearDown() override {
        queue = {};
        device.reset();
        window = {};
        glfwPollEvents();
        vkrc_test::expect_no_validation_messages(*log);
        xvfb.reset();
    }

    vkrc::Swapchain make_swapchain(VkImageUsageFlags usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) {
        return vkrc::Swapchain::create(queue, window.surface,
                                       {.image_usage = usage, .log = [this](const char* m) { choices.push_back(m); }});
    }

    std::shared_ptr<ValidationLog> log = std::make_shared<ValidationLog>();
    std::unique_ptr<vkrc_test::Xvfb> xvfb;
    vkrc::glfw::WindowSurface window;
    vkrc::Device device;
    vkrc::Queue queue;
    std::vector<std::string> choices;
};

TEST_F(PresentationTest, RendersTenFramesAndLogsItsChoices) {
    auto swapchain = make_swapchain();
    EXPECT_EQ(swapchain.extent().width, 320u);
    EXPECT_EQ(swapchain.extent().height, 240u);
    EXPECT_GE(swapchain.image_count(), 2u);
    ASSERT_EQ(choices.size(), 3u);  // format, present mode, images and extent
    EXPECT_NE(choices[0].find("format"), std::string::npos);
    EXPECT_NE(choices[1].find("present mode FIFO (as requested)"), std::string::npos) << choices[1];
    EXPECT_NE(choices[2].find("extent 320x240"), std::string::npos) << choices[2];

    Renderer renderer(queue, swapchain.format());
    for (int i = 0; i < 10; ++i) EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::success);
    EXPECT_EQ(renderer.count, 10u);
    renderer.wait();
}

// SwapchainCreateInfo::next reaches VkSwapchainCreateInfoKHR, at creation
// and again at a re-creation: a struct that does not extend it, chained on
// purpose, is reported by the validation layer each time (drivers skip it).
TEST_F(PresentationTest, RawInteropSwapchainNextReachesVulkan) {
    const VkFenceCreateInfo foreign{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    auto swapchain = vkrc::Swapchain::create(queue, window.surface, {.next = &foreign});
    EXPECT_TRUE(log->take_expected("VUID-VkSwapchainCreateInfoKHR-pNext-pNext", 1));
    EXPECT_EQ(swapchain.recreate(), vkrc::PresentStatus::success);
    EXPECT_TRUE(log->take_expected("VUID-VkSwapchainCreateInfoKHR-pNext-pNext", 1));
}

TEST_F(PresentationTest, ResizedHundredTimesWhileRendering) {
    auto swapchain = make_swapchain();
    Renderer renderer(queue, swapchain.format());
    int recreations = 0;
    for (int i = 0; i < 100; ++i) {
        const int width = 160 + (i * 37) % 400, height = 120 + (i * 53) % 300;
        glfwSetWindowSize(window.window.get(), width, height);
        glfwPollEvents();
        // What an application does in its framebuffer-size callback.
        if (window.window.framebuffer_extent().width != swapchain.extent().width ||
            window.window.framebuffer_extent().height != swapchain.extent().height) {
            ASSERT_EQ(swapchain.recreate(), vkrc::PresentStatus::success);
            ++recreations;
        }
        // Out of date or suboptimal: the next acquire re-creates.
        vkrc::PresentStatus status = vkrc::PresentStatus::out_of_date;
        for (int attempt = 0; attempt < 3 && status != vkrc::PresentStatus::success; ++attempt) {
            status = renderer.frame(swapchain);
        }
        EXPECT_EQ(status, vkrc::PresentStatus::success) << "resize " << i;
        EXPECT_EQ(swapchain.extent().width, static_cast<std::uint32_t>(width));
        EXPECT_EQ(swapchain.extent().height, static_cast<std::uint32_t>(height));
    }
    EXPECT_GE(recreations, 90);
    renderer.wait();
    EXPECT_NE(choices.back().find("replacing the previous swapchain"), std::string::npos);
}

// The capabilities a minimised window reports on platforms with a window
// manager (Xvfb has none, so iconifying changes nothing there).
PFN_vkGetPhysicalDeviceSurfaceCapabilitiesKHR real_capabilities = nullptr;
VKAPI_ATTR VkResult VKAPI_CALL minimised_capabilities(VkPhysicalDevice physical, VkSurfaceKHR surface,
                                                      VkSurfaceCapabilitiesKHR* caps) {
    VkResult r = real_capabilities(physical, surface, caps);
    caps->currentExtent = caps->minImageExtent = caps->maxImageExtent = {0, 0};
    return r;
}

TEST_F(PresentationTest, MinimisedAndRestored) {
    auto swapchain = make_swapchain();
    Renderer renderer(queue, swapchain.format());
    for (int i = 0; i < 3; ++i) EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::success);

    glfwIconifyWindow(window.window.get());
    glfwPollEvents();
    // Xvfb has no window manager, so the server may or may not shrink the
    // surface; either way a frame renders exactly when it gets an image.
    for (int i = 0; i < 3; ++i) {
        const auto rendered = renderer.count;
        const auto status = renderer.frame(swapchain);
        if (status == vkrc::PresentStatus::zero_extent) {
            EXPECT_EQ(renderer.count, rendered);
        } else if (status == vkrc::PresentStatus::success) {
            EXPECT_EQ(renderer.count, rendered + 1);
        } else {
            EXPECT_TRUE(status == vkrc::PresentStatus::suboptimal || status == vkrc::PresentStatus::out_of_date);
        }
    }

    auto& fn = window.instance.state()->fn;
    real_capabilities = fn.vkGetPhysicalDeviceSurfaceCapabilitiesKHR;
    fn.vkGetPhysicalDeviceSurfaceCapabilitiesKHR = minimised_capabilities;
    EXPECT_EQ(swapchain.recreate(), vkrc::PresentStatus::zero_extent);
    auto before = renderer.count;
    for (int i = 0; i < 5; ++i) EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::zero_extent);
    EXPECT_EQ(renderer.count, before);  // skipped: nothing acquired, submitted or presented
    fn.vkGetPhysicalDeviceSurfaceCapabilitiesKHR = real_capabilities;

    glfwRestoreWindow(window.window.get());
    glfwPollEvents();
    for (int i = 0; i < 5; ++i) EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::success);
    EXPECT_EQ(renderer.count, before + 5);
    renderer.wait();
}

TEST_F(PresentationTest, OneLiveSwapchainPerSurface) {
    auto swapchain = make_swapchain();
    EXPECT_THROW(make_swapchain(), vkrc::UsageError);
    {
        Renderer renderer(queue, swapchain.format());
        for (int i = 0; i < 3; ++i) EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::success);
        // Dropped with frames in flight: the next create waits for its destruction.
        swapchain.reset();
        swapchain = make_swapchain();
        EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::success);
        renderer.wait();
    }
    // A frame that outlives its Swapchain keeps the Vulkan swapchain, so the
    // surface is not free until the frame goes.
    vkrc::Frame frame;
    swapchain.acquire(frame);
    ASSERT_TRUE(frame);
    Renderer renderer(queue, swapchain.format());
    renderer.record(renderer.slots[0].cmd, frame, nullptr);
    renderer.slots[0].fence.unsignal();
    vkrc::submit(
        queue,
        {.waits = frame.waits(), .command_buffers = std::span(&renderer.slots[0].cmd, 1), .signals = frame.signals()},
        renderer.slots[0].fence);
    EXPECT_EQ(swapchain.present(frame), vkrc::PresentStatus::success);
    swapchain.reset();
    EXPECT_THROW(make_swapchain(), vkrc::UsageError);
    frame = {};
    EXPECT_TRUE(make_swapchain());
    renderer.wait();
}

// The frame's image, of the swapchain retired by recreate(), keeps that
// swapchain alive: the work rendering into it completes and its pixels read
// back are the triangle over the clear colour.
TEST_F(PresentationTest, RetiredSwapchainLivesWhileAFrameHoldsItsImage) {
    auto swapchain = make_swapchain(VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    const VkExtent2D extent = swapchain.extent();
    auto readback = vkrc::Buffer::create(device, {.size = VkDeviceSize{extent.width} * extent.height * 4,
                                                  .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                  .memory = {.usage = vkrc::MemoryUsage::readback}});
    Renderer renderer(queue, swapchain.format());
    vkrc::Frame frame;
    swapchain.acquire(frame);
    ASSERT_TRUE(frame);
    renderer.record(renderer.slots[0].cmd, frame, &readback);
    renderer.slots[0].fence.unsignal();
    vkrc::submit(
        queue,
        {.waits = frame.waits(), .command_buffers = std::span(&renderer.slots[0].cmd, 1), .signals = frame.signals()},
        renderer.slots[0].fence);
    const VkSwapchainKHR old = swapchain.vk();
    ASSERT_EQ(swapchain.recreate(), vkrc::PresentStatus::success);
    EXPECT_NE(swapchain.vk(), old);
    // Presenting an image of the retired swapchain is still allowed (the
    // server may take it or call it out of date).
    const auto status = swapchain.present(frame);
    EXPECT_TRUE(status == vkrc::PresentStatus::success || status == vkrc::PresentStatus::out_of_date) << int(status);
    frame = {};
    ASSERT_EQ(renderer.slots[0].fence.wait(), VK_SUCCESS);
    auto texel = [&](std::uint32_t x, std::uint32_t y) {
        return readback.allocation().read_value<std::uint32_t>((VkDeviceSize{y} * extent.width + x) * 4);
    };
    EXPECT_EQ(texel(1, 1) >> 24, 0xffu) << "the clear colour is opaque";
    EXPECT_NE(texel(extent.width / 2, extent.height / 2), texel(1, 1)) << "the triangle covers the centre";
    renderer.count = 1;
    for (int i = 0; i < 4; ++i) EXPECT_EQ(renderer.frame(swapchain), vkrc::PresentStatus::success);
    renderer.wait();
}

TEST_F(PresentationTest, HeadlessRendersTheSamePixelsAsTheWindow) {
    auto swapchain = make_swapchain(VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    const VkExtent2D extent = swapchain.extent();
    const VkDeviceSize size = VkDeviceSize{extent.width} * extent.height * 4;
    auto readback = vkrc::Buffer::create(
        device,
        {.size = size, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    Renderer renderer(queue, swapchain.format());
    ASSERT_EQ(renderer.frame(swapchain, &readback), vkrc::PresentStatus::success);
    renderer.wait();
    std::vector<std::byte> windowed(size);
    readback.allocation().read(0, std::span(windowed));

    auto headless = vkrc::HeadlessPresenter::create(queue, {.extent = extent, .format = swapchain.format()});
    Renderer headless_renderer(queue, headless.format());
    for (int i = 0; i < 4; ++i) ASSERT_EQ(headless_renderer.frame(headless), vkrc::PresentStatus::success);
    EXPECT_EQ(headless.last_presented(), 0u);  // frame 3 of a ring of 3
    auto pixels = headless.read_back(headless.last_presented());
    ASSERT_EQ(pixels.size(), windowed.size());
    EXPECT_TRUE(pixels == windowed);
    // Not trivially equal: the centre is the triangle, a corner the clear colour.
    auto texel = [&](std::uint32_t x, std::uint32_t y) {
        std::uint32_t v;
        std::memcpy(&v, &pixels[(std::size_t{y} * extent.width + x) * 4], 4);
        return v;
    };
    EXPECT_NE(texel(extent.width / 2, extent.height / 2), texel(1, 1));
    headless_renderer.wait();
}

#if VKRC_IS_MULTI_THREAD
// One round of a worker thread on the shared queue: an image cleared to the
// bytes of value through a view (dynamic rendering) and a buffer filled with
// value, both copied into readback. The view is dropped while the command
// buffer records, the image after end(), the buffer and the command buffer
// after the submit: vkrc holds each until the GPU is done. Whether readback
// then holds the colour and the words.
bool record_and_drop(const vkrc::Queue& queue, const vkrc::CommandPool& pool, const vkrc::Buffer& readback,
                     std::uint32_t value) {
    constexpr std::uint32_t side = 16, words = 64;
    const auto& device = queue.device();
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                     .extent = {side, side, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto view = vkrc::ImageView::create(image);
    auto buffer = vkrc::Buffer::create(
        device, {.size = words * 4, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    vkrc_test::Rgba rgba;
    std::memcpy(rgba.data(), &value, 4);
    auto cmd = pool.allocate();
    cmd.begin();
    const auto to_attachment = vkrc::image_barrier(
        image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
        VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
    vkrc::RenderingAttachment target{.image_view = view.vk()};
    for (int c = 0; c < 4; ++c) target.clear_value.color.float32[c] = float(rgba[c]) / 255.0f;
    cmd.begin_rendering({.render_area = {{0, 0}, {side, side}}, .color_attachments = std::span(&target, 1)});
    cmd.end_rendering();
    view.reset();
    const auto to_copy =
        vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {side, side, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, std::span(&region, 1));
    cmd.fill_buffer(buffer, 0, words * 4, value);
    const auto fill_to_copy = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    cmd.pipeline_barrier(std::span(&fill_to_copy, 1), {}, {});
    const VkBufferCopy words_region{0, side * side * 4, words * 4};
    cmd.copy_buffer(buffer, readback, std::span(&words_region, 1));
    const auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                              VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    image.reset();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    buffer.reset();
    cmd.reset();
    if (fence.wait() != VK_SUCCESS) return false;
    std::vector<std::uint32_t> got(side * side + words);
    readback.allocation().read(0, std::span(got));
    return std::ranges::all_of(got, [value](std::uint32_t v) { return v == value; });
}

// A presented frame read back (extent's RGBA or BGRA texels): the four
// corners are the clear colour (opaque, and corner of the first frame when
// given), the triangle covers the centre.
::testing::AssertionResult is_the_triangle(const vkrc::Buffer& readback, VkExtent2D extent, std::uint32_t corner) {
    auto texel = [&](std::uint32_t x, std::uint32_t y) {
        return readback.allocation().read_value<std::uint32_t>((VkDeviceSize{y} * extent.width + x) * 4);
    };
    const std::uint32_t clear = texel(0, 0);
    if (clear >> 24 != 0xffu) return ::testing::AssertionFailure() << "the clear colour is not opaque";
    if (corner != 0 && clear != corner) return ::testing::AssertionFailure() << "the clear colour changed";
    for (const auto& [x, y] :
         {std::pair{extent.width - 1, 0u}, {0u, extent.height - 1}, {extent.width - 1, extent.height - 1}}) {
        if (texel(x, y) != clear) return ::testing::AssertionFailure() << "corner (" << x << ", " << y << ")";
    }
    if (texel(extent.width / 2, extent.height / 2) == clear) {
        return ::testing::AssertionFailure() << "the triangle does not cover the centre";
    }
    return ::testing::AssertionSuccess();
}

// Issue 33's never-tested scenario under the multi-thread policy: the main
// thread resizes the window and re-creates the swapchain (the old one
// retired, its images destroyed once their frames are done) and presents a
// frame read back at every size, while three threads record on the same
// device and queue from their own pools and drop the buffers, images and
// views they made. Every presented frame shows the triangle at the new
// extent, every worker round reads back what it recorded, the recreations
// are counted, and nothing is left deferred. TSan runs it (`-L mt`).
TEST_F(PresentationTest, RecreatedOnOneThreadWhileThreeOthersRecordAndDrop) {
    vkrc_test::Watchdog watchdog("swapchain recreation while three threads record and drop", std::chrono::seconds(120));
    auto swapchain = make_swapchain(VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    Renderer renderer(queue, swapchain.format());
    constexpr int workers = 3, min_resizes = 8, min_rounds = 3;
    std::atomic<bool> stop{false};
    std::array<std::atomic<int>, workers> rounds{}, wrong{};
    std::vector<std::thread> threads;
    // Stops and joins the workers however the main thread leaves (a failed ASSERT too).
    struct Join {
        Join(std::atomic<bool>& s, std::vector<std::thread>& t) : stop(s), threads(t) {}
        Join(const Join&) = delete;
        Join& operator=(const Join&) = delete;
        ~Join() {
            stop.store(true);
            for (auto& thread : threads) thread.join();
        }
        std::atomic<bool>& stop;
        std::vector<std::thread>& threads;
    };
    std::optional<Join> join(std::in_place, stop, threads);
    for (int t = 0; t < workers; ++t) {
        threads.emplace_back([&, t] {
            auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
            auto readback = vkrc::Buffer::create(device, {.size = 16 * 16 * 4 + 64 * 4,
                                                          .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                          .memory = {.usage = vkrc::MemoryUsage::readback}});
            for (std::uint32_t r = 1; !stop.load(); ++r) {
                if (!record_and_drop(queue, pool, readback, std::uint32_t(t + 1) << 24 | r)) wrong[t].fetch_add(1);
                rounds[t].fetch_add(1);
            }
        });
    }
    auto fewest_rounds = [&] {
        int fewest = rounds[0].load();
        for (const auto& r : rounds) fewest = std::min(fewest, r.load());
        return fewest;
    };
    int resizes = 0, recreations = 0, frames = 0;
    std::uint32_t clear = 0;
    // At least min_resizes, and on until every worker has done min_rounds
    // while they went on (bounded: a worker that starves fails below).
    for (; resizes < 200 && (resizes < min_resizes || fewest_rounds() < min_rounds); ++resizes) {
        const int width = 160 + (resizes * 37) % 200, height = 120 + (resizes * 53) % 150;
        glfwSetWindowSize(window.window.get(), width, height);
        glfwPollEvents();
        const VkSwapchainKHR old = swapchain.vk();
        ASSERT_EQ(swapchain.recreate(), vkrc::PresentStatus::success);
        const VkExtent2D extent = swapchain.extent();
        EXPECT_EQ(extent.width, static_cast<std::uint32_t>(width));
        EXPECT_EQ(extent.height, static_cast<std::uint32_t>(height));
        // Dropped at the end of the iteration, while the workers record.
        auto readback = vkrc::Buffer::create(device, {.size = VkDeviceSize{extent.width} * extent.height * 4,
                                                      .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                      .memory = {.usage = vkrc::MemoryUsage::readback}});
        vkrc::PresentStatus status = vkrc::PresentStatus::out_of_date;
        for (int attempt = 0; attempt < 3 && status != vkrc::PresentStatus::success; ++attempt) {
            status = renderer.frame(swapchain, &readback);
        }
        ASSERT_EQ(status, vkrc::PresentStatus::success) << "resize " << resizes;
        ASSERT_EQ(swapchain.extent().width, extent.width) << "the frame was rendered at another extent";
        recreations += swapchain.vk() != old;
        renderer.wait();
        EXPECT_TRUE(is_the_triangle(readback, extent, clear))
            << "resize " << resizes << ": " << extent.width << "x" << extent.height;
        if (clear == 0) clear = readback.allocation().read_value<std::uint32_t>(0);
        ++frames;
    }
    join.reset();
    std::printf("%d resizes, %d recreations, %d frames; worker rounds %d, %d, %d\n", resizes, recreations, frames,
                rounds[0].load(), rounds[1].load(), rounds[2].load());
    EXPECT_EQ(recreations, resizes) << "each recreate() made a new swapchain";
    EXPECT_EQ(frames, resizes);
    for (int t = 0; t < workers; ++t) {
        EXPECT_GE(rounds[t].load(), min_rounds) << "worker " << t;
        EXPECT_EQ(wrong[t].load(), 0) << "worker " << t << " read back something else than it recorded";
    }
    EXPECT_NE(choices.back().find("replacing the previous swapchain"), std::string::npos);
    device.wait_idle();
    device.collect_garbage();
    EXPECT_EQ(device.deferred_count(), 0u);
}
#endif

// Device loss on the windowed path (issue 7): VK_ERROR_DEVICE_LOST from
// vkQueuePresentKHR or vkAcquireNextImageKHR raises DeviceLostError and marks
// the device lost; afterwards nothing waits for ever (the queue timeline the
// swapchain's destruction is queued behind will not advance) and every handle
// drops in any order without validation messages. The loss is simulated by
// the fault injector, as in device_loss_test.cpp.
namespace faults = vkrc_test::faults;

enum class LossObserver { present, acquire };

// The window outlives every handle (glfw.hpp) and is made once per test.
void lose_while_presenting(LossObserver how, unsigned seed, const vkrc::glfw::Window& window) {
    vkrc_test::Watchdog watchdog("losing the device while presenting and dropping every handle");
    faults::arm(0, VK_SUCCESS);
    auto log = std::make_shared<ValidationLog>();
    auto instance_info = vkrc_test::validated_instance_info(log);
    instance_info.get_instance_proc_addr = faults::get_instance_proc_addr();
    for (const char* name : vkrc::glfw::required_instance_extensions()) {
        instance_info.enabled_extension_names.push_back(name);
    }
    auto instance = vkrc::Instance::create(instance_info);
    auto surface = vkrc::glfw::create_surface(instance, window.get());
    auto requirements = vkrc_test::test_device_requirements();
    requirements.present_surface = surface.vk();
    requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    auto physical = vkrc::PhysicalDevice::select(instance, requirements);
    auto device = vkrc::Device::create(physical, {.enabled_extension_names = {VK_KHR_SWAPCHAIN_EXTENSION_NAME}});
    auto queue = device.default_queue();
    auto swapchain = vkrc::Swapchain::create(queue, surface);
    std::optional<Renderer> renderer(std::in_place, queue, swapchain.format());
    for (int i = 0; i < 3; ++i) EXPECT_EQ(renderer->frame(swapchain), vkrc::PresentStatus::success);

    // Present: a frame acquired, rendered and submitted; its present sees the
    // loss. Acquire: the loss comes between two frames.
    vkrc::Frame frame;
    if (how == LossObserver::present) {
        auto& slot = renderer->slots[renderer->count % Renderer::frames_in_flight];
        EXPECT_EQ(slot.fence.wait(), VK_SUCCESS);
        swapchain.acquire(frame);
        ASSERT_TRUE(frame);
        slot.fence.unsignal();
        renderer->record(slot.cmd, frame, nullptr);
        vkrc::submit(queue,
                     {.waits = frame.waits(), .command_buffers = std::span(&slot.cmd, 1), .signals = frame.signals()},
                     slot.fence);
    }
    faults::lose_device();
    try {
        if (how == LossObserver::present) {
            swapchain.present(frame);
        } else {
            swapchain.acquire(frame);
        }
        ADD_FAILURE() << "no DeviceLostError";
    } catch (const vkrc::DeviceLostError& e) {
        ASSERT_TRUE(faults::fired()) << e.what();
        if (how == LossObserver::present) EXPECT_STREQ(faults::fired_in(), "vkQueuePresentKHR");
    }
    EXPECT_TRUE(device.lost());

    // Later calls report the loss too, none waits.
    EXPECT_THROW(swapchain.acquire(frame), vkrc::DeviceLostError);
    EXPECT_THROW(swapchain.acquire(frame), vkrc::DeviceLostError);
    if (frame) EXPECT_THROW(swapchain.present(frame), vkrc::DeviceLostError);
    for (auto& slot : renderer->slots) EXPECT_THROW(slot.fence.wait(), vkrc::DeviceLostError);
    EXPECT_THROW(queue.wait_idle(), vkrc::DeviceLostError);
    EXPECT_THROW(device.wait_idle(), vkrc::DeviceLostError);
    EXPECT_EQ(device.deferred_count(), 0u) << "deferred destructions wait for a lost device";

    // Every handle, each with a way to drop it.
    std::vector<std::function<void()>> drops = {
        [&] { swapchain.reset(); },
        [&] { frame = {}; },
        [&] { surface.reset(); },
        [&] { instance.reset(); },
        [&] { physical.reset(); },
        [&] { device.reset(); },
        [&] { queue = {}; },
        [&] { renderer->queue = {}; },
        [&] { renderer->vertex_buffer.reset(); },
        [&] { renderer->pipeline.reset(); },
    };
    for (auto& slot : renderer->slots) {
        drops.push_back([&slot] { slot.pool.reset(); });
        drops.push_back([&slot] { slot.cmd.reset(); });
        drops.push_back([&slot] { slot.fence.reset(); });
    }
    std::vector<std::size_t> order(drops.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (seed == 1) std::reverse(order.begin(), order.end());
    if (seed > 1) std::shuffle(order.begin(), order.end(), std::mt19937(vkrc_test::test_seed() + seed));
    for (auto i : order) drops[i]();
    renderer.reset();
    glfwPollEvents();
    faults::arm(0, VK_SUCCESS);
    auto messages = log->take();
    EXPECT_TRUE(messages.empty()) << "drop order seed " << seed << ": " << messages.size()
                                  << " validation message(s), first: " << messages.front();
}

TEST(PresentationDeviceLoss, PresentReportsLossAndEveryHandleDropsInAnyOrder) {
    vkrc_test::Xvfb xvfb;
    ASSERT_TRUE(xvfb.running()) << xvfb.error();
    auto window = vkrc::glfw::Window::create({.width = 320, .height = 240, .title = "vkrc device loss test"});
    for (unsigned seed = 0; seed < 4; ++seed) lose_while_presenting(LossObserver::present, seed, window);
}

TEST(PresentationDeviceLoss, AcquireReportsLossAndEveryHandleDropsInAnyOrder) {
    vkrc_test::Xvfb xvfb;
    ASSERT_TRUE(xvfb.running()) << xvfb.error();
    auto window = vkrc::glfw::Window::create({.width = 320, .height = 240, .title = "vkrc device loss test"});
    for (unsigned seed = 0; seed < 4; ++seed) lose_while_presenting(LossObserver::acquire, seed, window);
}

}  // namespace
