// Header-cost probe: no vkrc, only the standard and Vulkan headers that
// vkrc's public API is made of (std::exception as the base of its errors,
// <initializer_list> and <new> under vkrc::List and vkrc::Function, <cstring>
// for mapped copies), and an empty main.
// The least a translation unit using vkrc's API as it stands can cost; keep
// the list in step with include/vkrc.
#include <vulkan/vulkan_core.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <initializer_list>
#include <new>

int main() {}
