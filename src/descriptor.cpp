#include "vkrc/descriptor.hpp"

#include "vkrc/descriptor_template.hpp"

#include "caller.hpp"
#include "object_state.hpp"
#include "enum_names.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {

DescriptorSetLayoutState::~DescriptorSetLayoutState() {
    destroy_owned<&DeviceFunctions::vkDestroyDescriptorSetLayout>(*this, device);
}

DescriptorPoolState::~DescriptorPoolState() {
    // Destroying the pool frees every set still in it, pending ones included.
    destroy_owned<&DeviceFunctions::vkDestroyDescriptorPool>(*this, device);
}

namespace {
void unlink_refs(DescriptorPoolState& p, DescriptorSetState& s) noexcept {
    if (s.previous_with_refs) s.previous_with_refs->next_with_refs = s.next_with_refs;
    else if (p.sets_with_refs == &s) p.sets_with_refs = s.next_with_refs;
    if (s.next_with_refs) s.next_with_refs->previous_with_refs = s.previous_with_refs;
    s.previous_with_refs = s.next_with_refs = nullptr;
}
}  // namespace

// The references (the refs member) are released after the body, as drops:
// the objects' destruction waits for the GPU like the set's free.
DescriptorSetState::~DescriptorSetState() {
    auto& p = *pool.state();
    const bool free_set = p.can_free_sets && owns_handle();
    if (!free_set && refs.empty()) return;
    LockGuard lock(p.mutex);
    if (!refs.empty()) unlink_refs(p, *this);
    if (free_set && p.generation == generation) {
        p.pending.push(*p.device.state(), DroppedSet{handle, std::move(layout), variable_count}, serial());
    }
}

// Resets the pool's sets: each one's references are moved to released (the
// caller drops them after the pool's lock). Under the pool's lock.
void release_set_refs(DescriptorPoolState& p, List<DescriptorRefs>& released) noexcept {
    while (DescriptorSetState* set = p.sets_with_refs) {
        unlink_refs(p, *set);
        List<DescriptorRefs> refs;
        refs.swap(set->refs);
        if (released.empty()) {
            released.swap(refs);
            continue;
        }
        // Out of host memory: released here, under the lock; a release never takes it.
        try {
            released.reserve(released.size() + refs.size());
            for (auto& r : refs) released.push_back(std::move(r));
        } catch (...) {}
    }
}

}  // namespace detail

namespace {

// Immutable samplers: one per descriptor of a sampler binding, of the
// layout's device (VUID-VkDescriptorSetLayoutBinding-descriptorType-00282).
void check_immutable_samplers(const detail::Caller& caller, const Device& device, const DescriptorSetLayoutBinding& b) {
    if (b.immutable_samplers.empty()) return;
    caller.require(b.descriptor_type == VK_DESCRIPTOR_TYPE_SAMPLER ||
                       b.descriptor_type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                   "binding ", b.binding, " has immutable samplers but type ", b.descriptor_type);
    caller.require(b.immutable_samplers.size() == b.descriptor_count, "binding ", b.binding, " has ",
                   b.immutable_samplers.size(), " immutable samplers for ", b.descriptor_count, " descriptors");
    for (const auto& sampler : b.immutable_samplers) {
        caller.require(sampler && sampler.device() == device, "binding ", b.binding,
                       ": an immutable sampler is empty or belongs to another device");
    }
}

// The cheap checks of a layout's bindings that give a clearer message than
// the validation layer: immutable samplers, and binding flags
// (VUID-VkDescriptorSetLayoutCreateInfo-flags-03000,
// VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-pBindingFlags-03004).
void check_bindings(const detail::Caller& caller, const Device& device, const DescriptorSetLayoutCreateInfo& info) {
    std::uint32_t highest = 0;
    for (const auto& b : info.bindings) highest = std::max(highest, b.binding);
    for (const auto& b : info.bindings) {
        check_immutable_samplers(caller, device, b);
        caller.require(!(b.binding_flags & VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT) ||
                           (info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT),
                       "binding ", b.binding,
                       " is UPDATE_AFTER_BIND but the layout lacks "
                       "VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT");
        caller.require(!(b.binding_flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) || b.binding == highest,
                       "binding ", b.binding, " has VARIABLE_DESCRIPTOR_COUNT but is not the highest binding (",
                       highest, ")");
    }
}

// The bindings a layout checks writes against, its variable-count binding,
// and where each binding's descriptors sit in a set's references (an inline
// uniform block counts bytes and references nothing).
void keep_bindings(detail::DescriptorSetLayoutState& s, const List<DescriptorSetLayoutBinding>& bindings) {
    s.bindings = bindings;
    s.first_slot.resize(bindings.size());
    std::uint32_t next = 0;
    for (std::size_t i = 0; i < bindings.size(); ++i) {
        const auto& b = bindings[i];
        if (b.binding_flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) {
            s.has_variable_binding = true;
            s.variable_binding = b.binding;
            continue;
        }
        s.first_slot[i] = next;
        if (b.descriptor_type != VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK) next += b.descriptor_count;
    }
    s.fixed_slots = next;
    for (std::size_t i = 0; i < bindings.size(); ++i) {
        if (s.has_variable_binding && bindings[i].binding == s.variable_binding) s.first_slot[i] = next;
    }
}

}  // namespace

