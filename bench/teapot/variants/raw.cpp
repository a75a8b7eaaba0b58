// The raw C API variants: `raw` calls the loader's exported functions, as a
// careful C programmer would; `raw-direct` makes the same device-level calls
// through pointers from vkGetDeviceProcAddr, skipping the loader's
// trampolines (the floor for any wrapper). One template, Direct selects the
// dispatch at compile time so `raw` keeps plain direct calls. Windowed
// (--window), both present with their own VkSurfaceKHR/VkSwapchainKHR code.
//
// Laid out as C would be: plain structs (instance and device, buffers and
// images, pipeline, frame slots, swapchain), free functions that create and
// destroy them, and a variant that holds them and runs the per-frame stages
// (its acquire .. update: the baseline every other variant is compared with).
#include "harness/thread_pool.hpp"
#include "harness/variant.hpp"
#include "harness/window.hpp"

#define GLFW_INCLUDE_NONE  // Vulkan only, no OpenGL headers
#include <GLFW/glfw3.h>

#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace teapot {
namespace {

// Never inlined: the stages call it, and their code (the baseline's
// instruction counts) must not change with how much else this file holds.
[[gnu::noinline]] void check(VkResult result, const char* call) {
    if (result != VK_SUCCESS)
        throw std::runtime_error(std::string(call) + " failed: VkResult " + std::to_string(result));
}

// The two-call enumeration: the count, then the items.
template <typename T, typename Enumerate>
std::vector<T> enumerate(const char* name, Enumerate&& call) {
    std::uint32_t count = 0;
    check(call(&count, static_cast<T*>(nullptr)), name);
    std::vector<T> items(count);
    check(call(&count, items.data()), name);
    return items;
}

// clang-format off
// Device-level functions the variant calls.
#define TEAPOT_DEVICE_FUNCTIONS(X)                                                                               \
    X(vkDestroyDevice) X(vkGetDeviceQueue) X(vkDeviceWaitIdle) X(vkCreateBuffer) X(vkDestroyBuffer)               \
    X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory) X(vkBindBufferMemory) X(vkMapMemory)     \
    X(vkCreateImage) X(vkDestroyImage) X(vkGetImageMemoryRequirements) X(vkBindImageMemory) X(vkCreateImageView)  \
    X(vkDestroyImageView) X(vkCreateShaderModule) X(vkDestroyShaderModule) X(vkCreateDescriptorSetLayout)         \
    X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout) X(vkDestroyPipelineLayout)                          \
    X(vkCreateGraphicsPipelines) X(vkDestroyPipeline) X(vkCreateDescriptorPool) X(vkDestroyDescriptorPool)        \
    X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets) X(vkCreateCommandPool) X(vkDestroyCommandPool)          \
    X(vkAllocateCommandBuffers) X(vkResetCommandPool) X(vkBeginCommandBuffer) X(vkEndCommandBuffer)               \
    X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) X(vkResetFences) X(vkQueueSubmit2)                      \
    X(vkCmdPipelineBarrier2) X(vkCmdBeginRendering) X(vkCmdEndRendering) X(vkCmdBindPipeline)                     \
    X(vkCmdSetViewport) X(vkCmdSetScissor) X(vkCmdBindDescriptorSets) X(vkCmdBindVertexBuffers)                   \
    X(vkCmdBindIndexBuffer) X(vkCmdPushConstants) X(vkCmdDrawIndexed) X(vkCmdCopyImageToBuffer) X(vkCmdCopyBuffer) \
    X(vkCmdExecuteCommands)                                                                                      \
    X(vkCreateSemaphore) X(vkDestroySemaphore) X(vkCreateSwapchainKHR) X(vkDestroySwapchainKHR)                   \
    X(vkGetSwapchainImagesKHR) X(vkAcquireNextImageKHR) X(vkQueuePresentKHR)
// clang-format on

struct DeviceFunctions {
#define TEAPOT_MEMBER(name) PFN_##name name = nullptr;
    TEAPOT_DEVICE_FUNCTIONS(TEAPOT_MEMBER)
#undef TEAPOT_MEMBER
};

// ---- Instance and device ----------------------------------------------------

// The instance, the device and what the rest needs to know of them.
struct Gpu {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;  // --validation
    VkSurfaceKHR surface = VK_NULL_HANDLE;                // windowed
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory_properties{};
    std::string name;
    VkDeviceSize uniform_alignment = 1;
    std::uint32_t queue_family = 0;
    VkDevice device = VK_NULL_HANDLE;
    DeviceFunctions fn;  // raw-direct's hot path and every untimed helper
    VkQueue queue = VK_NULL_HANDLE;
};

VkDebugUtilsMessengerCreateInfoEXT messenger_info() {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = validation_severities;
    info.messageType = validation_types;
    info.pfnUserCallback = validation_callback;
    return info;
}

// The instance; windowed, the window's surface; --validation, the layer and
// a messenger (chained to the create info too, to see the creation itself).
void create_instance(Gpu& gpu, const Config& config, const BenchWindow& window) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "teapot";
    app.apiVersion = VK_API_VERSION_1_3;
    const VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info();
    std::vector<const char*> extensions;
    if (config.window) extensions = window_instance_extensions();
    if (config.validation) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    if (config.validation) {
        info.pNext = &messenger;
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &validation_layer;
    }
    check(vkCreateInstance(&info, nullptr, &gpu.instance), "vkCreateInstance");
    if (config.window)
        check(glfwCreateWindowSurface(gpu.instance, window.get(), nullptr, &gpu.surface), "glfwCreateWindowSurface");
    if (config.validation) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(gpu.instance, "vkCreateDebugUtilsMessengerEXT"));
        check(create(gpu.instance, &messenger, nullptr, &gpu.messenger), "vkCreateDebugUtilsMessengerEXT");
    }
}

// candidate's first graphics queue family (windowed: one that also presents
// to the surface).
std::optional<std::uint32_t> graphics_family(const Gpu& gpu, VkPhysicalDevice candidate) {
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &count, families.data());
    for (std::uint32_t i = 0; i < count; ++i) {
        VkBool32 presents = VK_TRUE;
        if (gpu.surface)
            check(vkGetPhysicalDeviceSurfaceSupportKHR(candidate, i, gpu.surface, &presents),
                  "vkGetPhysicalDeviceSurfaceSupportKHR");
        if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && presents) return i;
    }
    return std::nullopt;
}

// The first Vulkan 1.3 device with such a queue family.
void pick_physical_device(Gpu& gpu) {
    const auto devices = enumerate<VkPhysicalDevice>("vkEnumeratePhysicalDevices", [&](auto* count, auto* items) {
        return vkEnumeratePhysicalDevices(gpu.instance, count, items);
    });
    for (VkPhysicalDevice candidate : devices) {
        VkPhysicalDeviceProperties properties;
        vkGetPhysicalDeviceProperties(candidate, &properties);
        if (properties.apiVersion < VK_API_VERSION_1_3) continue;
        const std::optional<std::uint32_t> family = graphics_family(gpu, candidate);
        if (!family) continue;
        gpu.physical_device = candidate;
        gpu.queue_family = *family;
        gpu.name = properties.deviceName;
        gpu.uniform_alignment = properties.limits.minUniformBufferOffsetAlignment;
        vkGetPhysicalDeviceMemoryProperties(candidate, &gpu.memory_properties);
        return;
    }
    throw std::runtime_error(gpu.surface ? "no Vulkan 1.3 device with a graphics queue that presents to the window"
                                         : "no Vulkan 1.3 device with a graphics queue");
}

