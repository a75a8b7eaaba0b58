// The contract every teapot benchmark variant implements. Adding one (the
// vkrc-st and vkrc-mt variants, say): a source file under variants/ with a
// class deriving from Variant that follows the convention below, a factory
// declared here and listed in variant_registry() (harness/variants.cpp), the
// file added to the teapot target with vkrc::st or vkrc::mt linked (each
// translation unit includes vkrc under one policy only). The harness times
// the stages itself, so a variant only does the work of each stage.
//
// Headless presentation convention (every variant follows it exactly, so the
// stages measure the same work; vkrc's headless presenter must match it):
//   * Frame resources: frames_in_flight slots, each with its own command pool
//     and primary command buffer, fence, descriptor set and 128-byte region
//     of one persistently mapped HOST_VISIBLE|HOST_COHERENT uniform buffer
//     (region stride rounded up to minUniformBufferOffsetAlignment; no flush,
//     coherent memory is the one write strategy for all variants).
//   * Images: a ring of frames_in_flight + 1 colour images (R8G8B8A8_UNORM,
//     the stand-in for a swapchain of that many images) and one D32_SFLOAT
//     depth image. Frame n uses slot n % frames_in_flight and ring image
//     n % (frames_in_flight + 1).
//   * acquire: picks frame n's slot and ring image. Bookkeeping only: the
//     slot was made free by the previous frame's wait stage, and the ring
//     image's last user (frame n - frames_in_flight - 1) is older still.
//   * uniform: copies the CameraUniforms (view, proj) into the slot's mapped
//     region uniform_writes times (write_camera_uniforms below).
//   * command: vkResetCommandPool on the slot's pool, then records: barrier
//     colour UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL and depth UNDEFINED ->
//     DEPTH_ATTACHMENT_OPTIMAL (after earlier frames' depth tests), dynamic
//     rendering with both cleared (colour clear_colour, depth 1), bind
//     pipeline, set viewport and scissor, bind the slot's descriptor set,
//     bind the position and normal vertex buffers and the 16-bit index
//     buffer, then per teapot vkCmdPushConstants (80 bytes) + vkCmdDrawIndexed;
//     end rendering, barrier colour -> TRANSFER_SRC_OPTIMAL (where a windowed
//     run transitions to PRESENT_SRC_KHR), end.
//   * submit: one vkQueueSubmit2 of the command buffer, signalling the slot's
//     fence; no semaphores.
//   * present: hands the ring image over. Headless there is no presentation
//     engine, so present is bookkeeping only: it records the ring image as the
//     last presented one and advances the frame counter; no Vulkan call.
//   * wait: waits for the fence of the slot the next frame will use, if that
//     slot has been submitted, and resets it (with one frame in flight this
//     waits for the frame just submitted).
//   * update: the CPU animation of every teapot for time t (teapot::animate)
//     into the variant's draw array, read by the next command stage.
#pragma once

#include "scene/teapot_scene.hpp"

#include <vulkan/vulkan_core.h>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace teapot {

struct Config {
    int teapots = 25;
    int frames_in_flight = 2;
    int uniform_writes = 1;
    int tessellation = 4;
    std::uint32_t width = 800;
    std::uint32_t height = 600;
    bool validation = false;
};

// What every variant draws: the mesh (shared, built once per tessellation)
// and the camera (constant for a configuration, still written every frame).
struct SceneData {
    const Mesh* mesh = nullptr;
    CameraUniforms camera{};
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
    // Runs update(t) and one full frame through the stages above, waits for
    // it and reads its colour image back: width * height RGBA8 pixels, top
    // row first.
    virtual std::vector<std::uint8_t> render_reference_frame(double t) = 0;
    virtual std::string device_name() const = 0;
};

// The one uniform write strategy: plain copies into coherent mapped memory.
// The compiler barrier keeps repeated identical copies from being merged, so
// uniform_writes = N really writes N times.
inline void write_camera_uniforms(void* mapped, const CameraUniforms& camera, int writes) {
    for (int i = 0; i < writes; ++i) {
        std::memcpy(mapped, &camera, sizeof camera);
        asm volatile("" ::: "memory");
    }
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
inline constexpr VkDebugUtilsMessageTypeFlagsEXT validation_types =
    VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
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

}  // namespace teapot
