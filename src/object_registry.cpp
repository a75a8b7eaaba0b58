#include "vkrc/detail/object_registry.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

namespace {
// Threads creating and dropping objects at once lock different stripes
// (one lock for all serialised them); one thread has no use for more than one.
constexpr std::size_t stripe_count = ThreadPolicy::multi_thread ? 64 : 1;

std::size_t stripe_of(std::uint64_t bits) noexcept {
    // Fibonacci hashing: handles (often aligned pointers) spread over the stripes.
    if constexpr (stripe_count == 1) return 0;
    return static_cast<std::size_t>((bits * 0x9E3779B97F4A7C15ull) >> 58);
}
static_assert(stripe_count == 1 || stripe_count == 64, "stripe_of takes the top 6 bits");
}  // namespace

// Handle bits to state, open addressing with linear probing: an add or a
// remove allocates nothing (a node-based map allocated and freed a node per
// object, half the registry's cost under vkrc::st). Bits 0 (no handle) marks
// an empty slot; removal shifts the run back, so there are no tombstones.
class HandleTable {
public:
    HandleTable() noexcept = default;
    HandleTable(const HandleTable&) = delete;
    HandleTable& operator=(const HandleTable&) = delete;
    ~HandleTable() { delete[] slots_; }

    void put(std::uint64_t bits, const RefCounted* state) {
        if ((size_ + 1) * 4 > capacity() * 3) grow();
        std::size_t i = home(bits);
        while (slots_[i].bits != 0 && slots_[i].bits != bits) i = (i + 1) & mask_;
        if (slots_[i].bits == 0) ++size_;
        slots_[i] = {bits, state};
    }
    const RefCounted* get(std::uint64_t bits) const noexcept {
        const std::size_t i = find(bits);
        return i == npos ? nullptr : slots_[i].state;
    }
    // Forgets bits when it still names state.
    void erase(std::uint64_t bits, const RefCounted* state) noexcept {
        std::size_t hole = find(bits);
        if (hole == npos || slots_[hole].state != state) return;
        for (std::size_t j = (hole + 1) & mask_; slots_[j].bits != 0; j = (j + 1) & mask_) {
            // An entry may fill the hole when the hole lies between its home and j.
            if (((j - home(slots_[j].bits)) & mask_) >= ((j - hole) & mask_)) {
                slots_[hole] = slots_[j];
                hole = j;
            }
        }
        slots_[hole] = {};
        --size_;
    }

private:
    struct Slot {
        std::uint64_t bits = 0;
        const RefCounted* state = nullptr;
    };
    static constexpr std::size_t npos = ~std::size_t{0};
    std::size_t capacity() const noexcept { return slots_ ? mask_ + 1 : 0; }
    // Fibonacci hashing on other bits than stripe_of's top six.
    std::size_t home(std::uint64_t bits) const noexcept {
        return static_cast<std::size_t>((bits * 0xD6E8FEB86659FD93ull) >> 32) & mask_;
    }
    std::size_t find(std::uint64_t bits) const noexcept {
        if (!slots_ || bits == 0) return npos;
        for (std::size_t i = home(bits);; i = (i + 1) & mask_) {
            if (slots_[i].bits == bits) return i;
            if (slots_[i].bits == 0) return npos;
        }
    }
    void grow() {
        const std::size_t old_capacity = capacity();
        const std::size_t new_capacity = old_capacity ? old_capacity * 2 : 16;
        Slot* old = slots_;
        slots_ = new Slot[new_capacity];
        mask_ = new_capacity - 1;
        size_ = 0;
        for (std::size_t i = 0; i < old_capacity; ++i) {
            if (old[i].bits != 0) put(old[i].bits, old[i].state);
        }
        delete[] old;
    }

    Slot* slots_ = nullptr;
    std::size_t mask_ = 0;
    std::size_t size_ = 0;
};

struct ObjectRegistry::Impl {
    struct alignas(64) Stripe {  // apart in cache: threads on different stripes share no line
        mutable Mutex mutex;
        HandleTable objects[described_kind_count];
    };
    Stripe stripes[stripe_count];
};

ObjectRegistry::~ObjectRegistry() { delete impl_.load(__ATOMIC_RELAXED); }

void ObjectRegistry::add(DescribedKind kind, std::uint64_t bits, const RefCounted* state) {
    if (bits == 0) return;  // no handle: nothing a descriptor can name
    Impl* impl = impl_.load(__ATOMIC_ACQUIRE);
    if (!impl) {
        LockGuard lock(mutex_);
        impl = impl_.load(__ATOMIC_RELAXED);
        if (!impl) {
            impl = new Impl;
            impl_.store(impl, __ATOMIC_RELEASE);
        }
    }
    auto& stripe = impl->stripes[stripe_of(bits)];
    LockGuard lock(stripe.mutex);
    stripe.objects[static_cast<std::size_t>(kind)].put(bits, state);
}

void ObjectRegistry::remove(DescribedKind kind, std::uint64_t bits, const RefCounted* state) noexcept {
    Impl* impl = impl_.load(__ATOMIC_ACQUIRE);
    if (!impl) return;
    auto& stripe = impl->stripes[stripe_of(bits)];
    LockGuard lock(stripe.mutex);
    stripe.objects[static_cast<std::size_t>(kind)].erase(bits, state);
}

Ref<const RefCounted> ObjectRegistry::find(DescribedKind kind, std::uint64_t bits) const {
    const Impl* impl = impl_.load(__ATOMIC_ACQUIRE);
    if (!impl || bits == 0) return {};
    const auto& stripe = impl->stripes[stripe_of(bits)];
    LockGuard lock(stripe.mutex);
    const RefCounted* state = stripe.objects[static_cast<std::size_t>(kind)].get(bits);
    // The destructor removes the entry under this lock, so the state is
    // still there; a count of zero means it is on its way out.
    if (!state || !state->try_add_ref()) return {};
    return Ref<const RefCounted>(state);
}

}  // namespace detail
VKRC_END_NAMESPACE
