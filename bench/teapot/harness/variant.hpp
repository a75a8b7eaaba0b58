// The contract every teapot benchmark variant implements. Adding one (the
// vkrc-st and vkrc-mt variants, say): a source file under variants/ with a
// class deriving from Variant that follows the convention below, a factory
// declared here and listed in variant_registry() (harness/variants.cpp), the
// file added to the teapot target with vkrc::st or vkrc::mt linked (each
// translation unit includes vkrc under one policy only). The harness times
// the stages itself, so a variant only does the work of each stage.
//
// Presentation convention (every variant follows it exactly, so the stages
// measure the same work). Two modes: headless (the default) and windowed
// (--window, a real swapchain); what differs between them is marked.
//   * Frame resources: frames_in_flight slots, each with its own command pool
//     and primary command buffer, fence, descriptor set and 128-byte region
//     of one persistently mapped HOST_VISIBLE|HOST_COHERENT uniform buffer
//     (region stride rounded up to minUniformBufferOffsetAlignment; no flush,
//     coherent memory is the one write strategy for all variants).
//     Windowed, each slot also has a binary "acquire" semaphore.
//   * Images, headless: a ring of frames_in_flight + 1 colour images
//     (R8G8B8A8_UNORM, the stand-in for a swapchain of that many images).
//     Frame n uses slot n % frames_in_flight and ring image
//     n % (frames_in_flight + 1).
//     Windowed: the variant's own window (harness/window.hpp) and a swapchain
//     made by the rule of the window_* helpers below: format B8G8R8A8_UNORM
//     or else R8G8B8A8_UNORM (colour space SRGB_NONLINEAR; UNORM so that the
//     bytes are the headless ones), present mode IMMEDIATE, else MAILBOX,
//     else FIFO (the first two do not wait for vertical blank, so the stages
//     measure the API rather than the display's rate; FIFO is the one every
//     surface has), minImageCount frames_in_flight + 1 clamped to the
//     surface's limits, the surface's current extent (Config width x height
//     where the surface leaves it to the swapchain), COLOR_ATTACHMENT and TRANSFER_SRC (image check) usage,
//     opaque composite alpha where supported, clipped. One binary
//     "render done" semaphore per swapchain image. vkrc's Swapchain applies
//     the same rule from its SwapchainCreateInfo.
//     Both: one D32_SFLOAT depth image, at least as large as every target.
//     Windowed, init (the timed preinit stage) includes creating the
//     window, its surface and the swapchain.
//   * acquire: picks frame n's slot and its target image. Headless this is
//     bookkeeping only: the slot was made free by the previous frame's wait
//     stage, and the ring image's last user (frame n - frames_in_flight - 1)
//     is older still. Windowed: vkAcquireNextImageKHR (no timeout) signalling
//     the slot's acquire semaphore, free since the wait stage waited for the
//     slot's last submission, which waited on it. A swapchain that reported
//     OUT_OF_DATE or SUBOPTIMAL is re-created here first (new extent, depth
//     image grown if needed), and acquiring again after OUT_OF_DATE.
//   * uniform: copies the CameraUniforms (view, proj) into the slot's mapped
//     region uniform_writes times (write_camera_uniforms below).
//   * command: vkResetCommandPool on the slot's pool, then records: barrier
//     colour UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL (source stage
//     COLOR_ATTACHMENT_OUTPUT, where a windowed submission waits for its
//     acquire semaphore) and depth UNDEFINED -> DEPTH_ATTACHMENT_OPTIMAL
//     (after earlier frames' depth tests), dynamic rendering over the
//     target's extent with both cleared (colour clear_colour, depth 1), bind
//     pipeline, set viewport and scissor to that extent, bind the slot's
//     descriptor set, bind the position and normal vertex buffers and the
//     16-bit index buffer, then per teapot vkCmdPushConstants (80 bytes) +
//     vkCmdDrawIndexed; end rendering, barrier colour -> TRANSFER_SRC_OPTIMAL
//     headless, PRESENT_SRC_KHR windowed (destination stage NONE), end.
//     With --threads N > 1 (Config::threads) the draws are recorded on N
//     threads into secondaries: each slot also has N command pools
//     (TRANSIENT), one per thread, each with one secondary command buffer.
//     The primary is recorded as above up to the rendering, which begins
//     with VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT; then
//     SceneData::recorders runs thread i = 0 .. N-1 (0 is the calling
//     thread): vkResetCommandPool on its pool, begin its secondary
//     (ONE_TIME_SUBMIT | RENDER_PASS_CONTINUE, inheriting the dynamic
//     rendering: the colour format, D32_SFLOAT, one sample), bind pipeline,
//     set viewport and scissor, bind the descriptor set, vertex and index
//     buffers (secondaries inherit no state), the push constants and draws of
//     draw_range(i, N), end. Then one vkCmdExecuteCommands of the N
//     secondaries in thread order (so the draw order is the 1-thread one) and
//     the primary ends as above. --threads 1 records the primary directly.
//   * submit: one vkQueueSubmit2 of the command buffer, signalling the slot's
//     fence. Headless: no semaphores. Windowed: waits on the slot's acquire
//     semaphore at COLOR_ATTACHMENT_OUTPUT and signals the image's render-done
//     semaphore at ALL_COMMANDS.
//   * present: hands the image over and advances the frame counter. Headless
//     there is no presentation engine, so present is bookkeeping only: it
//     records the ring image as the last presented one; no Vulkan call.
//     Windowed: vkQueuePresentKHR waiting on the image's render-done
//     semaphore; OUT_OF_DATE or SUBOPTIMAL marks the swapchain for
//     re-creation at the next acquire.
//   * wait: waits for the fence of the slot the next frame will use, if that
//     slot has been submitted, and resets it (with one frame in flight this
//     waits for the frame just submitted).
//   * update: the CPU animation of every teapot for time t (teapot::animate)
//     into the variant's draw array, read by the next command stage, and the
//     camera for time t (it sways), written by the next uniform stage
//     (update_scene below).
//   * Last frame (read_back_last_frame, the per-block image check): after a
//     block and drain(), the image the last timed frame rendered is read back
//     (headless: the ring image last presented, still TRANSFER_SRC_OPTIMAL;
//     windowed: one more frame at the same t through the window's stages,
//     its swapchain image, created with TRANSFER_SRC usage for this, copied
//     to the readback buffer between rendering and presentation: a second,
//     untimed submission PRESENT_SRC -> TRANSFER_SRC -> PRESENT_SRC that
//     signals the render-done semaphore the present waits on).
//   * Reference frame (render_reference_frame, the image check): in both
//     modes it is rendered offscreen through the headless path of the stages
//     above, into a ring image of Config width x height (windowed: a ring of
//     one image in the swapchain's format, so that the one pipeline serves
//     both), then read back and converted to RGBA (to_rgba). Presented
//     swapchain images cannot be read back, and their extent follows the
//     surface; the offscreen frame is the same pixels in every mode.
// vkrc's presenters (include/vkrc/swapchain.hpp) do somewhat more than the
// above on acquire and present, being general: see variants/vkrc.cpp.
#pragma once

