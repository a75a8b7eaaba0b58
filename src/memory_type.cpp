// Memory-type choice: the flags an intent implies and the best type for them.
#include "vkrc/memory.hpp"

#include "caller.hpp"
#include "text.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE

bool intent_needs_mapping(const MemoryIntent& intent) noexcept {
    return intent.usage == MemoryUsage::upload || intent.usage == MemoryUsage::readback ||
           (intent.required_flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
}

namespace {
// A few bits at most: cheaper than the library call std::popcount becomes
// without -mpopcnt.
int flag_count(VkMemoryPropertyFlags flags) noexcept {
    int n = 0;
    for (; flags; flags &= flags - 1) ++n;
    return n;
}
}  // namespace

namespace {
struct FlagChoice {
    VkMemoryPropertyFlags required, preferred, avoided;
};
// The intent's own flags plus what its usage implies.
FlagChoice flags_of(const MemoryIntent& intent) noexcept {
    VkMemoryPropertyFlags required = intent.required_flags;
    VkMemoryPropertyFlags preferred = intent.preferred_flags;
    VkMemoryPropertyFlags avoided = 0;
    switch (intent.usage) {
        case MemoryUsage::gpu_only:
            preferred |= VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
            avoided |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            break;
        case MemoryUsage::upload:
            required |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            preferred |= VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            break;
        case MemoryUsage::readback:
            required |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            preferred |= VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
            break;
        case MemoryUsage::custom: break;
    }
    return {required, preferred, avoided};
}
}  // namespace

int find_memory_type(const VkPhysicalDeviceMemoryProperties& properties, std::uint32_t type_bits,
                     const MemoryIntent& intent) noexcept {
    const auto [required, preferred, avoided] = flags_of(intent);
    // Memory only special resources may use is never chosen unless required.
    const VkMemoryPropertyFlags special = VK_MEMORY_PROPERTY_PROTECTED_BIT | VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT |
                                          VK_MEMORY_PROPERTY_DEVICE_COHERENT_BIT_AMD;
    int best = -1;
    int best_score = 0;
    for (std::uint32_t i = 0; i < properties.memoryTypeCount; ++i) {
        if (!(type_bits & (1u << i))) continue;
        const VkMemoryPropertyFlags flags = properties.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if (flags & special & ~required) continue;
        const int score = flag_count(flags & preferred) - flag_count(flags & avoided);
        if (best < 0 || score > best_score) {
            best = static_cast<int>(i);
            best_score = score;
        }
    }
    return best;
}

std::uint32_t choose_memory_type(const VkPhysicalDeviceMemoryProperties& properties, std::uint32_t type_bits,
                                 const MemoryIntent& intent, const char* who) {
    const int type = find_memory_type(properties, type_bits, intent);
    // Public, so the caller's name comes as text.
    detail::Caller(who).require(type >= 0, "no memory type of the device has the required property flags ",
                                detail::Hex{flags_of(intent).required}, " among the resource's allowed types ",
                                detail::Hex{type_bits});
    return static_cast<std::uint32_t>(type);
}

VKRC_END_NAMESPACE
