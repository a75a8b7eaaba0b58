// The generated extension tables (scripts/gen_registry_tables.py): which
// commands to load, from which entry point, and what stands in for the rest.
#include "vkrc/extension_functions.hpp"

#include "vkrc/device.hpp"

#include "caller.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

VKRC_BEGIN_NAMESPACE

namespace {

struct Command {
    bool device_table;
    const char* name;
    const char* core_name;  // the core command it became, or null
    std::uint32_t core_version;
    bool of_device_extension;
    // Space-separated alternatives, each an extension or extensions joined by '+'.
    const char* providers;
    std::size_t offset;  // of its slot in its table
};

using instance_table = InstanceExtensionFunctions;
using device_table = DeviceExtensionFunctions;

#define VKRC_EXTENSION_COMMAND(index, table, name, core, version, of_device_ext, providers) \
  {std::is_same_v<table##_table, DeviceExtensionFunctions>,                                 \
   #name,                                                                                   \
   core,                                                                                    \
   version,                                                                                 \
   of_device_ext,                                                                           \
   providers,                                                                               \
   offsetof(table##_table, name)},
constexpr Command commands[] = {
#include "extension_commands.inl"
};

#if VKRC_RUNTIME_CHECKS
[[noreturn]] void throw_unloaded(std::size_t index) {
    const Command& c = commands[index];
    std::string providers(c.providers);
    std::replace(providers.begin(), providers.end(), ' ', '|');
    // The caller is the application's call through the table, not a vkrc function.
    detail::Caller("vkrc").refuse(c.name, " was called but is not loaded: it needs ", providers,
                                  c.device_table          ? " enabled on the device or instance"
                                  : c.of_device_extension ? " offered by a driver"
                                                          : " enabled on the instance",
                                  c.core_name ? std::string(" (or Vulkan with ") + c.core_name + ")" : std::string());
}

// What an unloaded slot holds: a function of the command's own type that throws.
template <std::size_t Index, class F>
struct Unloaded;
template <std::size_t Index, class R, class... Args>
struct Unloaded<Index, R(VKAPI_PTR*)(Args...)> {
    static R VKAPI_CALL call(Args...) { throw_unloaded(Index); }
};

#  define VKRC_EXTENSION_COMMAND(index, table, name, core, version, of_device_ext, providers) \
    reinterpret_cast<PFN_vkVoidFunction>(&Unloaded<index, PFN_##name>::call),
const PFN_vkVoidFunction unloaded[] = {
#  include "extension_commands.inl"
};
#endif

// True when every extension of one alternative ("A" or "A+B") is enabled.
template <class Enabled>
bool all_enabled(std::string_view alternative, const Enabled& enabled) {
    while (!alternative.empty()) {
        auto end = std::min(alternative.find('+'), alternative.size());
        if (!enabled(std::string(alternative.substr(0, end)).c_str())) return false;
        alternative.remove_prefix(std::min(end + 1, alternative.size()));
    }
    return true;
}

template <class Enabled>
bool provided(std::string_view providers, const Enabled& enabled) {
    while (!providers.empty()) {
        auto end = std::min(providers.find(' '), providers.size());
        if (all_enabled(providers.substr(0, end), enabled)) return true;
        providers.remove_prefix(std::min(end + 1, providers.size()));
    }
    return false;
}

// Fills table's slots: each command by its core name when version includes
// it, else by its own name when wanted(command) says so, else the stand-in.
template <class Table, class GetProcAddr, class Wanted>
Table* load(std::uint32_t version, const GetProcAddr& get, const Wanted& wanted) {
    auto* table = new Table;
    for (std::size_t i = 0; i < std::size(commands); ++i) {
        const Command& c = commands[i];
        if (c.device_table != std::is_same_v<Table, DeviceExtensionFunctions>) continue;
        PFN_vkVoidFunction f = nullptr;
        if (c.core_name && version >= c.core_version) f = get(c.core_name);
        if (!f && wanted(c)) f = get(c.name);
#if VKRC_RUNTIME_CHECKS
        if (!f) f = unloaded[i];
#endif
        std::memcpy(reinterpret_cast<char*>(table) + c.offset, &f, sizeof f);
    }
    return table;
}

// Publishes a table made by make unless another thread already did.
template <class Table, class Make>
const Table& load_once(detail::PolicyAtomic<Table*>& slot, const Make& make) {
    if (Table* t = slot.load(__ATOMIC_ACQUIRE)) return *t;
    Table* made = make();
    Table* expected = nullptr;
    if (slot.compare_exchange_strong(expected, made, __ATOMIC_ACQ_REL)) return *made;
    delete made;
    return *expected;
}

}  // namespace

const InstanceExtensionFunctions& Instance::ext_fn() const {
    VKRC_REQUIRE_STATE("vkrc::Instance::ext_fn");
    return load_once(state_->ext_fn, [&] {
        auto get = [&](const char* name) { return global_fn().vkGetInstanceProcAddr(vk(), name); };
        auto enabled = [&](const char* e) { return extension_enabled(e); };
        return load<InstanceExtensionFunctions>(api_version(), get, [&](const Command& c) {
            return c.of_device_extension || provided(c.providers, enabled);
        });
    });
}

const DeviceExtensionFunctions& Device::ext_fn() const {
    VKRC_REQUIRE_STATE("vkrc::Device::ext_fn");
    return load_once(state_->ext_fn, [&] {
        auto get = [&](const char* name) { return physical_device().fn().vkGetDeviceProcAddr(vk(), name); };
        auto enabled = [&](const char* e) { return extension_enabled(e) || instance().extension_enabled(e); };
        auto version = std::min(instance().api_version(), physical_device().properties().apiVersion);
        return load<DeviceExtensionFunctions>(version, get,
                                              [&](const Command& c) { return provided(c.providers, enabled); });
    });
}

VKRC_END_NAMESPACE
