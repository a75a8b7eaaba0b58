// Shader modules from SPIR-V words (as vkrc_add_shaders embeds them) or files.
#pragma once

#include "vkrc/device.hpp"

#include <cstddef>
#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class ShaderModuleState;
}

class ShaderModule : public DeviceChild<detail::ShaderModuleState, VkShaderModule> {
public:
    // Throws UsageError for an empty module or a wrong SPIR-V magic number.
    static ShaderModule create(const Device& device, Span<const std::uint32_t> spirv);
    // Bytes of a .spv file; also rejects a size that is not a multiple of 4.
    static ShaderModule create(const Device& device, Span<const std::byte> spirv);
    static ShaderModule load(const Device& device, const char* spv_file);
    // Wraps one made elsewhere from device. With Ownership::owned vkrc destroys
    // it once the GPU is done; borrowed, its maker does (after vkrc's last use).
    static ShaderModule adopt(const Device& device, VkShaderModule module, Ownership ownership);

private:
    using DeviceChild::DeviceChild;
};

namespace detail {
class ShaderModuleState final : public DeviceChildState<VkShaderModule> {
public:
    static constexpr const char* type_name = "vkrc::ShaderModule";
    ~ShaderModuleState() override;
};
}  // namespace detail

VKRC_END_NAMESPACE
