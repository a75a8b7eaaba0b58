// Instance, debug messages and physical devices.
#pragma once

#include "vkrc/error.hpp"
#include "vkrc/functions.hpp"

#include "vkrc/detail/span.hpp"
#include "vkrc/handle.hpp"
#include "vkrc/detail/function.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class InstanceState;
class PhysicalDeviceState;
}  // namespace detail

class PhysicalDevice;
struct InstanceExtensionFunctions;

// One message from VK_EXT_debug_utils (the validation layer among others).
struct DebugMessage {
    VkDebugUtilsMessageSeverityFlagBitsEXT severity{};
    VkDebugUtilsMessageTypeFlagsEXT types{};
    const char* message_id_name{};  // may be null
    const char* message{};
    // The objects the message is about, with their names (set_name) where given.
    Span<const VkDebugUtilsObjectNameInfoEXT> objects{};
};
using DebugCallback = Function<void(const DebugMessage&)>;

// Writes "vkrc [warning|error|info|verbose] <id>: <message>" to stderr.
void print_debug_message(const DebugMessage& message);

// Mirrors VkInstanceCreateInfo, plus vkrc conveniences.
// Every member is optional. Pointers and lists are read during create() (the
// enabled extension names are copied): they need not outlive the call.
struct InstanceCreateInfo {
    // Default "vkrc application".
    const char* application_name = "vkrc application";
    // Default 0.
    std::uint32_t application_version = 0;
    // The highest Vulkan version the application uses (default 1.3, what vkrc needs).
    std::uint32_t api_version = VK_API_VERSION_1_3;
    // Default none.
    List<const char*> enabled_layer_names{};
    // Default none (vkrc adds what validation and debug_callback need).
    List<const char*> enabled_extension_names{};
    // Adds VK_LAYER_KHRONOS_validation and VK_EXT_debug_utils. Default false.
    bool validation = false;
    // Installs a debug-utils messenger for the instance's whole life (and for
    // vkCreateInstance/vkDestroyInstance themselves). Null with validation on
    // means print_debug_message. Set it without validation to hear other layers.
    // Copied into the Instance: what it refers to must outlive the Instance.
    DebugCallback debug_callback{};
    // Which messages reach the callback (default warnings and errors).
    VkDebugUtilsMessageSeverityFlagsEXT debug_severities =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    // Entry point every function is loaded through; null means the loader's.
    PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
    // Chained into VkInstanceCreateInfo::pNext (e.g. VkValidationFeaturesEXT).
    // Null: none. Read during create() only.
    const void* next = nullptr;
};

class Instance : public Handle<detail::InstanceState> {
public:
    static Instance create(const InstanceCreateInfo& info);
    // The defaults: a separate overload so that a caller's translation unit
    // does not build and destroy a default create-info (bench/header_cost).
    static Instance create();
    // Wraps an instance made elsewhere. With Ownership::owned vkrc destroys it.
    // enabled_extensions and enabled_layers: what it was created with, so
    // that extension_enabled (and Surface::adopt, which needs VK_KHR_surface)
    // see them.
    static Instance adopt(VkInstance instance, Ownership ownership, std::uint32_t api_version,
                          PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr,
                          Span<const char* const> enabled_extensions = {}, Span<const char* const> enabled_layers = {});

    VkInstance vk() const VKRC_UNCHECKED_NOEXCEPT;
    const InstanceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT;
    const GlobalFunctions& global_fn() const VKRC_UNCHECKED_NOEXCEPT;
    // Every instance-level extension command (include vkrc/extension_functions.hpp).
    const InstanceExtensionFunctions& ext_fn() const;
    std::uint32_t api_version() const VKRC_UNCHECKED_NOEXCEPT;
    bool extension_enabled(const char* name) const VKRC_UNCHECKED_NOEXCEPT;
    bool layer_enabled(const char* name) const VKRC_UNCHECKED_NOEXCEPT;

    List<PhysicalDevice> physical_devices() const;

    // Names of the available instance layers / extensions (for choosing what to enable).
    static List<Text> available_layers(PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr);
    static List<Text> available_extensions(PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr);

private:
    using Handle::Handle;
    friend class PhysicalDevice;
};