DescriptorSetLayout DescriptorSetLayout::create(const Device& device, const DescriptorSetLayoutCreateInfo& info) {
    const detail::Caller caller{"vkrc::DescriptorSetLayout::create"};
    caller.require_handle(device, "the Device");
    caller.require(!(info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR) ||
                       device.extension_enabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME),
                   "PUSH_DESCRIPTOR_BIT_KHR needs VK_KHR_push_descriptor enabled on the device");
    check_bindings(caller, device, info);
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    std::vector<VkDescriptorBindingFlags> flags;
    // Every binding's immutable samplers, one after another; reserved whole
    // so that the pointers into it stay valid.
    std::size_t sampler_count = 0;
    for (const auto& b : info.bindings) sampler_count += b.immutable_samplers.size();
    std::vector<VkSampler> samplers;
    samplers.reserve(sampler_count);
    bindings.reserve(info.bindings.size());
    flags.reserve(info.bindings.size());
    bool any_flags = false;
    for (const auto& b : info.bindings) {
        const VkSampler* immutable = b.immutable_samplers.empty() ? nullptr : samplers.data() + samplers.size();
        for (const auto& sampler : b.immutable_samplers) samplers.push_back(sampler.vk());
        bindings.push_back({b.binding, b.descriptor_type, b.descriptor_count, b.stage_flags, immutable});
        flags.push_back(b.binding_flags);
        any_flags = any_flags || b.binding_flags != 0;
    }
    VkDescriptorSetLayoutBindingFlagsCreateInfo flags_info{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO, info.next};
    flags_info.bindingCount = static_cast<std::uint32_t>(flags.size());
    flags_info.pBindingFlags = flags.data();
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    // The flags struct only when some binding has flags: older drivers need not know it.
    ci.pNext = any_flags ? &flags_info : info.next;
    ci.flags = info.flags;
    ci.bindingCount = static_cast<std::uint32_t>(bindings.size());
    ci.pBindings = bindings.data();
    auto s = detail::created_state<detail::DescriptorSetLayoutState, &DeviceFunctions::vkCreateDescriptorSetLayout>(
        device, ci, "vkCreateDescriptorSetLayout");
    keep_bindings(*s, info.bindings);
    return DescriptorSetLayout(std::move(s));
}

DescriptorSetLayout DescriptorSetLayout::adopt(const Device& device, VkDescriptorSetLayout layout,
                                               const DescriptorSetLayoutCreateInfo& info, Ownership ownership) {
    const detail::Caller caller{"vkrc::DescriptorSetLayout::adopt"};
    caller.require_handle(device, "the Device");
    caller.require_not_null(layout, "VkDescriptorSetLayout");
    check_bindings(caller, device, info);
    // The bindings before the handle: a failed copy must not destroy the adopted layout.
    detail::Ref<detail::DescriptorSetLayoutState> s(new detail::DescriptorSetLayoutState);
    keep_bindings(*s, info.bindings);
    s->device = device;
    s->handle = layout;
    s->ownership = ownership;
    return DescriptorSetLayout(std::move(s));
}

