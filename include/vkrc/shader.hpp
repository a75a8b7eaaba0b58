// Shader modules from SPIR-V words (as vkrc_add_shaders embeds them) or files.
#pragma once

#include "vkrc/device.hpp"

#include <cstddef>
#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class ShaderModuleState;
}

class ShaderModule : public Handle<detail::ShaderModuleState> {
public:
    ShaderModule() noexcept = default;
    // Throws UsageError for an empty module or a wrong SPIR-V magic number.
    static ShaderModule create(const Device& device, Span<const std::uint32_t> spirv);
    // Bytes of a .spv file; also rejects a size that is not a multiple of 4.
    static ShaderModule create(const Device& device, Span<const std::byte> spirv);
    static ShaderModule load(const Device& device, const char* spv_file);
    // Wraps one made elsewhere from device. With Ownership::owned vkrc destroys
    // it once the GPU is done; borrowed, its maker does (after vkrc's last use).
    static ShaderModule adopt(const Device& device, VkShaderModule module, Ownership ownership);

    VkShaderModule vk() const VKRC_UNCHECKED_NOEXCEPT;
    const Device& device() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using Handle::Handle;
};

namespace detail {
class ShaderModuleState final : public RefCounted {
public:
    ~ShaderModuleState() override;
    Device device;
    VkShaderModule module = VK_NULL_HANDLE;
    Ownership ownership = Ownership::owned;
};
}  // namespace detail

inline VkShaderModule ShaderModule::vk() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::ShaderModule::vk").module; }
inline const Device& ShaderModule::device() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::ShaderModule::device").device;
}

VKRC_END_NAMESPACE
