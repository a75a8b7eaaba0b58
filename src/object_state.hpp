// The starts that the create() and adopt() functions share (not installed).
#pragma once

#include "vkrc/device.hpp"

#include "caller.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

// The state of an adopted handle: refuses an empty parent (require_handle
// with the_parent, e.g. "the Device") and a null handle (require_not_null
// with handle_name, e.g. "VkBuffer") with UsageError, then holds both (the parent in
// parent_member, by default a DeviceChildState's device) and the ownership.
// The caller fills in the rest; nothing it does after this may throw, or the
// state would destroy an owned handle that adopt() did not take.
template <class State, auto parent_member = &State::device, class Parent, class VkHandle>
Ref<State> adopted_state(const Caller& caller, const Parent& parent, const char* the_parent, VkHandle handle,
                         const char* handle_name, Ownership ownership) {
    caller.require_handle(parent, the_parent);
    caller.require_not_null(handle, handle_name);
    Ref<State> s(new State);
    (*s).*parent_member = parent;
    s->handle = handle;
    s->ownership = ownership;
    return s;
}

// The state of a new object of device, its handle made by create (a vkCreate*
// member of DeviceFunctions; call names it in an Error). The caller has
// checked device and fills in the rest.
template <class State, auto create, class CreateInfo>
Ref<State> created_state(const Device& device, const CreateInfo& ci, const char* call) {
    Ref<State> s(new State);
    s->device = device;
    check((device.fn().*create)(device.vk(), &ci, nullptr, &s->handle), call);
    return s;
}

}  // namespace detail
VKRC_END_NAMESPACE