DescriptorPool DescriptorPool::adopt(const Device& device, VkDescriptorPool pool, VkDescriptorPoolCreateFlags flags,
                                     Ownership ownership) {
    auto s = detail::adopted_state<detail::DescriptorPoolState>(detail::Caller{"vkrc::DescriptorPool::adopt"}, device,
                                                                "the Device", pool, "VkDescriptorPool", ownership);
    s->can_free_sets = (flags & VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT) != 0;
    return DescriptorPool(std::move(s));
}

DescriptorPool DescriptorPool::create(const Device& device, const DescriptorPoolCreateInfo& info) {
    const detail::Caller caller{"vkrc::DescriptorPool::create"};
    caller.require_handle(device, "the Device");
    caller.require(info.max_sets != 0, "max_sets is 0");
    caller.require(!info.pool_sizes.empty(), "pool_sizes is empty");
    VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, info.next};
    ci.flags = info.flags;
    ci.maxSets = info.max_sets;
    ci.poolSizeCount = static_cast<std::uint32_t>(info.pool_sizes.size());
    ci.pPoolSizes = info.pool_sizes.data();
    auto s = detail::created_state<detail::DescriptorPoolState, &DeviceFunctions::vkCreateDescriptorPool>(
        device, ci, "vkCreateDescriptorPool");
    s->can_free_sets = (info.flags & VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT) != 0;
    return DescriptorPool(std::move(s));
}

namespace {

// The largest count a set of layout may ask for its variable binding; throws
// when the layout has none and a count was given.
void check_variable_count(const detail::Caller& caller, const detail::DescriptorSetLayoutState& layout,
                          std::uint32_t count) {
    if (!layout.has_variable_binding) {
        caller.require(count == 0, "variable_descriptor_count is ", count,
                       " but the layout has no VARIABLE_DESCRIPTOR_COUNT binding");
        return;
    }
    for (const auto& b : layout.bindings) {
        caller.require(b.binding != layout.variable_binding || count <= b.descriptor_count,
                       "variable_descriptor_count ", count, " is more than binding ", b.binding, "'s descriptor_count ",
                       b.descriptor_count);
    }
}

}  // namespace

namespace {

// Under the pool's lock: gives s a reusable set of its layout and count,
// the most recently dropped first, with that set's layout reference.
bool reuse_dropped_set(detail::DescriptorPoolState& p, detail::DescriptorSetState& s,
                       const DescriptorSetLayout& layout) noexcept {
    for (std::size_t i = p.reusable.size(); i-- > 0;) {
        detail::DroppedSet& dropped = p.reusable[i];
        if (dropped.layout != layout || dropped.variable_count != s.variable_count) continue;
        s.handle = dropped.handle;
        s.layout = std::move(dropped.layout);
        if (i + 1 != p.reusable.size()) dropped = std::move(p.reusable.back());
        p.reusable.pop_back();
        return true;
    }
    return false;
}

// Under the pool's lock: frees the reusable sets, all of them or only those
// whose layout nothing else holds (no allocate can ask for them again). Each
// is judged once: under vkrc::mt another holder of a layout may drop it
// meanwhile. Should the free fail, the sets stay allocated until the pool's
// reset or destruction.
void free_reusable(detail::DescriptorPoolState& p, bool all) {
    List<VkDescriptorSet> freed;
    freed.reserve(p.reusable.size());  // the only allocation, before anything changes
    std::size_t kept = 0;
    for (std::size_t i = 0; i < p.reusable.size(); ++i) {
        if (all || p.reusable[i].layout.use_count() == 1) {
            freed.push_back(p.reusable[i].handle);
            continue;
        }
        if (kept != i) p.reusable[kept] = std::move(p.reusable[i]);
        ++kept;
    }
    p.reusable.resize(kept);
    if (freed.empty()) return;
    check(p.device.fn().vkFreeDescriptorSets(p.device.vk(), p.handle, static_cast<std::uint32_t>(freed.size()),
                                             freed.data()),
          "vkFreeDescriptorSets");
}

// Under the pool's lock: a new set from the driver. When the pool is out of
// memory, the reusable sets are freed and the allocation tried once more.
VkDescriptorSet allocate_set(detail::DescriptorPoolState& p, const DescriptorSetLayout& layout,
                             std::uint32_t variable_descriptor_count) {
    free_reusable(p, false);
    VkDescriptorSetLayout raw_layout = layout.vk();
    VkDescriptorSetVariableDescriptorCountAllocateInfo variable{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO};
    variable.descriptorSetCount = 1;
    variable.pDescriptorCounts = &variable_descriptor_count;
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    if (layout.state()->has_variable_binding) ai.pNext = &variable;
    ai.descriptorPool = p.handle;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &raw_layout;
    const auto& fn = p.device.fn();
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkResult r = fn.vkAllocateDescriptorSets(p.device.vk(), &ai, &set);
    if ((r == VK_ERROR_OUT_OF_POOL_MEMORY || r == VK_ERROR_FRAGMENTED_POOL) && !p.reusable.empty()) {
        free_reusable(p, true);
        r = fn.vkAllocateDescriptorSets(p.device.vk(), &ai, &set);
    }
    check(r, "vkAllocateDescriptorSets");
    return set;
}

}  // namespace

