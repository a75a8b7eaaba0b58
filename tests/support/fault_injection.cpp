#include "fault_injection.hpp"

#include <atomic>
#include <cstring>
#include <string_view>
#include <tuple>
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
// Which failable functions were called since forget_called().
std::atomic<bool> called[int(Fn::count)];
std::atomic<bool> called_after_setup[int(Fn::count)];
std::atomic<std::uint64_t> setup_end{0};
// arm_function's target (-1: none) and whether it waits for end_of_setup().
std::atomic<int> armed_function{-1};
std::atomic<bool> armed_after_setup{false};
std::atomic<bool> armed_every{false};  // fail_every()
std::atomic<bool> hide_coherence{false};
// The device of the scenario, for simulating loss (one device at a time).
std::atomic<VkDevice> current_device{VK_NULL_HANDLE};
const char* names[int(Fn::count)] = {
#define VKRC_GLOBAL_FUNCTION(name) #name,
#define VKRC_INSTANCE_FUNCTION(name) #name,
#define VKRC_DEVICE_FUNCTION(name) #name,
#include <vkrc/detail/function_list.inl>
};

// A lost device runs nothing any more. lavapipe is not really lost, so the
// work already submitted is finished here, as a real loss would end it; what
// vkrc then destroys is not in use. Real calls made later keep working.
void simulate_loss() {
    VkDevice device = current_device.load();
    auto wait_idle = reinterpret_cast<PFN_vkDeviceWaitIdle>(real[int(Fn::vkDeviceWaitIdle)].load());
    if (device != VK_NULL_HANDLE && wait_idle) wait_idle(device);
}

std::atomic<bool> lost{false};

// The calls that report VK_ERROR_DEVICE_LOST once a device is lost.
bool reports_loss(Fn id) {
    switch (id) {
        case Fn::vkQueueSubmit:
        case Fn::vkQueueSubmit2:
        case Fn::vkQueueWaitIdle:
        case Fn::vkDeviceWaitIdle:
        case Fn::vkWaitForFences:
        case Fn::vkGetFenceStatus:
        case Fn::vkWaitSemaphores:
        case Fn::vkGetSemaphoreCounterValue:
        case Fn::vkGetEventStatus:
        case Fn::vkGetQueryPoolResults:
        case Fn::vkQueuePresentKHR:
        case Fn::vkAcquireNextImageKHR: return true;
        default: return false;
    }
}

void strip_coherence(VkPhysicalDeviceMemoryProperties* p) {
    for (std::uint32_t i = 0; i < p->memoryTypeCount; ++i) {
        auto& flags = p->memoryTypes[i].propertyFlags;
        if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) flags &= ~VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    }
}
void strip_coherence(VkPhysicalDeviceMemoryProperties2* p) { strip_coherence(&p->memoryProperties); }

// Counts the call; returns the error to inject, or VK_SUCCESS to go through.
VkResult next_call(Fn id) {
    if (lost.load() && reports_loss(id)) {
        fired_name.store(names[int(id)]);
        return VK_ERROR_DEVICE_LOST;
    }
    called[int(id)].store(true);
    if (setup_end.load() != 0) called_after_setup[int(id)].store(true);
    std::uint64_t n = calls.fetch_add(1) + 1;
    const bool function_armed = armed_function.load() == int(id) &&
                                (armed_every.load() || fired_name.load() == nullptr) &&
                                (!armed_after_setup.load() || setup_end.load() != 0);
    if (n == armed_call.load() || function_armed) {
        fired_name.store(names[int(id)]);
        const VkResult error = armed_error.load();
        if (error == VK_ERROR_DEVICE_LOST) simulate_loss();
        return error;
    }
    return VK_SUCCESS;
}

template <Fn id, class Pfn>
struct Wrap;
template <Fn id, class R, class... Args>
struct Wrap<id, R(VKAPI_PTR*)(Args...)> {
    static R VKAPI_PTR call(Args... args) {
        if constexpr (id == Fn::vkDestroyDevice) {
            VkDevice device = reinterpret_cast<VkDevice>(std::get<0>(std::tuple<Args...>(args...)));
            VkDevice expected = device;
            current_device.compare_exchange_strong(expected, VK_NULL_HANDLE);
        }
        if constexpr (std::is_same_v<R, VkResult>) {
            if (VkResult e = next_call(id); e != VK_SUCCESS) return e;
        }
        auto f = reinterpret_cast<R(VKAPI_PTR*)(Args...)>(real[int(id)].load());
        if constexpr (id == Fn::vkGetPhysicalDeviceMemoryProperties || id == Fn::vkGetPhysicalDeviceMemoryProperties2) {
            f(args...);
            if (hide_coherence.load()) strip_coherence(std::get<1>(std::tuple<Args...>(args...)));
        } else {
            return f(args...);
        }
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

// Whether each entry returns VkResult.
template <class Pfn>
struct ReturnsResult;
template <class R, class... Args>
struct ReturnsResult<R(VKAPI_PTR*)(Args...)> : std::is_same<R, VkResult> {};
#define VKRC_FAILABLE(name) ReturnsResult<PFN_##name>::value,
const bool failable[] = {
#define VKRC_GLOBAL_FUNCTION(name) VKRC_FAILABLE(name)
#define VKRC_INSTANCE_FUNCTION(name) VKRC_FAILABLE(name)
#define VKRC_DEVICE_FUNCTION(name) VKRC_FAILABLE(name)
#include <vkrc/detail/function_list.inl>
};
#undef VKRC_FAILABLE

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
    if (device != VK_NULL_HANDLE) current_device.store(device);
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
    lost.store(false);
    setup_end.store(0);
    armed_function.store(-1);
    armed_every.store(false);
    armed_error.store(error);
    armed_call.store(call);
    calls.store(0);
    fired_name.store(nullptr);
}
void arm_function(const char* name, VkResult error, bool after_setup) {
    arm(0, error);
    armed_after_setup.store(after_setup);
    for (int i = 0; i < int(Fn::count); ++i)
        if (std::strcmp(names[i], name) == 0) armed_function.store(i);
}
void fail_every(const char* name, VkResult error) {
    arm_function(name, error, false);
    armed_every.store(true);
}
std::uint64_t failable_calls() { return calls.load(); }
void lose_device() {
    fired_name.store(nullptr);
    simulate_loss();
    lost.store(true);
}
void lose_device_in_flight() {
    fired_name.store(nullptr);
    lost.store(true);
}
void finish_real_work() { simulate_loss(); }
bool fired() { return fired_name.load() != nullptr; }

std::vector<std::string> failable_functions() {
    std::vector<std::string> out;
    for (int i = 0; i < int(Fn::count); ++i)
        if (failable[i]) out.emplace_back(names[i]);
    return out;
}
std::vector<std::string> called_functions(bool after_setup) {
    std::vector<std::string> out;
    for (int i = 0; i < int(Fn::count); ++i)
        if ((after_setup ? called_after_setup : called)[i].load()) out.emplace_back(names[i]);
    return out;
}
void forget_called() {
    for (auto& c : called) c.store(false);
    for (auto& c : called_after_setup) c.store(false);
}
void end_of_setup() {
    if (setup_end.load() == 0) setup_end.store(calls.load());
}
std::uint64_t setup_calls() { return setup_end.load(); }
void hide_host_coherence(bool on) { hide_coherence.store(on); }
const char* fired_in() { return fired_name.load(); }

}  // namespace vkrc_test::faults
