#include "vkrc/error.hpp"

#include "caller.hpp"
#include "enum_names.hpp"
#include "vkrc/handle.hpp"

#include <cstdint>
#include <cstring>
#include <new>
#include <string>

// The symbol code compiled for this library's policy references (vkrc/config.hpp).
extern "C" const char VKRC_DETAIL_POLICY_SYMBOL = 0;

VKRC_BEGIN_NAMESPACE

const char* to_string(VkResult result) noexcept {
    switch (result) {
#define VKRC_RESULT(name) \
  case name: return #name;
        VKRC_RESULT(VK_SUCCESS)
        VKRC_RESULT(VK_NOT_READY)
        VKRC_RESULT(VK_TIMEOUT)
        VKRC_RESULT(VK_EVENT_SET)
        VKRC_RESULT(VK_EVENT_RESET)
        VKRC_RESULT(VK_INCOMPLETE)
        VKRC_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        VKRC_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        VKRC_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        VKRC_RESULT(VK_ERROR_DEVICE_LOST)
        VKRC_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        VKRC_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        VKRC_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        VKRC_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        VKRC_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        VKRC_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        VKRC_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        VKRC_RESULT(VK_ERROR_FRAGMENTED_POOL)
        VKRC_RESULT(VK_ERROR_UNKNOWN)
        VKRC_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        VKRC_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        VKRC_RESULT(VK_ERROR_FRAGMENTATION)
        VKRC_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        VKRC_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
        VKRC_RESULT(VK_ERROR_SURFACE_LOST_KHR)
        VKRC_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
        VKRC_RESULT(VK_SUBOPTIMAL_KHR)
        VKRC_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
        VKRC_RESULT(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)
        VKRC_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
        VKRC_RESULT(VK_ERROR_INVALID_SHADER_NV)
        VKRC_RESULT(VK_ERROR_FULL_SCREEN_EXCLUSIVE_MODE_LOST_EXT)
#undef VKRC_RESULT
        default: return nullptr;
    }
}

namespace detail {
namespace {
// The value's name, or its type and number for a value the table lacks.
std::string enum_text_of(const char* name, const char* type, long long value) {
    return name ? std::string(name) : std::string(type) + "(" + std::to_string(value) + ")";
}
}  // namespace

#include "enum_names.inl"

void throw_empty_handle(const char* call) {
    Caller(call).refuse(
        "the handle is empty (default-constructed, moved-from or reset(); an adopted Buffer or Image has no "
        "Allocation)");
}
void throw_stale_handle(const char* type) {
    Caller(type).refuse("the wrapper's copy of the raw handle differs from its state's (a vkrc bug; please report it)");
}
void throw_empty_handle(const char* type, const char* member) {
    throw_empty_handle((std::string(type) + "::" + member).c_str());
}
}  // namespace detail

Error::Error(VkResult result, const char* call) : result_(result), call_(call) {
    const char* name = vkrc::to_string(result);
    std::string message =
        std::string(call) + " failed: " + (name ? std::string(name) : "VkResult(" + std::to_string(int(result)) + ")");
    what_ = Text(message.data(), message.size());
}

// The characters follow the block; the count is atomic under both policies
// because an exception may be copied on another thread (std::exception_ptr).
struct Text::Block {
    std::uint32_t refs;
    std::size_t size;
    char* chars() noexcept { return reinterpret_cast<char*>(this + 1); }
};

Text::Text(const char* text) : Text(text, text ? std::strlen(text) : 0) {}

Text::Text(const char* data, std::size_t size) {
    void* memory = ::operator new(sizeof(Block) + size + 1);
    block_ = new (memory) Block{1, size};
    if (size) std::memcpy(block_->chars(), data, size);
    block_->chars()[size] = '\0';
}

Text::Text(const Text& other) noexcept : block_(other.block_) {
    if (block_) __atomic_fetch_add(&block_->refs, 1, __ATOMIC_RELAXED);
}

Text::~Text() {
    if (block_ && __atomic_fetch_sub(&block_->refs, 1, __ATOMIC_ACQ_REL) == 1) {
        block_->~Block();
        ::operator delete(block_);
    }
}

const char* Text::c_str() const noexcept { return block_ ? block_->chars() : ""; }
std::size_t Text::size() const noexcept { return block_ ? block_->size : 0; }
bool Text::contains(const char* part) const noexcept { return std::strstr(c_str(), part) != nullptr; }
bool operator==(const Text& a, const char* b) noexcept { return std::strcmp(a.c_str(), b ? b : "") == 0; }

namespace detail {
void throw_vk_error(VkResult result, const char* call) {
    if (result == VK_ERROR_DEVICE_LOST) throw DeviceLostError(call);
    throw Error(result, call);
}
}  // namespace detail

VKRC_END_NAMESPACE
