#include "vkrc/shader.hpp"

#include "object_state.hpp"
#include "text.hpp"

#include <filesystem>
#include <cstring>
#include <string>
#include <fstream>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {
ShaderModuleState::~ShaderModuleState() { destroy_owned<&DeviceFunctions::vkDestroyShaderModule>(*this, device); }
}  // namespace detail

namespace {
constexpr std::uint32_t spirv_magic = 0x07230203;

detail::Ref<detail::ShaderModuleState> make(const detail::Caller& caller, const Device& device, const void* code,
                                            std::size_t bytes) {
    caller.require_handle(device, "the Device");
    caller.require(bytes != 0, "the SPIR-V module is empty");
    caller.require(bytes % 4 == 0, "the SPIR-V size (", bytes, " bytes) is not a multiple of 4");
    std::uint32_t magic = 0;
    std::memcpy(&magic, code, 4);
    if (magic != spirv_magic)
        caller.refuse("not SPIR-V (magic number 0x", detail::hex(magic, 8), ", expected 0x07230203)");
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = static_cast<const std::uint32_t*>(code);
    return detail::created_state<detail::ShaderModuleState, &DeviceFunctions::vkCreateShaderModule>(
        device, ci, "vkCreateShaderModule");
}
}  // namespace

ShaderModule ShaderModule::create(const Device& device, Span<const std::uint32_t> spirv) {
    return ShaderModule(make(detail::Caller{"vkrc::ShaderModule::create"}, device, spirv.data(), spirv.size_bytes()));
}

ShaderModule ShaderModule::create(const Device& device, Span<const std::byte> spirv) {
    // Vulkan wants 4-byte-aligned words; bytes from anywhere are copied into them.
    std::vector<std::uint32_t> words((spirv.size() + 3) / 4);
    if (!spirv.empty()) std::memcpy(words.data(), spirv.data(), spirv.size());
    return ShaderModule(make(detail::Caller{"vkrc::ShaderModule::create"}, device, words.data(), spirv.size()));
}

ShaderModule ShaderModule::adopt(const Device& device, VkShaderModule module, Ownership ownership) {
    return ShaderModule(detail::adopted_state<detail::ShaderModuleState>(
        detail::Caller{"vkrc::ShaderModule::adopt"}, device, "the Device", module, "VkShaderModule", ownership));
}

ShaderModule ShaderModule::load(const Device& device, const char* spv_file) {
    const detail::Caller caller{"vkrc::ShaderModule::load"};
    std::ifstream in(spv_file, std::ios::binary);
    caller.require(static_cast<bool>(in), "cannot open ", spv_file);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::uint32_t> words((bytes.size() + 3) / 4);
    if (!bytes.empty()) std::memcpy(words.data(), bytes.data(), bytes.size());
    return ShaderModule(make(detail::Caller(caller.name(), spv_file), device, words.data(), bytes.size()));
}

VKRC_END_NAMESPACE