bool supports_device_extension(VkPhysicalDevice physical_device, const char* name) {
    const auto extensions =
        enumerate<VkExtensionProperties>("vkEnumerateDeviceExtensionProperties", [&](auto* count, auto* items) {
            return vkEnumerateDeviceExtensionProperties(physical_device, nullptr, count, items);
        });
    for (const VkExtensionProperties& e : extensions)
        if (std::strcmp(e.extensionName, name) == 0) return true;
    return false;
}

// The device with the features and extensions vkrc::Device enables (setup
// parity): synchronization2, dynamicRendering, maintenance4,
// timelineSemaphore, VK_EXT_memory_budget where supported; windowed, the
// swapchain. Then its functions and its queue.
void create_device(Gpu& gpu) {
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = gpu.queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    features13.synchronization2 = VK_TRUE;
    features13.dynamicRendering = VK_TRUE;
    features13.maintenance4 = VK_TRUE;
    VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    features12.pNext = &features13;
    features12.timelineSemaphore = VK_TRUE;
    std::vector<const char*> extensions;
    if (gpu.surface) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    if (supports_device_extension(gpu.physical_device, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME))
        extensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.pNext = &features12;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue_info;
    info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    check(vkCreateDevice(gpu.physical_device, &info, nullptr, &gpu.device), "vkCreateDevice");
#define TEAPOT_LOAD(name) gpu.fn.name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(gpu.device, #name));
    TEAPOT_DEVICE_FUNCTIONS(TEAPOT_LOAD)
#undef TEAPOT_LOAD
    gpu.fn.vkGetDeviceQueue(gpu.device, gpu.queue_family, 0, &gpu.queue);
}

// Everything made from the device is destroyed before.
void destroy_gpu(Gpu& gpu) {
    if (gpu.device) gpu.fn.vkDestroyDevice(gpu.device, nullptr);
    if (gpu.surface) vkDestroySurfaceKHR(gpu.instance, gpu.surface, nullptr);
    if (gpu.messenger) {
        auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(gpu.instance, "vkDestroyDebugUtilsMessengerEXT"));
        destroy_messenger(gpu.instance, gpu.messenger, nullptr);
    }
    if (gpu.instance) vkDestroyInstance(gpu.instance, nullptr);
    gpu = {};
}

// ---- Commands and synchronisation ------------------------------------------
// The helpers a careful C programmer writes once.

VkCommandPool create_command_pool(const Gpu& gpu) {
    VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    info.queueFamilyIndex = gpu.queue_family;
    VkCommandPool pool = VK_NULL_HANDLE;
    check(gpu.fn.vkCreateCommandPool(gpu.device, &info, nullptr, &pool), "vkCreateCommandPool");
    return pool;
}

VkCommandBuffer allocate_command_buffer(const Gpu& gpu, VkCommandPool pool, VkCommandBufferLevel level) {
    VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    allocate.commandPool = pool;
    allocate.level = level;
    allocate.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    check(gpu.fn.vkAllocateCommandBuffers(gpu.device, &allocate, &cmd), "vkAllocateCommandBuffers");
    return cmd;
}

VkFence create_fence(const Gpu& gpu) {
    VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    check(gpu.fn.vkCreateFence(gpu.device, &info, nullptr, &fence), "vkCreateFence");
    return fence;
}

VkSemaphore create_semaphore(const Gpu& gpu) {
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    check(gpu.fn.vkCreateSemaphore(gpu.device, &info, nullptr, &semaphore), "vkCreateSemaphore");
    return semaphore;
}

// An image barrier on the first mip level and layer of one aspect.
VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageAspectFlags aspect, VkImageLayout old_layout,
                                    VkImageLayout new_layout, VkPipelineStageFlags2 src_stage,
                                    VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage,
                                    VkAccessFlags2 dst_access) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = src_stage;
    b.srcAccessMask = src_access;
    b.dstStageMask = dst_stage;
    b.dstAccessMask = dst_access;
    b.oldLayout = old_layout;
    b.newLayout = new_layout;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    return b;
}

// A barrier after a copy that wrote the whole buffer.
VkBufferMemoryBarrier2 after_copy_barrier(VkBuffer buffer, VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) {
    VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.dstStageMask = dst_stage;
    b.dstAccessMask = dst_access;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.buffer = buffer;
    b.size = VK_WHOLE_SIZE;
    return b;
}

// Records the barriers into cmd with vkCmdPipelineBarrier2 (the loader's or
// the device's, as the caller dispatches).
void pipeline_barrier(PFN_vkCmdPipelineBarrier2 barrier, VkCommandBuffer cmd,
                      std::span<const VkImageMemoryBarrier2> images,
                      std::span<const VkBufferMemoryBarrier2> buffers = {}) {
    VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dependency.imageMemoryBarrierCount = static_cast<std::uint32_t>(images.size());
    dependency.pImageMemoryBarriers = images.data();
    dependency.bufferMemoryBarrierCount = static_cast<std::uint32_t>(buffers.size());
    dependency.pBufferMemoryBarriers = buffers.data();
    barrier(cmd, &dependency);
}

// Copies the first mip level of a colour image (already in TRANSFER_SRC
// layout) to a host-visible buffer and makes the bytes visible to the host;
// after_copy, when given, rides in the same barrier (a layout change back).
void copy_image_to_host(const Gpu& gpu, VkCommandBuffer cmd, VkImage image, VkExtent2D extent, VkBuffer buffer,
                        std::span<const VkImageMemoryBarrier2> after_copy = {}) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {extent.width, extent.height, 1};
    gpu.fn.vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
    const VkBufferMemoryBarrier2 to_host =
        after_copy_barrier(buffer, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    pipeline_barrier(gpu.fn.vkCmdPipelineBarrier2, cmd, after_copy, {&to_host, 1});
}

