// The states of a device's objects that a descriptor can point to, found by
// raw handle, so that a descriptor write of a raw handle vkrc made keeps the
// object alive like a write of its wrapper (docs/design.md, "Descriptor
// references"). Registered at create/adopt and removed when the state dies;
// the cost is paid there and at descriptor writes, never when recording.
#pragma once

#include "vkrc/handle.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

// What a descriptor slot can refer to.
enum class DescribedKind : std::uint8_t { buffer, buffer_view, image_view, sampler, acceleration_structure };
inline constexpr std::size_t described_kind_count = 5;

class ObjectRegistry {
public:
    ObjectRegistry() noexcept = default;
    ObjectRegistry(const ObjectRegistry&) = delete;
    ObjectRegistry& operator=(const ObjectRegistry&) = delete;
    ~ObjectRegistry();

    // state is the object of raw handle bits (a later adoption of the same
    // handle replaces an earlier one). Throws std::bad_alloc.
    void add(DescribedKind kind, std::uint64_t bits, const RefCounted* state);
    // Forgets bits when it still names state; from the state's destructor.
    void remove(DescribedKind kind, std::uint64_t bits, const RefCounted* state) noexcept;
    // A new reference to the live state of bits; empty when vkrc made no
    // such object of this device (or its last handle is going).
    Ref<const RefCounted> find(DescribedKind kind, std::uint64_t bits) const;

private:
    struct Impl;
    Mutex mutex_;                        // makes impl_, once
    PolicyAtomic<Impl*> impl_{nullptr};  // made at the first add; striped locks inside
};

}  // namespace detail
VKRC_END_NAMESPACE