DescriptorSet DescriptorPool::allocate(const DescriptorSetLayout& layout,
                                       std::uint32_t variable_descriptor_count) const {
    const detail::Caller caller{"vkrc::DescriptorPool::allocate"};
    caller.require_handle(layout, "the DescriptorSetLayout");
    caller.require(layout.device() == device(), "the DescriptorSetLayout belongs to another device");
    check_variable_count(caller, *layout.state(), variable_descriptor_count);
    auto& p = *state_;
    detail::Ref<detail::DescriptorSetState> s(new detail::DescriptorSetState);
    s->pool = *this;
    s->variable_count = variable_descriptor_count;
    LockGuard lock(p.mutex);
    if (!p.pending.empty()) p.pending.take_ready(*p.device.state(), p.reusable);
    if (!reuse_dropped_set(p, *s, layout)) {
        s->handle = allocate_set(p, layout, variable_descriptor_count);
        s->layout = layout;
    }
    s->generation = p.generation;
    return DescriptorSet(std::move(s));
}

DescriptorSet DescriptorSet::adopt(const DescriptorPool& pool, const DescriptorSetLayout& layout, VkDescriptorSet set,
                                   Ownership ownership, std::uint32_t variable_descriptor_count) {
    const detail::Caller caller{"vkrc::DescriptorSet::adopt"};
    caller.require_handle(pool, "the DescriptorPool");
    caller.require_handle(layout, "the DescriptorSetLayout");
    caller.require_not_null(set, "VkDescriptorSet");
    caller.require(layout.device() == pool.device(), "the DescriptorSetLayout belongs to another device");
    check_variable_count(caller, *layout.state(), variable_descriptor_count);
    detail::Ref<detail::DescriptorSetState> s(new detail::DescriptorSetState);
    s->pool = pool;
    s->layout = layout;
    s->handle = set;
    s->ownership = ownership;
    s->variable_count = variable_descriptor_count;
    LockGuard lock(pool.state()->mutex);
    s->generation = pool.state()->generation;
    return DescriptorSet(std::move(s));
}

void DescriptorPool::reset_sets() const {
    auto& p = *state_;
    List<detail::DescriptorRefs> released;  // dropped after the lock, as drops
    LockGuard lock(p.mutex);
    check(p.device.fn().vkResetDescriptorPool(p.device.vk(), p.handle, 0), "vkResetDescriptorPool");
    p.pending.clear();
    p.reusable.clear();
    ++p.generation;
    detail::release_set_refs(p, released);
}

std::size_t DescriptorPool::pending_free_count() const {
    LockGuard lock(state_->mutex);
    return state_->pending.size();
}

