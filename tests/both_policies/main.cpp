#include <cstdio>
#include <string>

std::string use_single_thread_policy();
std::string use_multi_thread_policy();

int main() {
    std::printf("st: %s\n", use_single_thread_policy().c_str());
    std::printf("mt: %s\n", use_multi_thread_policy().c_str());
}
