// Header-cost probe: no vkrc, only the standard and Vulkan headers that
// vkrc's public API is made of (std::exception as the base of its errors,
// std::vector in create-infos, std::span, std::function, and pthread.h under
// vkrc::Mutex), and an empty main. The least a translation
// unit using vkrc's API as it stands can cost; keep the list in step with
// include/vkrc.
#include <vkrc/detail/light_std.hpp>
#include <vulkan/vulkan_core.h>

#include <pthread.h>

#include <cstddef>
#include <cstdint>
#include <exception>
#include <span>
#include <utility>
#include <vector>

int main() {}