namespace {

bool is_buffer_type(VkDescriptorType t) {
    return t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || t == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER ||
           t == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC || t == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC;
}
bool is_image_type(VkDescriptorType t) {
    return t == VK_DESCRIPTOR_TYPE_SAMPLER || t == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER ||
           t == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE || t == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE ||
           t == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT;
}
bool is_texel_type(VkDescriptorType t) {
    return t == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER || t == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
}

// The layout binding a write targets must exist, have the write's type and
// hold the count elements from array_element on (VUID-VkWriteDescriptorSet-dstBinding-00315,
// -descriptorType-00319, -dstArrayElement-00321); vkrc does not let a write
// run on into the next binding. The variable binding holds the set's count.
// Returns the binding's index in the layout.
std::size_t check_write(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                        std::uint32_t array_element, std::size_t count, const detail::Caller& caller) {
    const auto& layout = *s.layout.state();
    for (std::size_t i = 0; i < layout.bindings.size(); ++i) {
        const auto& b = layout.bindings[i];
        if (b.binding != binding) continue;
        caller.require(b.descriptor_type == type, "binding ", binding, " has descriptor type ", b.descriptor_type,
                       " in the set layout, the write has type ", type);
        const bool variable = layout.has_variable_binding && layout.variable_binding == binding;
        const std::uint32_t size = variable ? s.variable_count : b.descriptor_count;
        if (array_element >= size || count > size - array_element) {
            if (count == 1)
                caller.refuse("array element ", array_element, " is past binding ", binding, "'s ", size,
                              " descriptors");
            caller.refuse("array elements ", array_element, " to ", array_element + count - 1, " are past binding ",
                          binding, "'s ", size, " descriptors");
        }
        return i;
    }
    caller.refuse("the set layout has no binding ", binding);
}

// One descriptor's new references and where they go in the set's refs.
struct SlotWrite {
    std::uint32_t slot = 0;
    detail::DescriptorRefs refs;
};

// The references of one descriptor whose info (a VkDescriptorBufferInfo,
// VkDescriptorImageInfo, VkBufferView or VkAccelerationStructureKHR, by
// type) is at info: the states vkrc made for its raw handles on this device.
detail::DescriptorRefs refs_of(const detail::DeviceState& d, VkDescriptorType type, const void* info,
                               bool immutable_sampler) {
    using detail::DescribedKind;
    detail::DescriptorRefs r;
    if (is_buffer_type(type)) {
        VkDescriptorBufferInfo b;
        std::memcpy(&b, info, sizeof b);
        r.object = d.objects.find(DescribedKind::buffer, detail::handle_bits(b.buffer));
    } else if (is_image_type(type)) {
        VkDescriptorImageInfo image;
        std::memcpy(&image, info, sizeof image);
        if (type != VK_DESCRIPTOR_TYPE_SAMPLER)
            r.object = d.objects.find(DescribedKind::image_view, detail::handle_bits(image.imageView));
        const bool has_sampler =
            type == VK_DESCRIPTOR_TYPE_SAMPLER || type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        if (has_sampler && !immutable_sampler)
            r.sampler = d.objects.find(DescribedKind::sampler, detail::handle_bits(image.sampler));
    } else if (is_texel_type(type)) {
        VkBufferView view;
        std::memcpy(&view, info, sizeof view);
        r.object = d.objects.find(DescribedKind::buffer_view, detail::handle_bits(view));
    } else if (type == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
        VkAccelerationStructureKHR as;
        std::memcpy(&as, info, sizeof as);
        r.object = d.objects.find(DescribedKind::acceleration_structure, detail::handle_bits(as));
    }
    return r;
}

std::size_t info_size(VkDescriptorType type) noexcept {
    if (is_buffer_type(type)) return sizeof(VkDescriptorBufferInfo);
    if (is_image_type(type)) return sizeof(VkDescriptorImageInfo);
    if (type == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) return sizeof(VkAccelerationStructureKHR);
    return sizeof(VkBufferView);
}

// The set's references, made at its first write, which puts the set on its
// pool's list (reset_sets releases them). Under the pool's lock.
void ensure_refs(detail::DescriptorPoolState& p, detail::DescriptorSetState& s) {
    if (!s.refs.empty()) return;
    const auto& layout = *s.layout.state();
    const std::size_t count = layout.fixed_slots + (layout.has_variable_binding ? s.variable_count : 0);
    if (count == 0) return;
    s.refs.resize(count);
    s.next_with_refs = p.sets_with_refs;
    if (p.sets_with_refs) p.sets_with_refs->previous_with_refs = &s;
    p.sets_with_refs = &s;
}

// Runs update (the Vulkan call), then swaps the writes' references into the
// set, all under the pool's lock (reset_sets and drops on other threads see
// the set's references whole). The writes come back holding the references
// they replaced, which their owner drops after the lock: a drop, so the old
// objects' destruction waits for the GPU.
template <class Update>
void update_keeping(const detail::DescriptorSetState& s, SlotWrite* writes, std::size_t count, const Update& update,
                    const detail::Caller& caller) {
    auto& set = const_cast<detail::DescriptorSetState&>(s);
    auto& p = *s.pool.state();
    LockGuard lock(p.mutex);
    caller.require(s.generation == p.generation, "the set was invalidated by its pool's reset_sets()");
    if (count != 0) ensure_refs(p, set);
    update();
    for (std::size_t i = 0; i < count; ++i) {
        auto& kept = set.refs[writes[i].slot];
        kept.object.swap(writes[i].refs.object);
        kept.sampler.swap(writes[i].refs.sampler);
    }
}

// One vkUpdateDescriptorSets of count descriptors of binding whose infos
// (of the type's kind) start at infos, keeping what they point to. set is the
// written DescriptorSet's state, null for an empty handle.
void write_infos(const detail::DescriptorSetState* set, std::uint32_t binding, VkDescriptorType type,
                 std::uint32_t array_element, std::size_t count, const void* infos, const detail::Caller& caller) {
    if (!set) detail::throw_empty_handle(caller.name());
    const auto& s = *set;
    const std::size_t b = check_write(s, binding, type, array_element, count, caller);
    if (count == 0) return;
    const auto& layout = *s.layout.state();
    const bool immutable = !layout.bindings[b].immutable_samplers.empty();
    const std::uint32_t first = layout.first_slot[b] + array_element;
    const auto& d = *s.pool.device().state();
    SlotWrite one;
    List<SlotWrite> many;
    if (count > 1) many.resize(count);
    SlotWrite* writes = count > 1 ? many.data() : &one;
    const std::size_t stride = info_size(type);
    for (std::size_t i = 0; i < count; ++i) {
        writes[i].slot = first + static_cast<std::uint32_t>(i);
        writes[i].refs = refs_of(d, type, static_cast<const char*>(infos) + i * stride, immutable);
    }
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = s.handle;
    w.dstBinding = binding;
    w.dstArrayElement = array_element;
    w.descriptorCount = static_cast<std::uint32_t>(count);
    w.descriptorType = type;
    // Acceleration structures go in a struct of their own, chained.
    VkWriteDescriptorSetAccelerationStructureKHR structures{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    if (is_buffer_type(type)) w.pBufferInfo = static_cast<const VkDescriptorBufferInfo*>(infos);
    else if (is_image_type(type)) w.pImageInfo = static_cast<const VkDescriptorImageInfo*>(infos);
    else if (type != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR)
        w.pTexelBufferView = static_cast<const VkBufferView*>(infos);
    else {
        structures.accelerationStructureCount = w.descriptorCount;
        structures.pAccelerationStructures = static_cast<const VkAccelerationStructureKHR*>(infos);
        w.pNext = &structures;
    }
    update_keeping(
        s, writes, count, [&] { d.fn.vkUpdateDescriptorSets(d.device, 1, &w, 0, nullptr); }, caller);
}

void write_buffer_infos(const detail::DescriptorSetState* s, std::uint32_t binding, VkDescriptorType type,
                        Span<const VkDescriptorBufferInfo> infos, std::uint32_t array_element,
                        const detail::Caller& caller) {
    caller.require(is_buffer_type(type), "descriptor type ", type, " is not a buffer type");
    write_infos(s, binding, type, array_element, infos.size(), infos.data(), caller);
}

void write_image_infos(const detail::DescriptorSetState* s, std::uint32_t binding, VkDescriptorType type,
                       Span<const VkDescriptorImageInfo> infos, std::uint32_t array_element,
                       const detail::Caller& caller) {
    caller.require(is_image_type(type), "descriptor type ", type, " is not an image or sampler type");
    write_infos(s, binding, type, array_element, infos.size(), infos.data(), caller);
}

void write_texel_views(const detail::DescriptorSetState* s, std::uint32_t binding, VkDescriptorType type,
                       Span<const VkBufferView> views, std::uint32_t array_element, const detail::Caller& caller) {
    caller.require(is_texel_type(type), "descriptor type ", type, " is not a texel buffer type");
    write_infos(s, binding, type, array_element, views.size(), views.data(), caller);
}

void write_structures(const detail::DescriptorSetState* s, std::uint32_t binding,
                      Span<const VkAccelerationStructureKHR> structures, std::uint32_t array_element,
                      const detail::Caller& caller) {
    write_infos(s, binding, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, array_element, structures.size(),
                structures.data(), caller);
}

}  // namespace

void DescriptorSet::write_acceleration_structure(std::uint32_t binding, const AccelerationStructure& structure,
                                                 std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_acceleration_structure"};
    caller.require_handle(structure, "the AccelerationStructure");
    caller.require(structure.device() == pool().device(), "the acceleration structure belongs to another device");
    caller.require(structure.type() != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                   "the acceleration structure is a bottom level; shaders trace top levels "
                   "(VUID-VkWriteDescriptorSetAccelerationStructureKHR-pAccelerationStructures-03579)");
    const VkAccelerationStructureKHR raw = structure.vk();
    write_structures(state_.get(), binding, Span(&raw, 1), array_element, caller);
}

void DescriptorSet::write_acceleration_structures(std::uint32_t binding,
                                                  Span<const VkAccelerationStructureKHR> structures,
                                                  std::uint32_t array_element) const {
    write_structures(state_.get(), binding, structures, array_element,
                     detail::Caller{"vkrc::DescriptorSet::write_acceleration_structures"});
}

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, const Buffer& buffer,
                                 VkDeviceSize offset, VkDeviceSize range, std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_buffer"};
    caller.require_handle(buffer, "the Buffer");
    caller.require(buffer.device() == pool().device(), "the buffer belongs to another device");
    const VkBufferUsageFlags needs =
        type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC
            ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
            : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    caller.require(!is_buffer_type(type) || (buffer.usage() & needs), "the buffer lacks the usage descriptor type ",
                   type, " needs (VUID-VkWriteDescriptorSet-descriptorType-00330/00331)");
    write_buffer(binding, type, buffer.vk(), offset, range, array_element);
}

