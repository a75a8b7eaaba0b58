// Header-cost probe: no vkrc, only the standard and Vulkan headers that
// vkrc's public API is made of (std::string and std::system_error in errors
// and create-infos, std::vector, std::span, std::function, std::atomic,
// std::mutex), and an empty main. The least a translation unit using vkrc's
// API as it stands can cost; keep the list in step with include/vkrc.
#include <vkrc/detail/light_std.hpp>
#include <vulkan/vulkan_core.h>

#include <atomic>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

int main() {}