#include "scene/teapot_scene.hpp"

#include <vulkan/vulkan_core.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace teapot {

class BenchWindow;  // harness/window.hpp
class ThreadPool;   // harness/thread_pool.hpp

struct Config {
    int teapots = 25;
    int frames_in_flight = 2;
    int uniform_writes = 1;
    int tessellation = 4;
    std::uint32_t width = 800;
    std::uint32_t height = 600;
    bool validation = false;
    bool window = false;  // --window: present to a window instead of the headless ring
    int threads = 1;      // --threads: recording threads of the command stage (the convention's "threads")
};

// What every variant draws: the mesh (shared, built once per tessellation)
// and the camera (constant for a configuration, still written every frame).
struct SceneData {
    const Mesh* mesh = nullptr;
    CameraUniforms camera{};
    // Config::threads > 1: the recording threads, shared by every variant.
    ThreadPool* recorders = nullptr;
};

inline constexpr VkFormat colour_format = VK_FORMAT_R8G8B8A8_UNORM;
inline constexpr VkFormat depth_format = VK_FORMAT_D32_SFLOAT;
inline constexpr float clear_colour[4] = {0.08f, 0.09f, 0.11f, 1.0f};

class Variant {
public:
    virtual ~Variant() = default;
    // Everything from instance to pipeline and frame resources: the timed
    // "preinit" stage. Teardown is the destructor.
    virtual void init(const Config& config, const SceneData& scene) = 0;
    // The per-frame stages, in this order (see the convention above).
    virtual void acquire() = 0;
    virtual void uniform() = 0;
    virtual void command() = 0;
    virtual void submit() = 0;
    virtual void present() = 0;
    virtual void wait() = 0;
    virtual void update(double t) = 0;
    // Waits until the device is idle; untimed, between blocks of frames.
    virtual void drain() = 0;
    // Runs update(t) and one full frame through the stages above, offscreen
    // in both modes, waits for it and reads its colour image back: width *
    // height RGBA8 pixels, top row first.
    std::vector<std::uint8_t> render_reference_frame(double t) {
        drain();
        update(t);
        render_offscreen(true);
        acquire();
        uniform();
        command();
        submit();
        present();
        wait();  // the other slot's last frame: every slot is free afterwards
        render_offscreen(false);
        return read_back_offscreen();
    }
    // After drain(): the last timed frame's colour image, rendered at time t
    // (the convention's "last frame"), as RGBA8 pixels, top row first.
    std::vector<std::uint8_t> read_back_last_frame(double t) {
        return window() ? read_back_presented_frame(t) : read_back_offscreen();
    }
    virtual std::string device_name() const = 0;
    // How frames are presented, e.g. "swapchain B8G8R8A8_UNORM, FIFO, 3
    // images, 800x600": the harness requires it to be the same for all.
    virtual std::string presentation() const = 0;
    // Windowed: the variant's window; null headless.
    virtual const BenchWindow* window() const = 0;

protected:
    // true: the stages render to the offscreen image even when windowed;
    // false: back to the configured target.
    virtual void render_offscreen(bool on) = 0;
    // The colour image of the last frame rendered offscreen, after it is done.
    virtual std::vector<std::uint8_t> read_back_offscreen() = 0;
    // Windowed: one more frame at time t through the window's stages, its
    // swapchain image copied back between its rendering and its presentation.
    virtual std::vector<std::uint8_t> read_back_presented_frame(double t) = 0;
};