void DescriptorSet::write_image(std::uint32_t binding, VkDescriptorType type, const ImageView& view,
                                VkImageLayout layout, const Sampler& sampler, std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_image"};
    const auto& device = pool().device();
    caller.require(!view || view.image().device() == device, "the image view belongs to another device");
    caller.require(!sampler || sampler.device() == device, "the sampler belongs to another device");
    write_image(binding, type, view ? view.vk() : VK_NULL_HANDLE, layout, sampler ? sampler.vk() : VK_NULL_HANDLE,
                array_element);
}

void DescriptorSet::write_buffer_view(std::uint32_t binding, VkDescriptorType type, const BufferView& view,
                                      std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_buffer_view"};
    caller.require_handle(view, "the BufferView");
    caller.require(view.buffer().device() == pool().device(), "the buffer view belongs to another device");
    const VkBufferView raw = view.vk();
    write_texel_views(state_.get(), binding, type, Span(&raw, 1), array_element, caller);
}

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, VkBuffer buffer, VkDeviceSize offset,
                                 VkDeviceSize range, std::uint32_t array_element) const {
    const VkDescriptorBufferInfo info{buffer, offset, range};
    write_buffer_infos(state_.get(), binding, type, Span(&info, 1), array_element,
                       detail::Caller{"vkrc::DescriptorSet::write_buffer"});
}

