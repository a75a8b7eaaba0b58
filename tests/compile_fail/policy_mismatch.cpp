// Linked against the library of the other policy (tests/CMakeLists.txt):
// the link must fail naming the define (vkrc/config.hpp), issue 34.
#include <vkrc/vkrc.hpp>

int main() { return vkrc::Instance::create({}).vk() != VK_NULL_HANDLE ? 0 : 1; }