// Windowed mode's choices (the convention above), one rule for all variants.
inline constexpr VkSurfaceFormatKHR window_formats[2] = {{VK_FORMAT_B8G8R8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
                                                         {VK_FORMAT_R8G8B8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR}};
inline constexpr VkPresentModeKHR window_present_modes[3] = {VK_PRESENT_MODE_IMMEDIATE_KHR, VK_PRESENT_MODE_MAILBOX_KHR,
                                                             VK_PRESENT_MODE_FIFO_KHR};

inline bool is_window_format(VkSurfaceFormatKHR f) {
    return std::any_of(std::begin(window_formats), std::end(window_formats), [&](const VkSurfaceFormatKHR& w) {
        return w.format == f.format && w.colorSpace == f.colorSpace;
    });
}

[[noreturn]] inline void throw_no_window_format() {
    throw std::runtime_error(
        "--window: the surface supports neither B8G8R8A8_UNORM nor R8G8B8A8_UNORM (SRGB_NONLINEAR)");
}

inline VkSurfaceFormatKHR choose_window_format(std::span<const VkSurfaceFormatKHR> supported) {
    if (supported.size() == 1 && supported[0].format == VK_FORMAT_UNDEFINED) return window_formats[0];  // any format
    for (const VkSurfaceFormatKHR& wanted : window_formats)
        for (const VkSurfaceFormatKHR& f : supported)
            if (f.format == wanted.format && f.colorSpace == wanted.colorSpace) return f;
    throw_no_window_format();
}

inline VkPresentModeKHR choose_present_mode(std::span<const VkPresentModeKHR> supported) {
    for (VkPresentModeKHR wanted : window_present_modes)
        if (std::find(supported.begin(), supported.end(), wanted) != supported.end()) return wanted;
    return VK_PRESENT_MODE_FIFO_KHR;  // every surface supports it
}

inline std::uint32_t swapchain_image_request(const Config& config, const VkSurfaceCapabilitiesKHR& caps) {
    std::uint32_t count = std::max(std::uint32_t(config.frames_in_flight + 1), caps.minImageCount);
    return caps.maxImageCount ? std::min(count, caps.maxImageCount) : count;
}

inline VkExtent2D swapchain_extent(const Config& config, const VkSurfaceCapabilitiesKHR& caps) {
    if (caps.currentExtent.width != UINT32_MAX) return caps.currentExtent;
    return {std::clamp(config.width, caps.minImageExtent.width, caps.maxImageExtent.width),
            std::clamp(config.height, caps.minImageExtent.height, caps.maxImageExtent.height)};
}

inline VkCompositeAlphaFlagBitsKHR composite_alpha(const VkSurfaceCapabilitiesKHR& caps) {
    if (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR) return VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    for (std::uint32_t bit = 1; bit != 0; bit <<= 1)
        if (caps.supportedCompositeAlpha & bit) return VkCompositeAlphaFlagBitsKHR(bit);
    return VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
}

inline const char* present_mode_name(VkPresentModeKHR mode) {
    switch (mode) {
        case VK_PRESENT_MODE_IMMEDIATE_KHR: return "IMMEDIATE";
        case VK_PRESENT_MODE_MAILBOX_KHR: return "MAILBOX";
        case VK_PRESENT_MODE_FIFO_KHR: return "FIFO";
        default: return "other";
    }
}

inline const char* format_name(VkFormat format) {
    switch (format) {
        case VK_FORMAT_B8G8R8A8_UNORM: return "B8G8R8A8_UNORM";
        case VK_FORMAT_R8G8B8A8_UNORM: return "R8G8B8A8_UNORM";
        default: return "other";
    }
}

// The presentation() text of both modes.
inline std::string headless_presentation(std::size_t images, VkFormat format, VkExtent2D e) {
    return "headless ring of " + std::to_string(images) + " " + format_name(format) + " images, " +
           std::to_string(e.width) + "x" + std::to_string(e.height);
}
inline std::string swapchain_presentation(VkFormat format, VkPresentModeKHR mode, std::size_t images, VkExtent2D e) {
    return std::string("swapchain ") + format_name(format) + ", " + present_mode_name(mode) + ", " +
           std::to_string(images) + " images, " + std::to_string(e.width) + "x" + std::to_string(e.height);
}

// Read-back pixels of a reference image of this format, as RGBA.
inline void to_rgba(std::vector<std::uint8_t>& pixels, VkFormat format) {
    if (format != VK_FORMAT_B8G8R8A8_UNORM) return;
    for (std::size_t p = 0; p + 3 < pixels.size(); p += 4) std::swap(pixels[p], pixels[p + 2]);
}

// The one uniform write strategy: plain copies into coherent mapped memory.
// The compiler barrier keeps repeated identical copies from being merged, so
// uniform_writes = N really writes N times.
inline void write_camera_uniforms(void* mapped, const CameraUniforms& camera, int writes) {
    for (int i = 0; i < writes; ++i) {
        std::memcpy(mapped, &camera, sizeof camera);
        asm volatile("" ::: "memory");
    }
}

// The update stage's work, the same for every variant.
inline void update_scene(const Config& config, double t, std::vector<PushConstants>& draws, CameraUniforms& camera) {
    animate(config.teapots, t, draws);
    camera = teapot::camera(config.teapots, config.width, config.height, t);
}

// Validation messages (warnings and errors) seen by any variant; the run
// fails if any arrive. Variants install validation_callback on their
// instance (also through VkInstanceCreateInfo::pNext) when
// Config::validation is set.
inline std::atomic<int> validation_messages{0};
VKAPI_ATTR VkBool32 VKAPI_CALL validation_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT types,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
inline constexpr VkDebugUtilsMessageSeverityFlagsEXT validation_severities =
    VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
inline constexpr VkDebugUtilsMessageTypeFlagsEXT validation_types = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                                                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                                                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
inline constexpr const char* validation_layer = "VK_LAYER_KHRONOS_validation";

// The variants this program has, by name, in the order they are listed.
struct VariantEntry {
    std::string_view name;
    std::unique_ptr<Variant> (*make)();
};
const std::vector<VariantEntry>& variant_registry();

// Factories of the variants defined in their own translation units.
std::unique_ptr<Variant> make_raw_variant();
std::unique_ptr<Variant> make_raw_direct_variant();
std::unique_ptr<Variant> make_vkhpp_variant();
// variants/vkrc.cpp, compiled against vkrc::st and against vkrc::mt.
std::unique_ptr<Variant> make_vkrc_st_variant();
std::unique_ptr<Variant> make_vkrc_mt_variant();
// The vkrc-st copy built against a vkrc compiled with VKRC_RUNTIME_CHECKS=1.
std::unique_ptr<Variant> make_vkrc_st_checked_variant();

}  // namespace teapot
