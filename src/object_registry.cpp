#include "vkrc/detail/object_registry.hpp"

#include <unordered_map>

VKRC_BEGIN_NAMESPACE
namespace detail {

struct ObjectRegistry::Impl {
    std::unordered_map<std::uint64_t, const RefCounted*> objects[described_kind_count];
};

ObjectRegistry::~ObjectRegistry() { delete impl_; }

void ObjectRegistry::add(DescribedKind kind, std::uint64_t bits, const RefCounted* state) {
    LockGuard lock(mutex_);
    if (!impl_) impl_ = new Impl;
    impl_->objects[static_cast<std::size_t>(kind)][bits] = state;
}

void ObjectRegistry::remove(DescribedKind kind, std::uint64_t bits, const RefCounted* state) noexcept {
    LockGuard lock(mutex_);
    if (!impl_) return;
    auto& map = impl_->objects[static_cast<std::size_t>(kind)];
    const auto it = map.find(bits);
    if (it != map.end() && it->second == state) map.erase(it);
}

Ref<const RefCounted> ObjectRegistry::find(DescribedKind kind, std::uint64_t bits) const {
    LockGuard lock(mutex_);
    if (!impl_ || bits == 0) return {};
    const auto& map = impl_->objects[static_cast<std::size_t>(kind)];
    const auto it = map.find(bits);
    // The destructor removes the entry under this lock, so the state is
    // still there; a count of zero means it is on its way out.
    if (it == map.end() || !it->second->try_add_ref()) return {};
    return Ref<const RefCounted>(it->second);
}

}  // namespace detail
VKRC_END_NAMESPACE