namespace detail {
// A zeroed Vulkan struct with its sType (aggregate init would name every member).
template <class T>
constexpr T with_type(VkStructureType type) noexcept {
    T t{};
    t.sType = type;
    return t;
}
}  // namespace detail

// The Vulkan 1.0-1.3 feature structs and those of the extensions vkrc wraps
// (mesh shading, ray tracing), unchained: the sTypes are set and every pNext
// is null, so copies are safe (vkrc chains them when it queries).
struct DeviceFeatures {
    VkPhysicalDeviceFeatures core{};
    VkPhysicalDeviceVulkan11Features vulkan11 =
        detail::with_type<VkPhysicalDeviceVulkan11Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES);
    VkPhysicalDeviceVulkan12Features vulkan12 =
        detail::with_type<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    VkPhysicalDeviceVulkan13Features vulkan13 =
        detail::with_type<VkPhysicalDeviceVulkan13Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES);
    // VK_EXT_mesh_shader (taskShader, meshShader): read only from a device that offers the extension.
    VkPhysicalDeviceMeshShaderFeaturesEXT mesh_shader = detail::with_type<VkPhysicalDeviceMeshShaderFeaturesEXT>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT);
    // VK_KHR_acceleration_structure's and VK_KHR_ray_query's: read only where
    // the device offers the extension (all VK_FALSE otherwise).
    VkPhysicalDeviceAccelerationStructureFeaturesKHR acceleration_structure =
        detail::with_type<VkPhysicalDeviceAccelerationStructureFeaturesKHR>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR);
    VkPhysicalDeviceRayQueryFeaturesKHR ray_query = detail::with_type<VkPhysicalDeviceRayQueryFeaturesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
    // VK_KHR_ray_tracing_pipeline's, likewise.
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR ray_tracing_pipeline =
        detail::with_type<VkPhysicalDeviceRayTracingPipelineFeaturesKHR>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR);
};

// What a device must offer to be chosen. Every unmet item is reported.
// Every member is optional and read during select() only.
struct DeviceRequirements {
    // Default 1.3 (what vkrc needs).
    std::uint32_t min_api_version = VK_API_VERSION_1_3;
    // A queue family must have all of them (default graphics and compute).
    VkQueueFlags queue_flags = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    // Default none.
    List<const char*> required_extensions{};
    // Every feature set to VK_TRUE must be supported; each missing one is
    // named in the rejection. Default none.
    DeviceFeatures required_features{};
    // A queue family of the chosen device must be able to present to it (default: no surface).
    VkSurfaceKHR present_surface = VK_NULL_HANDLE;
    // Devices of earlier types in this list win; CPU devices (lavapipe) are accepted.
    List<VkPhysicalDeviceType> preferred_types = {
        VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU,
        VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU, VK_PHYSICAL_DEVICE_TYPE_CPU, VK_PHYSICAL_DEVICE_TYPE_OTHER};
    // Only a device whose name contains this text (e.g. from an environment variable). Null: any.
    const char* name_contains = nullptr;
};

// Thrown when no physical device meets the requirements; what() lists every
// device with the reasons it was rejected.
class NoSuitableDeviceError : public std::exception {
public:
    NoSuitableDeviceError(Text message, List<Text> rejections)
        : what_(moves::move(message)), rejections_(moves::move(rejections)) {}
    const char* what() const noexcept override { return what_.c_str(); }
    // One line per rejected device: "<name>: <reason>; <reason>".
    const List<Text>& rejections() const noexcept { return rejections_; }

private:
    Text what_;
    List<Text> rejections_;
};

// A physical device; keeps its Instance alive. Properties are read once.
class PhysicalDevice : public Handle<detail::PhysicalDeviceState> {
public:
    // Chooses the best device that meets the requirements, or throws
    // NoSuitableDeviceError naming each device and why it was rejected.
    static PhysicalDevice select(const Instance& instance, const DeviceRequirements& requirements);
    // The defaults: a separate overload so that a caller's translation unit
    // does not build and destroy a default DeviceRequirements (bench/header_cost).
    static PhysicalDevice select(const Instance& instance);
    // The reasons this device fails the requirements; empty when it meets them.
    List<Text> unmet_requirements(const DeviceRequirements& requirements) const;

