#include "fault_injection.hpp"

#include <atomic>
#include <cstring>
#include <string_view>
#include <type_traits>

namespace vkrc_test::faults {
namespace {

enum class Fn : int {
#define VKRC_GLOBAL_FUNCTION(name) name,
#define VKRC_INSTANCE_FUNCTION(name) name,
#define VKRC_DEVICE_FUNCTION(name) name,
#include <vkrc/detail/function_list.inl>
    count
};

std::atomic<PFN_vkVoidFunction> real[int(Fn::count)];
std::atomic<PFN_vkGetDeviceProcAddr> real_get_device_proc_addr{nullptr};
std::atomic<std::uint64_t> calls{0};
std::atomic<std::uint64_t> armed_call{0};
std::atomic<VkResult> armed_error{VK_SUCCESS};
std::atomic<const char*> fired_name{nullptr};
const char* names[int(Fn::count)] = {
#define VKRC_GLOBAL_FUNCTION(name) #name,
#define VKRC_INSTANCE_FUNCTION(name) #name,
#define VKRC_DEVICE_FUNCTION(name) #name,
#include <vkrc/detail/function_list.inl>
};

// Counts the call; returns the error to inject, or VK_SUCCESS to go through.
VkResult next_call(Fn id) {
    std::uint64_t n = calls.fetch_add(1) + 1;
    if (n == armed_call.load()) {
        fired_name.store(names[int(id)]);
        return armed_error.load();
    }
    return VK_SUCCESS;
}

template <Fn id, class Pfn>
struct Wrap;
template <Fn id, class R, class... Args>
struct Wrap<id, R(VKAPI_PTR*)(Args...)> {
    static R VKAPI_PTR call(Args... args) {
        if constexpr (std::is_same_v<R, VkResult>) {
            if (VkResult e = next_call(id); e != VK_SUCCESS) return e;
        }
        auto f = reinterpret_cast<R(VKAPI_PTR*)(Args...)>(real[int(id)].load());
        return f(args...);
    }
};

struct Entry {
    const char* name;
    PFN_vkVoidFunction wrapper;
};
const Entry entries[] = {
#define VKRC_GLOBAL_FUNCTION(name) {#name, reinterpret_cast<PFN_vkVoidFunction>(&Wrap<Fn::name, PFN_##name>::call)},
#define VKRC_INSTANCE_FUNCTION(name) {#name, reinterpret_cast<PFN_vkVoidFunction>(&Wrap<Fn::name, PFN_##name>::call)},
#define VKRC_DEVICE_FUNCTION(name) {#name, reinterpret_cast<PFN_vkVoidFunction>(&Wrap<Fn::name, PFN_##name>::call)},
#include <vkrc/detail/function_list.inl>
};

PFN_vkVoidFunction intercept(const char* name, PFN_vkVoidFunction found) {
    if (!found) return nullptr;
    for (int i = 0; i < int(Fn::count); ++i) {
        if (std::strcmp(entries[i].name, name) == 0) {
            real[i].store(found);
            return entries[i].wrapper;
        }
    }
    return found;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL get_device_proc_addr(VkDevice device, const char* name) {
    return intercept(name, real_get_device_proc_addr.load()(device, name));
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL wrapped_get_instance_proc_addr(VkInstance instance, const char* name) {
    PFN_vkVoidFunction found = vkGetInstanceProcAddr(instance, name);
    if (found && std::string_view(name) == "vkGetDeviceProcAddr") {
        real_get_device_proc_addr.store(reinterpret_cast<PFN_vkGetDeviceProcAddr>(found));
        return reinterpret_cast<PFN_vkVoidFunction>(&get_device_proc_addr);
    }
    return intercept(name, found);
}

}  // namespace

PFN_vkGetInstanceProcAddr get_instance_proc_addr() { return &wrapped_get_instance_proc_addr; }

void arm(std::uint64_t call, VkResult error) {
    armed_error.store(error);
    armed_call.store(call);
    calls.store(0);
    fired_name.store(nullptr);
}
std::uint64_t failable_calls() {
    return calls.load();
}
bool fired() { return fired_name.load() != nullptr; }
const char* fired_in() { return fired_name.load(); }

}  // namespace vkrc_test::faults
