#include "vkrc/instance.hpp"

#include "enum_names.hpp"
#include "text.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {
// Adds "lacks feature <name> (Vulkan 1.x)" (or "(VK_EXT_...)", the extension
// that provides it) for each feature wanted but missing.
void add_missing_features(const DeviceFeatures& want, const DeviceFeatures& have, std::vector<std::string>& reasons) {
#define VKRC_FEATURE(group, version, name) \
  if (want.group.name && !have.group.name) reasons.push_back("lacks feature " #name " (" version ")");
#include "feature_names.inl"
#define VKRC_EXTENSION_FEATURE(group, extension, name) \
  if (want.group.name && !have.group.name) reasons.push_back("lacks feature " #name " (" extension ")");
    VKRC_EXTENSION_FEATURE(acceleration_structure, "VK_KHR_acceleration_structure", accelerationStructure)
    VKRC_EXTENSION_FEATURE(acceleration_structure, "VK_KHR_acceleration_structure", accelerationStructureCaptureReplay)
    VKRC_EXTENSION_FEATURE(acceleration_structure, "VK_KHR_acceleration_structure", accelerationStructureIndirectBuild)
    VKRC_EXTENSION_FEATURE(acceleration_structure, "VK_KHR_acceleration_structure", accelerationStructureHostCommands)
    VKRC_EXTENSION_FEATURE(acceleration_structure, "VK_KHR_acceleration_structure",
                           descriptorBindingAccelerationStructureUpdateAfterBind)
    VKRC_EXTENSION_FEATURE(ray_query, "VK_KHR_ray_query", rayQuery)
    VKRC_EXTENSION_FEATURE(ray_tracing_pipeline, "VK_KHR_ray_tracing_pipeline", rayTracingPipeline)
    VKRC_EXTENSION_FEATURE(ray_tracing_pipeline, "VK_KHR_ray_tracing_pipeline",
                           rayTracingPipelineShaderGroupHandleCaptureReplay)
    VKRC_EXTENSION_FEATURE(ray_tracing_pipeline, "VK_KHR_ray_tracing_pipeline",
                           rayTracingPipelineShaderGroupHandleCaptureReplayMixed)
    VKRC_EXTENSION_FEATURE(ray_tracing_pipeline, "VK_KHR_ray_tracing_pipeline", rayTracingPipelineTraceRaysIndirect)
    VKRC_EXTENSION_FEATURE(ray_tracing_pipeline, "VK_KHR_ray_tracing_pipeline", rayTraversalPrimitiveCulling)
#undef VKRC_EXTENSION_FEATURE
}

std::string version_string(std::uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}
}  // namespace

bool PhysicalDevice::supports_extension(const char* name) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::PhysicalDevice::supports_extension");
    return detail::contains(state_->extensions, name);
}

int PhysicalDevice::find_queue_family(VkQueueFlags flags, VkSurfaceKHR present_surface) const {
    const auto& families = queue_families();
    for (std::uint32_t i = 0; i < families.size(); ++i) {
        if ((families[i].queueFlags & flags) != flags) continue;
        if (present_surface != VK_NULL_HANDLE) {
            VkBool32 supported = VK_FALSE;
            check(fn().vkGetPhysicalDeviceSurfaceSupportKHR(vk(), i, present_surface, &supported),
                  "vkGetPhysicalDeviceSurfaceSupportKHR");
            if (!supported) continue;
        }
        return static_cast<int>(i);
    }
    return -1;
}

VkFormatProperties3 PhysicalDevice::format_properties(VkFormat format) const {
    VkFormatProperties3 props3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    if (std::min(properties().apiVersion, instance().api_version()) >= VK_API_VERSION_1_3) {
        VkFormatProperties2 props2{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &props3};
        fn().vkGetPhysicalDeviceFormatProperties2(vk(), format, &props2);
        props3.pNext = nullptr;
        return props3;
    }
    // The 64-bit flags keep the 32-bit flags' bit values.
    VkFormatProperties props{};
    fn().vkGetPhysicalDeviceFormatProperties(vk(), format, &props);
    props3.linearTilingFeatures = props.linearTilingFeatures;
    props3.optimalTilingFeatures = props.optimalTilingFeatures;
    props3.bufferFeatures = props.bufferFeatures;
    return props3;
}

List<Text> PhysicalDevice::unmet_requirements(const DeviceRequirements& req) const {
    std::vector<std::string> reasons;
    const auto& props = properties();
    if (props.apiVersion < req.min_api_version) {
        reasons.push_back("supports Vulkan " + version_string(props.apiVersion) + ", needs " +
                          version_string(req.min_api_version));
    }
    if (std::find(req.preferred_types.begin(), req.preferred_types.end(), props.deviceType) ==
        req.preferred_types.end()) {
        reasons.push_back("device type " + detail::enum_text(props.deviceType) + " is not among the accepted types");
    }
    if (req.name_contains && std::strstr(props.deviceName, req.name_contains) == nullptr) {
        reasons.push_back("name does not contain \"" + std::string(req.name_contains) + "\"");
    }
    for (const char* ext : req.required_extensions) {
        if (!supports_extension(ext)) reasons.push_back(std::string("lacks extension ") + ext);
    }
    if (find_queue_family(req.queue_flags) < 0) {
        reasons.push_back("no queue family with flags 0x" + detail::hex(req.queue_flags));
    } else if (req.present_surface != VK_NULL_HANDLE && find_queue_family(req.queue_flags, req.present_surface) < 0) {
        reasons.push_back("no queue family with those flags can present to the surface");
    }
    // vkrc is built on these three features; Vulkan 1.3 makes only two of them mandatory.
    auto want = req.required_features;
    if (props.apiVersion >= VK_API_VERSION_1_3) {
        want.vulkan12.timelineSemaphore = VK_TRUE;
        want.vulkan13.synchronization2 = VK_TRUE;
        want.vulkan13.dynamicRendering = VK_TRUE;
    }
    add_missing_features(want, features(), reasons);
    return std::vector<Text>(reasons.begin(), reasons.end());
}

PhysicalDevice PhysicalDevice::select(const Instance& instance) { return select(instance, DeviceRequirements{}); }

PhysicalDevice PhysicalDevice::select(const Instance& instance, const DeviceRequirements& req) {
    auto devices = instance.physical_devices();
    std::vector<std::string> rejections;
    PhysicalDevice best;
    std::size_t best_rank = SIZE_MAX;
    for (auto& device : devices) {
        auto reasons = device.unmet_requirements(req);
        if (!reasons.empty()) {
            std::string line = std::string(device.name()) + ": ";
            for (std::size_t i = 0; i < reasons.size(); ++i) line += (i ? "; " : "") + std::string(reasons[i].c_str());
            rejections.push_back(std::move(line));
            continue;
        }
        auto type = device.properties().deviceType;
        auto rank = static_cast<std::size_t>(std::find(req.preferred_types.begin(), req.preferred_types.end(), type) -
                                             req.preferred_types.begin());
        if (rank < best_rank) {
            best_rank = rank;
            best = device;
        }
    }
    if (best) {
        best.state_->default_queue_family = best.find_queue_family(req.queue_flags, req.present_surface);
        return best;
    }
    std::string message = devices.empty() ? "vkrc: no Vulkan physical device found (is a Vulkan driver installed?)"
                                          : "vkrc: no suitable Vulkan physical device";
    for (const auto& r : rejections) message += "\n  rejected " + r;
    throw NoSuitableDeviceError(Text(message), std::vector<Text>(rejections.begin(), rejections.end()));
}

VKRC_END_NAMESPACE