void DescriptorSet::write_image(std::uint32_t binding, VkDescriptorType type, VkImageView view, VkImageLayout layout,
                                VkSampler sampler, std::uint32_t array_element) const {
    const VkDescriptorImageInfo info{sampler, view, layout};
    write_image_infos(state_.get(), binding, type, Span(&info, 1), array_element,
                      detail::Caller{"vkrc::DescriptorSet::write_image"});
}

void DescriptorSet::write_buffers(std::uint32_t binding, VkDescriptorType type,
                                  Span<const VkDescriptorBufferInfo> infos, std::uint32_t array_element) const {
    write_buffer_infos(state_.get(), binding, type, infos, array_element,
                       detail::Caller{"vkrc::DescriptorSet::write_buffers"});
}

void DescriptorSet::write_images(std::uint32_t binding, VkDescriptorType type, Span<const VkDescriptorImageInfo> infos,
                                 std::uint32_t array_element) const {
    write_image_infos(state_.get(), binding, type, infos, array_element,
                      detail::Caller{"vkrc::DescriptorSet::write_images"});
}

void DescriptorSet::write_buffer_views(std::uint32_t binding, VkDescriptorType type, Span<const VkBufferView> views,
                                       std::uint32_t array_element) const {
    write_texel_views(state_.get(), binding, type, views, array_element,
                      detail::Caller{"vkrc::DescriptorSet::write_buffer_views"});
}