// Begins a one-time-submit recording of cmd after resetting its pool.
void begin_one_time(const Gpu& gpu, VkCommandPool pool, VkCommandBuffer cmd) {
    check(gpu.fn.vkResetCommandPool(gpu.device, pool, 0), "vkResetCommandPool");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(gpu.fn.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
}

void wait_and_reset(const Gpu& gpu, VkFence fence) {
    check(gpu.fn.vkWaitForFences(gpu.device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check(gpu.fn.vkResetFences(gpu.device, 1, &fence), "vkResetFences");
}

// Submits the recorded cmd signalling fence, waits for the fence and resets
// it. A frame's submission may wait on an acquire semaphore and signal a
// render-done one, at the submit stage's pipeline stages.
void submit_and_wait(const Gpu& gpu, VkCommandBuffer cmd, VkFence fence, VkSemaphore wait = VK_NULL_HANDLE,
                     VkSemaphore signal = VK_NULL_HANDLE) {
    VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmd_info.commandBuffer = cmd;
    VkSemaphoreSubmitInfo wait_info{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    wait_info.semaphore = wait;
    wait_info.stageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSemaphoreSubmitInfo signal_info{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    signal_info.semaphore = signal;
    signal_info.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    if (wait) {
        submit.waitSemaphoreInfoCount = 1;
        submit.pWaitSemaphoreInfos = &wait_info;
    }
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmd_info;
    if (signal) {
        submit.signalSemaphoreInfoCount = 1;
        submit.pSignalSemaphoreInfos = &signal_info;
    }
    check(gpu.fn.vkQueueSubmit2(gpu.queue, 1, &submit, fence), "vkQueueSubmit2");
    wait_and_reset(gpu, fence);
}

// Ends a one-off recording, then submit_and_wait.
void end_submit_and_wait(const Gpu& gpu, VkCommandBuffer cmd, VkFence fence, VkSemaphore signal = VK_NULL_HANDLE) {
    check(gpu.fn.vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    submit_and_wait(gpu, cmd, fence, VK_NULL_HANDLE, signal);
}

// ---- Buffers and images -----------------------------------------------------

// A buffer with its own allocation; mapped when host-visible.
struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
};

struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
};

std::uint32_t memory_type(const Gpu& gpu, std::uint32_t bits, VkMemoryPropertyFlags wanted) {
    const VkPhysicalDeviceMemoryProperties& memory = gpu.memory_properties;
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    return UINT32_MAX;
}

// Memory for requirements, of a type with the preferred properties where
// there is one, else with the fallback's.
VkDeviceMemory allocate_memory(const Gpu& gpu, const VkMemoryRequirements& requirements,
                               VkMemoryPropertyFlags preferred, VkMemoryPropertyFlags fallback) {
    std::uint32_t type = memory_type(gpu, requirements.memoryTypeBits, preferred);
    if (type == UINT32_MAX) type = memory_type(gpu, requirements.memoryTypeBits, fallback);
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    check(gpu.fn.vkAllocateMemory(gpu.device, &allocate, nullptr, &memory), "vkAllocateMemory");
    return memory;
}

void create_buffer(const Gpu& gpu, VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags preferred,
                   VkMemoryPropertyFlags fallback, VkBuffer& buffer, VkDeviceMemory& memory) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    check(gpu.fn.vkCreateBuffer(gpu.device, &info, nullptr, &buffer), "vkCreateBuffer");
    VkMemoryRequirements requirements;
    gpu.fn.vkGetBufferMemoryRequirements(gpu.device, buffer, &requirements);
    memory = allocate_memory(gpu, requirements, preferred, fallback);
    check(gpu.fn.vkBindBufferMemory(gpu.device, buffer, memory, 0), "vkBindBufferMemory");
}

// A mapped buffer in memory the host writes directly: device-local as well
// where the device offers that (integrated GPUs, lavapipe, resizable BAR).
void create_host_buffer(const Gpu& gpu, VkDeviceSize size, VkBufferUsageFlags usage, Buffer& buffer) {
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    create_buffer(gpu, size, usage, host | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, host, buffer.buffer, buffer.memory);
    check(gpu.fn.vkMapMemory(gpu.device, buffer.memory, 0, VK_WHOLE_SIZE, 0, &buffer.mapped), "vkMapMemory");
}

void destroy_buffer(const Gpu& gpu, VkBuffer buffer, VkDeviceMemory memory) {
    gpu.fn.vkDestroyBuffer(gpu.device, buffer, nullptr);
    gpu.fn.vkFreeMemory(gpu.device, memory, nullptr);  // unmaps implicitly
}

// Fills a buffer through a host-visible staging buffer (what
// vkrc::upload_buffer does), with a one-off command pool and fence. The data
// is visible to every later command (vertex input and index reads).
void upload(const Gpu& gpu, VkBuffer destination, const void* data, VkDeviceSize size) {
    Buffer staging;
    create_host_buffer(gpu, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, staging);
    std::memcpy(staging.mapped, data, size);
    const VkCommandPool pool = create_command_pool(gpu);
    const VkCommandBuffer cmd = allocate_command_buffer(gpu, pool, VK_COMMAND_BUFFER_LEVEL_PRIMARY);
    const VkFence fence = create_fence(gpu);
    begin_one_time(gpu, pool, cmd);
    VkBufferCopy region{0, 0, size};
    gpu.fn.vkCmdCopyBuffer(cmd, staging.buffer, destination, 1, &region);
    const VkBufferMemoryBarrier2 to_read =
        after_copy_barrier(destination, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT);
    pipeline_barrier(gpu.fn.vkCmdPipelineBarrier2, cmd, {}, {&to_read, 1});
    end_submit_and_wait(gpu, cmd, fence);
    gpu.fn.vkDestroyFence(gpu.device, fence, nullptr);
    gpu.fn.vkDestroyCommandPool(gpu.device, pool, nullptr);
    destroy_buffer(gpu, staging.buffer, staging.memory);
}

// A device-local buffer holding data.
template <typename T>
void create_filled_buffer(const Gpu& gpu, const std::vector<T>& data, VkBufferUsageFlags usage, VkBuffer& buffer,
                          VkDeviceMemory& memory) {
    const VkDeviceSize size = data.size() * sizeof(T);
    create_buffer(gpu, size, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, buffer,
                  memory);
    upload(gpu, buffer, data.data(), size);
}

VkImageView create_view(const Gpu& gpu, VkImage image, VkFormat format, VkImageAspectFlags aspect) {
    VkImageViewCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    info.image = image;
    info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    info.format = format;
    info.subresourceRange = {aspect, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    check(gpu.fn.vkCreateImageView(gpu.device, &info, nullptr, &view), "vkCreateImageView");
    return view;
}

// A 2D device-local image with one mip level and its view.
void create_image(const Gpu& gpu, VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                  VkExtent2D extent, Image& image) {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {extent.width, extent.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    check(gpu.fn.vkCreateImage(gpu.device, &info, nullptr, &image.image), "vkCreateImage");
    VkMemoryRequirements requirements;
    gpu.fn.vkGetImageMemoryRequirements(gpu.device, image.image, &requirements);
    image.memory = allocate_memory(gpu, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    check(gpu.fn.vkBindImageMemory(gpu.device, image.image, image.memory, 0), "vkBindImageMemory");
    image.view = create_view(gpu, image.image, format, aspect);
}

void destroy_image(const Gpu& gpu, Image& image) {
    gpu.fn.vkDestroyImageView(gpu.device, image.view, nullptr);
    gpu.fn.vkDestroyImage(gpu.device, image.image, nullptr);
    gpu.fn.vkFreeMemory(gpu.device, image.memory, nullptr);
    image = {};
}

// ---- Scene and render targets -----------------------------------------------

// The mesh: three device-local buffers filled by a staging upload. The
// handles lie side by side, as the command stage has always read them (both
// vertex buffers in one load: the baseline's instruction count).
struct MeshBuffers {
    VkBuffer positions = VK_NULL_HANDLE, normals = VK_NULL_HANDLE, indices = VK_NULL_HANDLE;
    VkDeviceMemory positions_memory = VK_NULL_HANDLE, normals_memory = VK_NULL_HANDLE, indices_memory = VK_NULL_HANDLE;
    std::uint32_t index_count = 0;
};

void create_mesh(const Gpu& gpu, const Mesh& mesh, MeshBuffers& buffers) {
    create_filled_buffer(gpu, mesh.positions, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, buffers.positions,
                         buffers.positions_memory);
    create_filled_buffer(gpu, mesh.normals, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, buffers.normals, buffers.normals_memory);
    create_filled_buffer(gpu, mesh.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, buffers.indices, buffers.indices_memory);
    buffers.index_count = static_cast<std::uint32_t>(mesh.indices.size());
}

void destroy_mesh(const Gpu& gpu, MeshBuffers& buffers) {
    destroy_buffer(gpu, buffers.positions, buffers.positions_memory);
    destroy_buffer(gpu, buffers.normals, buffers.normals_memory);
    destroy_buffer(gpu, buffers.indices, buffers.indices_memory);
    buffers = {};
}

// What frames render into besides a swapchain's images: the headless ring
// (windowed: the one offscreen image of the reference frame), a depth image
// covering every target, and the buffer the image check reads back into.
struct Targets {
    VkFormat format = colour_format;  // windowed: the swapchain's, so that one pipeline serves both
    std::vector<Image> ring;
    Image depth;
    VkExtent2D depth_extent{};
    Buffer readback;
};

void create_ring(const Gpu& gpu, const Config& config, Targets& targets) {
    targets.ring.resize(config.window ? 1 : config.frames_in_flight + 1);
    for (Image& image : targets.ring)
        create_image(gpu, targets.format, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                     VK_IMAGE_ASPECT_COLOR_BIT, {config.width, config.height}, image);
}

// The depth image, as large as the ring's images and the swapchain's.
void create_depth(const Gpu& gpu, const Config& config, VkExtent2D swapchain_extent, Targets& targets) {
    targets.depth_extent = {std::max(config.width, swapchain_extent.width),
                            std::max(config.height, swapchain_extent.height)};
    create_image(gpu, depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT,
                 targets.depth_extent, targets.depth);
}

void destroy_targets(const Gpu& gpu, Targets& targets) {
    for (Image& image : targets.ring) destroy_image(gpu, image);
    destroy_image(gpu, targets.depth);
    destroy_buffer(gpu, targets.readback.buffer, targets.readback.memory);
}

// The readback buffer's pixels of an extent, as RGBA.
std::vector<std::uint8_t> read_pixels(const Targets& targets, VkExtent2D extent) {
    const auto* pixels = static_cast<const std::uint8_t*>(targets.readback.mapped);
    std::vector<std::uint8_t> bytes(pixels, pixels + std::size_t(extent.width) * extent.height * 4);
    to_rgba(bytes, targets.format);
    return bytes;
}

// ---- Pipeline ---------------------------------------------------------------

// The pipeline's fixed state, constant as in C: positions and normals in two
// bindings, triangle lists, depth test, viewport and scissor dynamic.
const VkVertexInputBindingDescription vertex_bindings[2] = {{0, sizeof(glm::vec3), VK_VERTEX_INPUT_RATE_VERTEX},
                                                            {1, sizeof(glm::vec3), VK_VERTEX_INPUT_RATE_VERTEX}};
const VkVertexInputAttributeDescription vertex_attributes[2] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                                {1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0}};
const VkPipelineVertexInputStateCreateInfo vertex_input{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
    .vertexBindingDescriptionCount = 2,
    .pVertexBindingDescriptions = vertex_bindings,
    .vertexAttributeDescriptionCount = 2,
    .pVertexAttributeDescriptions = vertex_attributes};
const VkPipelineInputAssemblyStateCreateInfo input_assembly{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
    .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
const VkPipelineViewportStateCreateInfo viewport_state{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO, .viewportCount = 1, .scissorCount = 1};
const VkPipelineRasterizationStateCreateInfo rasterization{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
    .polygonMode = VK_POLYGON_MODE_FILL,
    .cullMode = VK_CULL_MODE_NONE,  // the spout and lid openings show inner faces
    .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
    .lineWidth = 1.0f};
const VkPipelineMultisampleStateCreateInfo multisample{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO, .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT};
const VkPipelineDepthStencilStateCreateInfo depth_test{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
    .depthTestEnable = VK_TRUE,
    .depthWriteEnable = VK_TRUE,
    .depthCompareOp = VK_COMPARE_OP_LESS};
const VkPipelineColorBlendAttachmentState blend_attachment{.colorWriteMask =
                                                               VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                                               VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT};
const VkPipelineColorBlendStateCreateInfo colour_blend{
    .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
    .attachmentCount = 1,
    .pAttachments = &blend_attachment};
const VkDynamicState dynamic_states[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
const VkPipelineDynamicStateCreateInfo dynamic_state{.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
                                                     .dynamicStateCount = 2,
                                                     .pDynamicStates = dynamic_states};

struct Pipeline {
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;  // binding 0: the camera uniforms
    VkPipelineLayout layout = VK_NULL_HANDLE;           // that set and the per-teapot push constants
    VkPipeline pipeline = VK_NULL_HANDLE;
};

void create_layouts(const Gpu& gpu, Pipeline& pipeline) {
    VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo set_layout{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_layout.bindingCount = 1;
    set_layout.pBindings = &binding;
    check(gpu.fn.vkCreateDescriptorSetLayout(gpu.device, &set_layout, nullptr, &pipeline.set_layout),
          "vkCreateDescriptorSetLayout");
    VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(PushConstants)};
    VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout.setLayoutCount = 1;
    layout.pSetLayouts = &pipeline.set_layout;
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &push;
    check(gpu.fn.vkCreatePipelineLayout(gpu.device, &layout, nullptr, &pipeline.layout), "vkCreatePipelineLayout");
}

VkShaderModule create_shader(const Gpu& gpu, std::span<const std::uint32_t> code) {
    VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = code.size_bytes();
    info.pCode = code.data();
    VkShaderModule module;
    check(gpu.fn.vkCreateShaderModule(gpu.device, &info, nullptr, &module), "vkCreateShaderModule");
    return module;
}

VkPipelineShaderStageCreateInfo shader_stage(VkShaderStageFlagBits stage, VkShaderModule module) {
    return {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, stage, module, "main", nullptr};
}

// The layouts and the pipeline, for dynamic rendering into colour and
// depth_format.
void create_pipeline(const Gpu& gpu, VkFormat colour, Pipeline& pipeline) {
    create_layouts(gpu, pipeline);
    const VkShaderModule vert = create_shader(gpu, vkrc_shaders::teapot_vert);
    const VkShaderModule frag = create_shader(gpu, vkrc_shaders::teapot_frag);
    const VkPipelineShaderStageCreateInfo stages[2] = {shader_stage(VK_SHADER_STAGE_VERTEX_BIT, vert),
                                                       shader_stage(VK_SHADER_STAGE_FRAGMENT_BIT, frag)};
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachmentFormats = &colour;
    rendering.depthAttachmentFormat = depth_format;
    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &input_assembly;
    info.pViewportState = &viewport_state;
    info.pRasterizationState = &rasterization;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth_test;
    info.pColorBlendState = &colour_blend;
    info.pDynamicState = &dynamic_state;
    info.layout = pipeline.layout;
    VkResult result =
        gpu.fn.vkCreateGraphicsPipelines(gpu.device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline.pipeline);
    gpu.fn.vkDestroyShaderModule(gpu.device, vert, nullptr);
    gpu.fn.vkDestroyShaderModule(gpu.device, frag, nullptr);
    check(result, "vkCreateGraphicsPipelines");
}

void destroy_pipeline(const Gpu& gpu, Pipeline& pipeline) {
    gpu.fn.vkDestroyPipeline(gpu.device, pipeline.pipeline, nullptr);
    gpu.fn.vkDestroyPipelineLayout(gpu.device, pipeline.layout, nullptr);
    gpu.fn.vkDestroyDescriptorSetLayout(gpu.device, pipeline.set_layout, nullptr);
    pipeline = {};
}

// ---- Frame slots ------------------------------------------------------------

struct Frame {
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set = VK_NULL_HANDLE;
    VkSemaphore acquire_semaphore = VK_NULL_HANDLE;  // windowed only
    bool submitted = false;
    // --threads N > 1: per thread, a pool and its secondary.
    std::vector<VkCommandPool> thread_pools;
    std::vector<VkCommandBuffer> secondaries;
};

// The slots, the pool of their descriptor sets and the uniform buffer they
// share, one region per slot.
struct Frames {
    std::vector<Frame> slots;
    VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
    Buffer uniforms;
    VkDeviceSize uniform_stride = 0;  // the region's size rounded up to the device's alignment
};

void create_uniforms(const Gpu& gpu, const Config& config, Frames& frames) {
    const VkDeviceSize alignment = gpu.uniform_alignment;
    frames.uniform_stride = (sizeof(CameraUniforms) + alignment - 1) / alignment * alignment;
    create_host_buffer(gpu, frames.uniform_stride * config.frames_in_flight, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                       frames.uniforms);
}

void create_descriptor_pool(const Gpu& gpu, std::uint32_t slots, Frames& frames) {
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, slots};
    VkDescriptorPoolCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    info.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;  // as every variant's pool
    info.maxSets = slots;
    info.poolSizeCount = 1;
    info.pPoolSizes = &size;
    check(gpu.fn.vkCreateDescriptorPool(gpu.device, &info, nullptr, &frames.descriptor_pool), "vkCreateDescriptorPool");
}

// A slot's command pool and primary; per recording thread, a pool and a
// secondary.
void create_command_buffers(const Gpu& gpu, int threads, Frame& f) {
    f.pool = create_command_pool(gpu);
    f.cmd = allocate_command_buffer(gpu, f.pool, VK_COMMAND_BUFFER_LEVEL_PRIMARY);
    for (int t = 0; t < threads; ++t) {
        f.thread_pools.push_back(create_command_pool(gpu));
        f.secondaries.push_back(allocate_command_buffer(gpu, f.thread_pools.back(), VK_COMMAND_BUFFER_LEVEL_SECONDARY));
    }
}

// Slot i's descriptor set, bound to its region of the uniform buffer.
void create_descriptor_set(const Gpu& gpu, const Frames& frames, VkDescriptorSetLayout layout, std::uint32_t i,
                           Frame& f) {
    VkDescriptorSetAllocateInfo set{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    set.descriptorPool = frames.descriptor_pool;
    set.descriptorSetCount = 1;
    set.pSetLayouts = &layout;
    check(gpu.fn.vkAllocateDescriptorSets(gpu.device, &set, &f.descriptor_set), "vkAllocateDescriptorSets");
    VkDescriptorBufferInfo buffer{frames.uniforms.buffer, i * frames.uniform_stride, sizeof(CameraUniforms)};
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = f.descriptor_set;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    write.pBufferInfo = &buffer;
    gpu.fn.vkUpdateDescriptorSets(gpu.device, 1, &write, 0, nullptr);
}

// The slots, after create_uniforms: threads recording threads (0: the
// primary is recorded directly), windowed an acquire semaphore each.
void create_frames(const Gpu& gpu, const Config& config, int threads, VkDescriptorSetLayout layout, Frames& frames) {
    const auto slots = static_cast<std::uint32_t>(config.frames_in_flight);
    create_descriptor_pool(gpu, slots, frames);
    frames.slots.resize(slots);
    for (std::uint32_t i = 0; i < slots; ++i) {
        Frame& f = frames.slots[i];
        create_command_buffers(gpu, threads, f);
        f.fence = create_fence(gpu);
        if (config.window) f.acquire_semaphore = create_semaphore(gpu);
        create_descriptor_set(gpu, frames, layout, i, f);
    }
}

void destroy_frames(const Gpu& gpu, Frames& frames) {
    for (Frame& f : frames.slots) {
        gpu.fn.vkDestroySemaphore(gpu.device, f.acquire_semaphore, nullptr);
        gpu.fn.vkDestroyFence(gpu.device, f.fence, nullptr);
        gpu.fn.vkDestroyCommandPool(gpu.device, f.pool, nullptr);
        for (VkCommandPool pool : f.thread_pools) gpu.fn.vkDestroyCommandPool(gpu.device, pool, nullptr);
    }
    gpu.fn.vkDestroyDescriptorPool(gpu.device, frames.descriptor_pool, nullptr);
    destroy_buffer(gpu, frames.uniforms.buffer, frames.uniforms.memory);
    frames = {};
}

// ---- Window swapchain -------------------------------------------------------

// Windowed: the swapchain by the convention's rule and its per-image objects.
struct Swapchain {
    VkSurfaceFormatKHR surface_format{};
    VkPresentModeKHR present_mode = VK_PRESENT_MODE_FIFO_KHR;
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    VkExtent2D extent{};
    std::vector<VkImage> images;
    std::vector<VkImageView> views;
    std::vector<VkSemaphore> render_done;  // one per swapchain image
    bool stale = false;                    // OUT_OF_DATE or SUBOPTIMAL seen: re-create at the next acquire
};

// Format and present mode, chosen once: the pipeline is made for the format.
void choose_format_and_mode(const Gpu& gpu, Swapchain& sc) {
    sc.surface_format = choose_window_format(
        enumerate<VkSurfaceFormatKHR>("vkGetPhysicalDeviceSurfaceFormatsKHR", [&](auto* count, auto* items) {
            return vkGetPhysicalDeviceSurfaceFormatsKHR(gpu.physical_device, gpu.surface, count, items);
        }));
    sc.present_mode = choose_present_mode(
        enumerate<VkPresentModeKHR>("vkGetPhysicalDeviceSurfacePresentModesKHR", [&](auto* count, auto* items) {
            return vkGetPhysicalDeviceSurfacePresentModesKHR(gpu.physical_device, gpu.surface, count, items);
        }));
}

void destroy_swapchain(const Gpu& gpu, Swapchain& sc) {
    for (VkImageView view : sc.views) gpu.fn.vkDestroyImageView(gpu.device, view, nullptr);
    for (VkSemaphore semaphore : sc.render_done) gpu.fn.vkDestroySemaphore(gpu.device, semaphore, nullptr);
    sc.views.clear();
    sc.render_done.clear();
    sc.images.clear();
    if (sc.swapchain) gpu.fn.vkDestroySwapchainKHR(gpu.device, sc.swapchain, nullptr);
    sc.swapchain = VK_NULL_HANDLE;
}

VkSwapchainCreateInfoKHR swapchain_info(const Gpu& gpu, const Config& config, const Swapchain& sc,
                                        const VkSurfaceCapabilitiesKHR& caps, VkExtent2D extent) {
    VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    info.surface = gpu.surface;
    info.minImageCount = swapchain_image_request(config, caps);
    info.imageFormat = sc.surface_format.format;
    info.imageColorSpace = sc.surface_format.colorSpace;
    info.imageExtent = extent;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;  // the image check
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = composite_alpha(caps);
    info.presentMode = sc.present_mode;
    info.clipped = VK_TRUE;
    info.oldSwapchain = sc.swapchain;
    return info;
}

// A swapchain for the surface's current extent, retiring the previous one
// (the device is idle), with a view and a render-done semaphore per image;
// false while the surface has no area.
bool build_swapchain(const Gpu& gpu, const Config& config, Swapchain& sc) {
    VkSurfaceCapabilitiesKHR caps;
    check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(gpu.physical_device, gpu.surface, &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    const VkExtent2D extent = swapchain_extent(config, caps);
    if (extent.width == 0 || extent.height == 0) return false;
    const VkSwapchainCreateInfoKHR info = swapchain_info(gpu, config, sc, caps, extent);
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    const VkResult result = gpu.fn.vkCreateSwapchainKHR(gpu.device, &info, nullptr, &swapchain);
    destroy_swapchain(gpu, sc);  // retired even if the creation failed
    check(result, "vkCreateSwapchainKHR");
    sc.swapchain = swapchain;
    sc.images = enumerate<VkImage>("vkGetSwapchainImagesKHR", [&](auto* count, auto* items) {
        return gpu.fn.vkGetSwapchainImagesKHR(gpu.device, sc.swapchain, count, items);
    });
    for (VkImage image : sc.images) {
        sc.views.push_back(create_view(gpu, image, sc.surface_format.format, VK_IMAGE_ASPECT_COLOR_BIT));
        sc.render_done.push_back(create_semaphore(gpu));
    }
    sc.extent = extent;
    return true;
}

// build_swapchain, waiting while the window is minimised. Never inlined: the
// acquire stage re-creates through it, and inlined its loop would hold
// registers (pushed and popped) on every headless acquire too.
[[gnu::noinline]] void build_swapchain_when_visible(const Gpu& gpu, const Config& config, Swapchain& sc) {
    while (!build_swapchain(gpu, config, sc)) wait_window_events();
}

void create_swapchain(const Gpu& gpu, const Config& config, Swapchain& sc) {
    choose_format_and_mode(gpu, sc);
    build_swapchain_when_visible(gpu, config, sc);
}

// ---- The variant ------------------------------------------------------------

// What this frame renders into: a ring image or a swapchain image.
struct Target {
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkExtent2D extent{};
    VkImageLayout present_layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

template <bool Direct>
class RawVariant final : public Variant {
public:
    ~RawVariant() override {
        if (gpu_.device) {
            gpu_.fn.vkDeviceWaitIdle(gpu_.device);
            destroy_swapchain(gpu_, swapchain_);
            destroy_frames(gpu_, frames_);
            destroy_pipeline(gpu_, pipeline_);
            destroy_targets(gpu_, targets_);
            destroy_mesh(gpu_, mesh_);
        }
        destroy_gpu(gpu_);  // the surface before the window (a member) goes
    }

    void init(const Config& config, const SceneData& scene) override {
        config_ = config;
        recorders_ = config.threads > 1 ? scene.recorders : nullptr;
        draws_.resize(config.teapots);
        present_to_window_ = config.window;
        if (config.window) window_ = BenchWindow(config);
        create_instance(gpu_, config, window_);
        pick_physical_device(gpu_);
        create_device(gpu_);
        if (config.window) {
            create_swapchain(gpu_, config, swapchain_);
            targets_.format = swapchain_.surface_format.format;
        }
        create_mesh(gpu_, *scene.mesh, mesh_);
        create_uniforms(gpu_, config, frames_);
        create_host_buffer(gpu_, VkDeviceSize(config.width) * config.height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                           targets_.readback);
        create_ring(gpu_, config, targets_);
        create_depth(gpu_, config, swapchain_.extent, targets_);
        create_pipeline(gpu_, targets_.format, pipeline_);
        create_frames(gpu_, config, recorders_ ? recorders_->size() : 0, pipeline_.set_layout, frames_);
    }

    void acquire() override {
        slot_ = static_cast<std::uint32_t>(frame_ % config_.frames_in_flight);
        if (!present_to_window_) {
            image_ = static_cast<std::uint32_t>(frame_ % targets_.ring.size());
            target_ = {targets_.ring[image_].image,
                       targets_.ring[image_].view,
                       {config_.width, config_.height},
                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
            return;
        }
        for (;;) {
            if (swapchain_.stale) recreate_swapchain();
            VkResult result = call(&DeviceFunctions::vkAcquireNextImageKHR, ::vkAcquireNextImageKHR)(
                gpu_.device, swapchain_.swapchain, UINT64_MAX, frames_.slots[slot_].acquire_semaphore, VK_NULL_HANDLE,
                &image_);
            if (result == VK_ERROR_OUT_OF_DATE_KHR) {
                swapchain_.stale = true;
                continue;
            }
            if (result == VK_SUBOPTIMAL_KHR)
                swapchain_.stale = true;  // the image is still usable: re-created after its present
            else check(result, "vkAcquireNextImageKHR");
            break;
        }
        target_ = {swapchain_.images[image_], swapchain_.views[image_], swapchain_.extent,
                   VK_IMAGE_LAYOUT_PRESENT_SRC_KHR};
    }

    void uniform() override {
        write_camera_uniforms(static_cast<char*>(frames_.uniforms.mapped) + slot_ * frames_.uniform_stride, camera_,
                              config_.uniform_writes);
    }

    void command() override {
        Frame& f = frames_.slots[slot_];
        check(call(&DeviceFunctions::vkResetCommandPool, ::vkResetCommandPool)(gpu_.device, f.pool, 0),
              "vkResetCommandPool");
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VkCommandBuffer cmd = f.cmd;
        check(call(&DeviceFunctions::vkBeginCommandBuffer, ::vkBeginCommandBuffer)(cmd, &begin),
              "vkBeginCommandBuffer");
        const bool threaded = !f.secondaries.empty();
        begin_target(cmd, threaded ? VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT : 0);
        if (threaded) record_on_threads(f);
        else record_draws(cmd, f, {0, draws_.size()});
        end_target(cmd);
    }

    void submit() override {
        Frame& f = frames_.slots[slot_];
        VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
        cmd_info.commandBuffer = f.cmd;
        VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        submit.commandBufferInfoCount = 1;
        submit.pCommandBufferInfos = &cmd_info;
        VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        if (present_to_window_) {
            wait.semaphore = f.acquire_semaphore;
            wait.stageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
            signal.semaphore = swapchain_.render_done[image_];
            signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
            submit.waitSemaphoreInfoCount = 1;
            submit.pWaitSemaphoreInfos = &wait;
            submit.signalSemaphoreInfoCount = 1;
            submit.pSignalSemaphoreInfos = &signal;
        }
        check(call(&DeviceFunctions::vkQueueSubmit2, ::vkQueueSubmit2)(gpu_.queue, 1, &submit, f.fence),
              "vkQueueSubmit2");
        f.submitted = true;
    }

    void present() override {
        if (present_to_window_) {
            VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
            info.waitSemaphoreCount = 1;
            info.pWaitSemaphores = &swapchain_.render_done[image_];
            info.swapchainCount = 1;
            info.pSwapchains = &swapchain_.swapchain;
            info.pImageIndices = &image_;
            VkResult result = call(&DeviceFunctions::vkQueuePresentKHR, ::vkQueuePresentKHR)(gpu_.queue, &info);
            if (result == VK_ERROR_OUT_OF_DATE_KHR || result == VK_SUBOPTIMAL_KHR)
                swapchain_.stale = true;  // re-created at the next acquire
            else check(result, "vkQueuePresentKHR");
        }
        presented_image_ = image_;
        ++frame_;
    }

    void wait() override {
        Frame& next = frames_.slots[frame_ % config_.frames_in_flight];
        if (!next.submitted) return;
        check(call(&DeviceFunctions::vkWaitForFences, ::vkWaitForFences)(gpu_.device, 1, &next.fence, VK_TRUE,
                                                                         UINT64_MAX),
              "vkWaitForFences");
        check(call(&DeviceFunctions::vkResetFences, ::vkResetFences)(gpu_.device, 1, &next.fence), "vkResetFences");
        next.submitted = false;
    }

    void update(double t) override { update_scene(config_, t, draws_, camera_); }

    void drain() override { check(gpu_.fn.vkDeviceWaitIdle(gpu_.device), "vkDeviceWaitIdle"); }

    void render_offscreen(bool on) override { present_to_window_ = !on && config_.window; }

    std::string device_name() const override { return gpu_.name; }

    const BenchWindow* window() const override { return config_.window ? &window_ : nullptr; }

    std::string presentation() const override {
        return config_.window
                   ? swapchain_presentation(targets_.format, swapchain_.present_mode, swapchain_.images.size(),
                                            swapchain_.extent)
                   : headless_presentation(targets_.ring.size(), targets_.format, {config_.width, config_.height});
    }

private:
    // The device-level function: the loader's export for raw, the device's
    // own pointer for raw-direct. Resolved at compile time.
    template <typename Pfn>
    Pfn call(Pfn DeviceFunctions::*member, Pfn exported) const {
        if constexpr (Direct) return gpu_.fn.*member;
        else return exported;
    }

    // The barriers into the attachment layouts and the rendering's begin.
    void begin_target(VkCommandBuffer cmd, VkRenderingFlags flags) const {
        const VkPipelineStageFlags2 depth_stages =
            VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
        const VkImageMemoryBarrier2 to_render[2] = {
            image_barrier(target_.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0,
                          VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
            image_barrier(
                targets_.depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, depth_stages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                depth_stages,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT)};
        pipeline_barrier(call(&DeviceFunctions::vkCmdPipelineBarrier2, ::vkCmdPipelineBarrier2), cmd, to_render);

        VkRenderingAttachmentInfo colour{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        colour.imageView = target_.view;
        colour.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        colour.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        std::memcpy(colour.clearValue.color.float32, clear_colour, sizeof clear_colour);
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        depth.imageView = targets_.depth.view;
        depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
        depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        depth.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
        rendering.flags = flags;
        rendering.renderArea = {{0, 0}, target_.extent};
        rendering.layerCount = 1;
        rendering.colorAttachmentCount = 1;
        rendering.pColorAttachments = &colour;
        rendering.pDepthAttachment = &depth;
        call(&DeviceFunctions::vkCmdBeginRendering, ::vkCmdBeginRendering)(cmd, &rendering);
    }

    // The state every draw needs, then the draws of range: into the primary,
    // or one thread's slice into its secondary (which inherits no state).
    void record_draws(VkCommandBuffer cmd, const Frame& f, DrawRange range) const {
        call(&DeviceFunctions::vkCmdBindPipeline, ::vkCmdBindPipeline)(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS,
                                                                       pipeline_.pipeline);
        VkViewport viewport{0, 0, float(target_.extent.width), float(target_.extent.height), 0, 1};
        call(&DeviceFunctions::vkCmdSetViewport, ::vkCmdSetViewport)(cmd, 0, 1, &viewport);
        VkRect2D scissor{{0, 0}, target_.extent};
        call(&DeviceFunctions::vkCmdSetScissor, ::vkCmdSetScissor)(cmd, 0, 1, &scissor);
        call(&DeviceFunctions::vkCmdBindDescriptorSets, ::vkCmdBindDescriptorSets)(
            cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_.layout, 0, 1, &f.descriptor_set, 0, nullptr);
        VkBuffer vertex_buffers[2] = {mesh_.positions, mesh_.normals};
        VkDeviceSize offsets[2] = {0, 0};
        call(&DeviceFunctions::vkCmdBindVertexBuffers, ::vkCmdBindVertexBuffers)(cmd, 0, 2, vertex_buffers, offsets);
        call(&DeviceFunctions::vkCmdBindIndexBuffer, ::vkCmdBindIndexBuffer)(cmd, mesh_.indices, 0,
                                                                             VK_INDEX_TYPE_UINT16);
        auto push = call(&DeviceFunctions::vkCmdPushConstants, ::vkCmdPushConstants);
        auto draw = call(&DeviceFunctions::vkCmdDrawIndexed, ::vkCmdDrawIndexed);
        for (std::size_t i = range.first; i < range.last; ++i) {
            push(cmd, pipeline_.layout, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(PushConstants), &draws_[i]);
            draw(cmd, mesh_.index_count, 1, 0, 0, 0);
        }
    }

    // --threads N: thread i records its slice into the secondary of its own
    // pool; the primary executes them in thread order.
    void record_on_threads(const Frame& f) const {
        const int threads = int(f.secondaries.size());
        auto record = [&](int i) {
            const auto t = std::size_t(i);
            check(call(&DeviceFunctions::vkResetCommandPool, ::vkResetCommandPool)(gpu_.device, f.thread_pools[t], 0),
                  "vkResetCommandPool");
            VkCommandBufferInheritanceRenderingInfo rendering{
                VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO};
            rendering.colorAttachmentCount = 1;
            rendering.pColorAttachmentFormats = &targets_.format;
            rendering.depthAttachmentFormat = depth_format;
            rendering.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
            VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
            inheritance.pNext = &rendering;
            VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            begin.flags =
                VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT | VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT;
            begin.pInheritanceInfo = &inheritance;
            VkCommandBuffer secondary = f.secondaries[t];
            check(call(&DeviceFunctions::vkBeginCommandBuffer, ::vkBeginCommandBuffer)(secondary, &begin),
                  "vkBeginCommandBuffer");
            record_draws(secondary, f, draw_range(i, threads, draws_.size()));
            check(call(&DeviceFunctions::vkEndCommandBuffer, ::vkEndCommandBuffer)(secondary), "vkEndCommandBuffer");
        };
        recorders_->run(record);
        call(&DeviceFunctions::vkCmdExecuteCommands, ::vkCmdExecuteCommands)(
            f.cmd, static_cast<std::uint32_t>(f.secondaries.size()), f.secondaries.data());
    }

    // The rendering's end, the barrier to the presentation layout and the end.
    void end_target(VkCommandBuffer cmd) const {
        call(&DeviceFunctions::vkCmdEndRendering, ::vkCmdEndRendering)(cmd);
        const VkImageMemoryBarrier2 to_present =
            image_barrier(target_.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          target_.present_layout, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                          VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_NONE, 0);
        pipeline_barrier(call(&DeviceFunctions::vkCmdPipelineBarrier2, ::vkCmdPipelineBarrier2), cmd, {&to_present, 1});
        check(call(&DeviceFunctions::vkEndCommandBuffer, ::vkEndCommandBuffer)(cmd), "vkEndCommandBuffer");
    }

    // Out of the per-frame path: the device idle, a new swapchain for the
    // surface's extent and, where it grew past it, a larger depth image.
    void recreate_swapchain() {
        check(gpu_.fn.vkDeviceWaitIdle(gpu_.device), "vkDeviceWaitIdle");
        build_swapchain_when_visible(gpu_, config_, swapchain_);
        if (swapchain_.extent.width > targets_.depth_extent.width ||
            swapchain_.extent.height > targets_.depth_extent.height) {
            destroy_image(gpu_, targets_.depth);
            create_depth(gpu_, config_, swapchain_.extent, targets_);
        }
        swapchain_.stale = false;
    }

    // Drains, then copies the ring image last presented to the readback
    // buffer with a one-off command buffer from the last frame's slot.
    std::vector<std::uint8_t> read_back_offscreen() override {
        drain();
        Frame& f = frames_.slots[slot_];
        if (f.submitted) {
            wait_and_reset(gpu_, f.fence);
            f.submitted = false;
        }
        begin_one_time(gpu_, f.pool, f.cmd);
        const VkImage image = targets_.ring[presented_image_].image;
        const VkImageMemoryBarrier2 to_copy = image_barrier(
            image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        pipeline_barrier(gpu_.fn.vkCmdPipelineBarrier2, f.cmd, {&to_copy, 1});
        copy_image_to_host(gpu_, f.cmd, image, {config_.width, config_.height}, targets_.readback.buffer);
        end_submit_and_wait(gpu_, f.cmd, f.fence);
        return read_pixels(targets_, {config_.width, config_.height});
    }

    // Windowed: one more frame at time t through the window's stages, its
    // swapchain image copied to the readback buffer (the swapchain has
    // TRANSFER_SRC usage) between its rendering and its presentation: the
    // submission renders (waiting on the acquire semaphore), then a one-off
    // copy (copy_presented_image) signals the render-done semaphore that
    // present waits on.
    std::vector<std::uint8_t> read_back_presented_frame(double t) override {
        drain();
        update(t);
        acquire();
        uniform();
        command();
        if (swapchain_.extent.width != config_.width || swapchain_.extent.height != config_.height)
            throw std::runtime_error("windowed image check: the swapchain's extent is not --size");
        const Frame& f = frames_.slots[slot_];
        submit_and_wait(gpu_, f.cmd, f.fence, f.acquire_semaphore);
        copy_presented_image(f);
        std::vector<std::uint8_t> bytes = read_pixels(targets_, swapchain_.extent);
        present();
        wait();
        drain();
        return bytes;
    }

    // The acquired image PRESENT_SRC -> TRANSFER_SRC, copied, -> PRESENT_SRC.
    void copy_presented_image(const Frame& f) {
        begin_one_time(gpu_, f.pool, f.cmd);
        const VkImage image = swapchain_.images[image_];
        const VkImageMemoryBarrier2 to_copy = image_barrier(
            image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        pipeline_barrier(gpu_.fn.vkCmdPipelineBarrier2, f.cmd, {&to_copy, 1});
        const VkImageMemoryBarrier2 back = image_barrier(
            image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
            VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_NONE, 0);
        copy_image_to_host(gpu_, f.cmd, image, swapchain_.extent, targets_.readback.buffer, {&back, 1});
        end_submit_and_wait(gpu_, f.cmd, f.fence, swapchain_.render_done[image_]);
    }

    // The scene, as every variant keeps it.
    Config config_;
    CameraUniforms camera_{};
    std::vector<PushConstants> draws_;
    ThreadPool* recorders_ = nullptr;  // --threads N > 1

    // What init makes: the window, then the Vulkan objects in their C structs.
    BenchWindow window_;  // windowed only; outlives the surface (the destructor's body runs first)
    Gpu gpu_;
    Swapchain swapchain_;  // windowed only
    MeshBuffers mesh_;
    Frames frames_;
    Targets targets_;
    Pipeline pipeline_;

    // Where the frame loop is.
    std::uint64_t frame_ = 0;
    std::uint32_t slot_ = 0;
    std::uint32_t image_ = 0;  // in the ring, or in the swapchain
    std::uint32_t presented_image_ = 0;
    Target target_;
    bool present_to_window_ = false;  // windowed, except for the reference frame
};

}  // namespace

std::unique_ptr<Variant> make_raw_variant() { return std::make_unique<RawVariant<false>>(); }
std::unique_ptr<Variant> make_raw_direct_variant() { return std::make_unique<RawVariant<true>>(); }

}  // namespace teapot
