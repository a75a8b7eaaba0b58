// Must not compile: one translation unit including vkrc under both policies.
#include <vkrc/vkrc.hpp>
#undef VKRC_MULTI_THREAD
#define VKRC_MULTI_THREAD 1
#include <vkrc/config.hpp>
int main() {}