    VkPhysicalDevice vk() const VKRC_UNCHECKED_NOEXCEPT;
    const Instance& instance() const VKRC_UNCHECKED_NOEXCEPT;
    const InstanceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT;
    const VkPhysicalDeviceProperties& properties() const VKRC_UNCHECKED_NOEXCEPT;
    const VkPhysicalDeviceMemoryProperties& memory_properties() const VKRC_UNCHECKED_NOEXCEPT;
    const List<VkQueueFamilyProperties>& queue_families() const VKRC_UNCHECKED_NOEXCEPT;
    // The 1.0-1.3 and extension features, read once (those of versions the
    // device or the instance lacks, or of extensions the device lacks, stay VK_FALSE).
    const DeviceFeatures& features() const VKRC_UNCHECKED_NOEXCEPT;
    // vkGetPhysicalDeviceFormatProperties2 with VkFormatProperties3 (64-bit
    // flags); before Vulkan 1.3, the 32-bit flags widened. pNext is null.
    VkFormatProperties3 format_properties(VkFormat format) const;
    // The family select() chose: the first with the requirements' queue_flags
    // that can present to their present_surface, if one was given. For a
    // device not chosen by select(), the first with graphics and compute; -1 if none.
    int default_queue_family() const VKRC_UNCHECKED_NOEXCEPT;
    const char* name() const VKRC_UNCHECKED_NOEXCEPT { return properties().deviceName; }
    bool supports_extension(const char* name) const VKRC_UNCHECKED_NOEXCEPT;
    // First family with all the flags (and presentation to surface if given), or -1.
    int find_queue_family(VkQueueFlags flags, VkSurfaceKHR present_surface = VK_NULL_HANDLE) const;

private:
    using Handle::Handle;
    friend class Instance;
};

namespace detail {

class InstanceState final : public RefCounted {
public:
    ~InstanceState() override;

    VkInstance instance = VK_NULL_HANDLE;
    Ownership ownership = Ownership::owned;
    std::uint32_t api_version = 0;
    GlobalFunctions global_fn;
    InstanceFunctions fn;
    // Loaded by the first Instance::ext_fn() (src/extension_functions.cpp).
    PolicyAtomic<InstanceExtensionFunctions*> ext_fn{nullptr};
    List<Text> enabled_extensions;
    List<Text> enabled_layers;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    DebugCallback debug_callback;  // the messengers' user data: the state never moves
};

class PhysicalDeviceState final : public RefCounted {
public:
    Instance instance;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memory_properties{};
    List<VkQueueFamilyProperties> queue_families;
    DeviceFeatures features;
    List<Text> extensions;
    int default_queue_family = -1;
};

}  // namespace detail

inline VkInstance Instance::vk() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Instance::vk").instance; }
inline const InstanceFunctions& Instance::fn() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Instance::fn").fn; }
inline const GlobalFunctions& Instance::global_fn() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Instance::global_fn").global_fn;
}
inline std::uint32_t Instance::api_version() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Instance::api_version").api_version;
}

inline VkPhysicalDevice PhysicalDevice::vk() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::vk").physical_device;
}
inline const Instance& PhysicalDevice::instance() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::instance").instance;
}
inline const InstanceFunctions& PhysicalDevice::fn() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::fn").instance.fn();
}
inline const VkPhysicalDeviceProperties& PhysicalDevice::properties() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::properties").properties;
}
inline const VkPhysicalDeviceMemoryProperties& PhysicalDevice::memory_properties() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::memory_properties").memory_properties;
}
inline const List<VkQueueFamilyProperties>& PhysicalDevice::queue_families() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::queue_families").queue_families;
}
inline const DeviceFeatures& PhysicalDevice::features() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::features").features;
}
inline int PhysicalDevice::default_queue_family() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PhysicalDevice::default_queue_family").default_queue_family;
}

VKRC_END_NAMESPACE