namespace {

// The references an update with template t writes into s from data: each
// entry's descriptors, which must lie in its binding.
List<SlotWrite> template_writes(const detail::DescriptorSetState& s, const detail::DescriptorUpdateTemplateState& t,
                                const void* data, const detail::Caller& caller) {
    const auto& layout = *s.layout.state();
    const auto& d = *s.pool.device().state();
    std::size_t count = 0;
    for (const auto& e : t.entries) {
        if (e.descriptorType != VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK) count += e.descriptorCount;
    }
    List<SlotWrite> writes;
    writes.reserve(count);
    for (const auto& e : t.entries) {
        const std::size_t b =
            check_write(s, e.dstBinding, e.descriptorType, e.dstArrayElement, e.descriptorCount, caller);
        if (e.descriptorType == VK_DESCRIPTOR_TYPE_INLINE_UNIFORM_BLOCK) continue;
        const bool immutable = !layout.bindings[b].immutable_samplers.empty();
        for (std::uint32_t i = 0; i < e.descriptorCount; ++i) {
            const void* info = static_cast<const char*>(data) + e.offset + i * e.stride;
            writes.push_back(
                {layout.first_slot[b] + e.dstArrayElement + i, refs_of(d, e.descriptorType, info, immutable)});
        }
    }
    return writes;
}

}  // namespace

void DescriptorSet::update_with_template(const DescriptorUpdateTemplate& update_template, const void* data) const {
    VKRC_REQUIRE_STATE("vkrc::DescriptorSet::update_with_template");
    const detail::Caller caller{"vkrc::DescriptorSet::update_with_template"};
    caller.require_handle(update_template, "the DescriptorUpdateTemplate");
    caller.require(update_template.template_type() == VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET,
                   "the template is for push descriptors");
    // VUID-vkUpdateDescriptorSetWithTemplate-descriptorUpdateTemplate-00387 asks
    // for a compatible layout; vkrc asks for the same one.
    caller.require(update_template.descriptor_set_layout() == state_->layout,
                   "the template was made for another descriptor set layout");
    caller.require(data != nullptr || update_template.state()->entries.empty(), "data is null");
    auto writes = template_writes(*state_, *update_template.state(), data, caller);
    const auto& d = *state_->pool.device().state();
    update_keeping(
        *state_, writes.data(), writes.size(),
        [&] { d.fn.vkUpdateDescriptorSetWithTemplate(d.device, state_->handle, update_template.vk(), data); }, caller);
}

void detail::release_descriptors(const DescriptorSetState& s, std::uint32_t binding,
                                 Span<const std::uint32_t> elements) noexcept {
    auto& set = const_cast<DescriptorSetState&>(s);
    const auto& layout = *s.layout.state();
    LockGuard lock(s.pool.state()->mutex);
    if (set.refs.empty()) return;
    for (std::size_t b = 0; b < layout.bindings.size(); ++b) {
        if (layout.bindings[b].binding != binding) continue;
        // Released under the lock: a release never takes a descriptor pool's lock.
        for (const std::uint32_t e : elements) set.refs[layout.first_slot[b] + e] = DescriptorRefs{};
    }
}

VKRC_END_NAMESPACE
