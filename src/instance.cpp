#include "vkrc/instance.hpp"

#include "vkrc/extension_functions.hpp"

#include "caller.hpp"
#include "debug_message.hpp"
#include "text.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

constexpr const char* validation_layer = "VK_LAYER_KHRONOS_validation";

// The 1.0-1.3 features of versions both the device and the instance have,
// and those of the extensions in DeviceFeatures that the device offers (a
// struct of an extension it lacks must not be chained).
void read_features(const InstanceFunctions& f, VkPhysicalDevice raw, std::uint32_t version, Span<const Text> extensions,
                   DeviceFeatures& out) {
    if (version < VK_API_VERSION_1_2) {
        f.vkGetPhysicalDeviceFeatures(raw, &out.core);
        return;
    }
    out.vulkan11.pNext = &out.vulkan12;
    out.vulkan12.pNext = version >= VK_API_VERSION_1_3 ? &out.vulkan13 : nullptr;
    void*& tail = version >= VK_API_VERSION_1_3 ? out.vulkan13.pNext : out.vulkan12.pNext;
    if (detail::contains(extensions, VK_EXT_MESH_SHADER_EXTENSION_NAME)) tail = &out.mesh_shader;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &out.vulkan11};
    f.vkGetPhysicalDeviceFeatures2(raw, &features);
    out.core = features.features;
    out.vulkan11.pNext = out.vulkan12.pNext = out.vulkan13.pNext = nullptr;
}

// The ray tracing extensions' features, for a device that offers them
// (vkGetPhysicalDeviceFeatures2 is core from Vulkan 1.1).
void read_extension_features(const InstanceFunctions& f, VkPhysicalDevice raw, std::uint32_t version,
                             const List<Text>& extensions, DeviceFeatures& out) {
    if (version < VK_API_VERSION_1_1) return;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    if (detail::contains(extensions, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME)) {
        out.acceleration_structure.pNext = features.pNext;
        features.pNext = &out.acceleration_structure;
    }
    if (detail::contains(extensions, VK_KHR_RAY_QUERY_EXTENSION_NAME)) {
        out.ray_query.pNext = features.pNext;
        features.pNext = &out.ray_query;
    }
    if (detail::contains(extensions, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME)) {
        out.ray_tracing_pipeline.pNext = features.pNext;
        features.pNext = &out.ray_tracing_pipeline;
    }
    if (!features.pNext) return;
    f.vkGetPhysicalDeviceFeatures2(raw, &features);
    out.acceleration_structure.pNext = out.ray_query.pNext = out.ray_tracing_pipeline.pNext = nullptr;
}

}  // namespace

namespace detail {
VKAPI_ATTR VkBool32 VKAPI_CALL debug_trampoline(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT types,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    const auto& callback = *static_cast<const DebugCallback*>(user);
    callback(
        DebugMessage{severity, types, data->pMessageIdName, data->pMessage, Span(data->pObjects, data->objectCount)});
    return VK_FALSE;  // never abort the call that produced the message
}
}  // namespace detail

void print_debug_message(const DebugMessage& message) {
    const char* level = (message.severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)     ? "error"
                        : (message.severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) ? "warning"
                        : (message.severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT)    ? "info"
                                                                                               : "verbose";
    std::fprintf(stderr, "vkrc [%s] %s: %s\n", level, message.message_id_name ? message.message_id_name : "-",
                 message.message);
}

namespace detail {
InstanceState::~InstanceState() {
    delete ext_fn.load(__ATOMIC_ACQUIRE);
    if (messenger != VK_NULL_HANDLE) fn.vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
    if (ownership == Ownership::owned && instance != VK_NULL_HANDLE) fn.vkDestroyInstance(instance, nullptr);
}
}  // namespace detail

