#include "vkrc/detail/object_registry.hpp"

#include <unordered_map>

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

struct ObjectRegistry::Impl {
    struct alignas(64) Stripe {  // apart in cache: threads on different stripes share no line
        mutable Mutex mutex;
        std::unordered_map<std::uint64_t, const RefCounted*> objects[described_kind_count];
    };
    Stripe stripes[stripe_count];
};

ObjectRegistry::~ObjectRegistry() { delete impl_.load(__ATOMIC_RELAXED); }

void ObjectRegistry::add(DescribedKind kind, std::uint64_t bits, const RefCounted* state) {
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
    stripe.objects[static_cast<std::size_t>(kind)][bits] = state;
}

void ObjectRegistry::remove(DescribedKind kind, std::uint64_t bits, const RefCounted* state) noexcept {
    Impl* impl = impl_.load(__ATOMIC_ACQUIRE);
    if (!impl) return;
    auto& stripe = impl->stripes[stripe_of(bits)];
    LockGuard lock(stripe.mutex);
    auto& map = stripe.objects[static_cast<std::size_t>(kind)];
    const auto it = map.find(bits);
    if (it != map.end() && it->second == state) map.erase(it);
}

Ref<const RefCounted> ObjectRegistry::find(DescribedKind kind, std::uint64_t bits) const {
    const Impl* impl = impl_.load(__ATOMIC_ACQUIRE);
    if (!impl || bits == 0) return {};
    const auto& stripe = impl->stripes[stripe_of(bits)];
    LockGuard lock(stripe.mutex);
    const auto& map = stripe.objects[static_cast<std::size_t>(kind)];
    const auto it = map.find(bits);
    // The destructor removes the entry under this lock, so the state is
    // still there; a count of zero means it is on its way out.
    if (it == map.end() || !it->second->try_add_ref()) return {};
    return Ref<const RefCounted>(it->second);
}

}  // namespace detail
VKRC_END_NAMESPACE
