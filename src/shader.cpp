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

detail::Ref<detail::ShaderModuleState> make(const Device& device, const void* code, std::size_t bytes,
                                            const char* who) {
    detail::require_handle(device, who, "the Device");
    if (bytes == 0) throw UsageError(std::string(who) + ": the SPIR-V module is empty");
    if (bytes % 4 != 0) {
        throw UsageError(std::string(who) + ": the SPIR-V size (" + std::to_string(bytes) +
                         " bytes) is not a multiple of 4");
    }
    std::uint32_t magic = 0;
    std::memcpy(&magic, code, 4);
    if (magic != spirv_magic) {
        throw UsageError(std::string(who) + ": not SPIR-V (magic number 0x" + detail::hex(magic, 8) +
                         ", expected 0x07230203)");
    }
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = static_cast<const std::uint32_t*>(code);
    return detail::created_state<detail::ShaderModuleState, &DeviceFunctions::vkCreateShaderModule>(
        device, ci, "vkCreateShaderModule");
}
}  // namespace

ShaderModule ShaderModule::create(const Device& device, Span<const std::uint32_t> spirv) {
    return ShaderModule(make(device, spirv.data(), spirv.size_bytes(), "vkrc::ShaderModule::create"));
}

ShaderModule ShaderModule::create(const Device& device, Span<const std::byte> spirv) {
    // Vulkan wants 4-byte-aligned words; bytes from anywhere are copied into them.
    std::vector<std::uint32_t> words((spirv.size() + 3) / 4);
    if (!spirv.empty()) std::memcpy(words.data(), spirv.data(), spirv.size());
    return ShaderModule(make(device, words.data(), spirv.size(), "vkrc::ShaderModule::create"));
}

ShaderModule ShaderModule::adopt(const Device& device, VkShaderModule module, Ownership ownership) {
    return ShaderModule(detail::adopted_state<detail::ShaderModuleState>(
        "vkrc::ShaderModule::adopt", device, "the Device", module, "VkShaderModule", ownership));
}

ShaderModule ShaderModule::load(const Device& device, const char* spv_file) {
    std::ifstream in(spv_file, std::ios::binary);
    if (!in) throw UsageError("vkrc::ShaderModule::load: cannot open " + std::string(spv_file));
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::uint32_t> words((bytes.size() + 3) / 4);
    if (!bytes.empty()) std::memcpy(words.data(), bytes.data(), bytes.size());
    const std::string who = "vkrc::ShaderModule::load: " + std::string(spv_file);
    return ShaderModule(make(device, words.data(), bytes.size(), who.c_str()));
}

VKRC_END_NAMESPACE