namespace {

// The extensions asked for, and those vkrc needs: debug utils for the
// messenger (validation or a callback) and portability enumeration where the
// loader has it.
std::vector<const char*> instance_extensions(const InstanceCreateInfo& info, bool portability) {
    std::vector<const char*> extensions(info.enabled_extension_names.begin(), info.enabled_extension_names.end());
    if (info.validation || info.debug_callback) detail::add_unique(extensions, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (portability) detail::add_unique(extensions, VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
    return extensions;
}

VkApplicationInfo application_info(const InstanceCreateInfo& info) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = info.application_name;
    app.applicationVersion = info.application_version;
    app.pEngineName = "vkrc";
    app.apiVersion = info.api_version;
    return app;
}

// The messenger of info's severities, calling callback (which must outlive it); chained before info.next.
VkDebugUtilsMessengerCreateInfoEXT messenger_create_info(const InstanceCreateInfo& info, DebugCallback& callback) {
    VkDebugUtilsMessengerCreateInfoEXT m{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    m.messageSeverity = info.debug_severities;
    m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    m.pfnUserCallback = detail::debug_trampoline;
    m.pUserData = &callback;
    m.pNext = info.next;
    return m;
}

// Records raw in a new state, which from then on owns it (unless borrowed).
void init_state(detail::InstanceState& s, VkInstance raw, std::uint32_t api_version, const GlobalFunctions& global,
                Span<const char* const> extensions, Span<const char* const> layers) {
    s.instance = raw;
    s.api_version = api_version;
    s.global_fn = global;
    s.fn = InstanceFunctions::load(global.vkGetInstanceProcAddr, raw);
    for (const char* e : extensions) s.enabled_extensions.push_back(e);
    for (const char* l : layers) s.enabled_layers.push_back(l);
}

}  // namespace

Instance Instance::create() { return create(InstanceCreateInfo{}); }

Instance Instance::create(const InstanceCreateInfo& info) {
    auto global = GlobalFunctions::load(info.get_instance_proc_addr);
    std::vector<const char*> layers(info.enabled_layer_names.begin(), info.enabled_layer_names.end());
    if (info.validation) detail::add_unique(layers, validation_layer);
    // With it, the loader also lists portability drivers (MoltenVK); those
    // need VK_KHR_portability_subset, which Device::create enables.
    const bool portability = detail::contains(available_extensions(info.get_instance_proc_addr),
                                              VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
    const auto extensions = instance_extensions(info, portability);
    // The state exists before the instance: its callback's address is the
    // messenger's user data from vkCreateInstance to vkDestroyInstance.
    Instance instance(detail::Ref<detail::InstanceState>(new detail::InstanceState));
    auto& s = *instance.state_;
    const bool messenger = info.debug_callback || info.validation;
    if (messenger) s.debug_callback = info.debug_callback ? info.debug_callback : DebugCallback(print_debug_message);
    const VkApplicationInfo app = application_info(info);
    // The same messenger description is chained into vkCreateInstance so that
    // messages from instance creation and destruction reach the callback too.
    VkDebugUtilsMessengerCreateInfoEXT messenger_info = messenger_create_info(info, s.debug_callback);

    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pNext = messenger ? &messenger_info : info.next;
    if (portability) ci.flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();

    VkInstance raw = VK_NULL_HANDLE;
    check(global.vkCreateInstance(&ci, nullptr, &raw), "vkCreateInstance");
    // From here the state owns the instance: an exception below destroys it.
    init_state(s, raw, info.api_version, global, extensions, layers);
    if (messenger) {
        messenger_info.pNext = nullptr;
        check(s.fn.vkCreateDebugUtilsMessengerEXT(raw, &messenger_info, nullptr, &s.messenger),
              "vkCreateDebugUtilsMessengerEXT");
    }
    return instance;
}

Instance Instance::adopt(VkInstance raw, Ownership ownership, std::uint32_t api_version,
                         PFN_vkGetInstanceProcAddr get_instance_proc_addr, Span<const char* const> enabled_extensions,
                         Span<const char* const> enabled_layers) {
    detail::Caller("vkrc::Instance::adopt").require_not_null(raw, "VkInstance");
    auto global = GlobalFunctions::load(get_instance_proc_addr);
    Instance instance(detail::Ref<detail::InstanceState>(new detail::InstanceState));
    auto& s = *instance.state_;
    s.ownership = ownership;
    init_state(s, raw, api_version, global, enabled_extensions, enabled_layers);
    return instance;
}

bool Instance::extension_enabled(const char* name) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Instance::extension_enabled");
    return detail::contains(state_->enabled_extensions, name);
}

bool Instance::layer_enabled(const char* name) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Instance::layer_enabled");
    return detail::contains(state_->enabled_layers, name);
}

List<Text> Instance::available_layers(PFN_vkGetInstanceProcAddr get_instance_proc_addr) {
    auto global = GlobalFunctions::load(get_instance_proc_addr);
    auto props = detail::enumerate<VkLayerProperties>(global.vkEnumerateInstanceLayerProperties,
                                                      "vkEnumerateInstanceLayerProperties");
    std::vector<Text> names;
    for (const auto& p : props) names.emplace_back(p.layerName);
    return names;
}

List<Text> Instance::available_extensions(PFN_vkGetInstanceProcAddr get_instance_proc_addr) {
    auto global = GlobalFunctions::load(get_instance_proc_addr);
    auto props = detail::enumerate<VkExtensionProperties>(global.vkEnumerateInstanceExtensionProperties,
                                                          "vkEnumerateInstanceExtensionProperties", nullptr);
    std::vector<Text> names;
    for (const auto& p : props) names.emplace_back(p.extensionName);
    return names;
}

List<PhysicalDevice> Instance::physical_devices() const {
    const auto& f = fn();
    auto raws = detail::enumerate<VkPhysicalDevice>(f.vkEnumeratePhysicalDevices, "vkEnumeratePhysicalDevices", vk());
    std::vector<PhysicalDevice> devices;
    for (VkPhysicalDevice raw : raws) {
        PhysicalDevice device(detail::Ref<detail::PhysicalDeviceState>(new detail::PhysicalDeviceState));
        auto& s = *device.state_;
        s.instance = *this;
        s.physical_device = raw;
        f.vkGetPhysicalDeviceProperties(raw, &s.properties);
        f.vkGetPhysicalDeviceMemoryProperties(raw, &s.memory_properties);
        std::uint32_t families = 0;
        f.vkGetPhysicalDeviceQueueFamilyProperties(raw, &families, nullptr);
        s.queue_families.resize(families);
        f.vkGetPhysicalDeviceQueueFamilyProperties(raw, &families, s.queue_families.data());
        auto exts = detail::enumerate<VkExtensionProperties>(f.vkEnumerateDeviceExtensionProperties,
                                                             "vkEnumerateDeviceExtensionProperties", raw, nullptr);
        for (const auto& e : exts) s.extensions.push_back(e.extensionName);
        read_features(f, raw, std::min(s.properties.apiVersion, api_version()), s.extensions, s.features);
        read_extension_features(f, raw, std::min(s.properties.apiVersion, api_version()), s.extensions, s.features);
        s.default_queue_family = device.find_queue_family(VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT);
        devices.push_back(std::move(device));
    }
    return devices;
}

VKRC_END_NAMESPACE
