#include "vkrc/bindless.hpp"

#include "caller.hpp"

#include <algorithm>

VKRC_BEGIN_NAMESPACE

namespace detail {

class BindlessTableState final : public RefCounted {
public:
    static constexpr const char* type_name = "vkrc::BindlessTable";
    // Unique per table in the process (serials are not): tells indices apart.
    const std::uint64_t id = next_id.fetch_add(1, __ATOMIC_RELAXED);
    inline static Atomic<std::uint64_t> next_id{1};
    DescriptorSetLayout layout;
    DescriptorPool pool;
    DescriptorSet set;
    struct Slot {
        std::uint32_t generation = 0;
        bool live = false;
    };
    // One per BindlessKind; under mutex.
    struct Array {
        std::uint32_t capacity = 0;
        std::uint32_t fresh = 0;  // slots below it have been handed out once
        std::uint32_t live = 0;
        std::uint32_t pending = 0;  // removed, not yet back in free
        List<Slot> slots;
        List<std::uint32_t> free;  // reusable now
    };
    // Where removed slots come back: a removal is a DeferredAction (the one
    // machinery of deferred destruction: held while a command buffer that
    // may bind the set is open, then until the work submitted by then
    // completes) that puts the slot here. The action holds a reference to
    // this box, which holds nothing, so it outlives neither the table's
    // device nor forms a cycle; ready has room for every slot.
    class Returns final : public RefCounted {
    public:
        Mutex mutex;
        List<std::uint64_t> ready;  // kind << 32 | index
    };
    Array arrays[2];
    Ref<Returns> returns;
    mutable Mutex mutex;
};

}  // namespace detail

namespace {

constexpr VkDescriptorType kind_type[2] = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                           VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
constexpr const char* kind_name[2] = {"image", "buffer"};
constexpr VkDescriptorBindingFlags table_flags = VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT |
                                                 VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT |
                                                 VK_DESCRIPTOR_BINDING_UPDATE_UNUSED_WHILE_PENDING_BIT;

VkPhysicalDeviceVulkan12Properties vulkan12_properties(const PhysicalDevice& physical) {
    VkPhysicalDeviceVulkan12Properties v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
    VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &v12};
    physical.instance().fn().vkGetPhysicalDeviceProperties2(physical.vk(), &properties);
    return v12;
}

// The slots of kind a table holds, and where they are taken and given back.
detail::BindlessTableState::Array& array_of(const detail::BindlessTableState& s, BindlessKind kind) {
    return const_cast<detail::BindlessTableState&>(s).arrays[static_cast<int>(kind)];
}

// Moves the removed slots the GPU is done with to their free lists, then
// drops their objects outside the box's lock (a drop may run deferred
// actions, which take it). Under the table's lock.
void collect(const detail::BindlessTableState& s) {
    auto& returns = *s.returns;
    std::size_t before[2] = {s.arrays[0].free.size(), s.arrays[1].free.size()};
    {
        LockGuard lock(returns.mutex);
        for (const std::uint64_t bits : returns.ready) {
            auto& a = array_of(s, static_cast<BindlessKind>(bits >> 32));
            a.free.push_back(static_cast<std::uint32_t>(bits));  // reserved for every slot: no allocation
            --a.pending;
        }
        returns.ready.clear();
    }
    for (std::uint32_t k = 0; k < 2; ++k) {
        const auto& free = s.arrays[k].free;
        detail::release_descriptors(*s.set.state(), k,
                                    Span<const std::uint32_t>(free.data() + before[k], free.size() - before[k]));
    }
}

// The DeferredAction of a removal: the slot is back.
void slot_returned(detail::DeviceState&, std::uint64_t bits, void* context) noexcept {
    auto* returns = static_cast<detail::BindlessTableState::Returns*>(context);
    {
        LockGuard lock(returns->mutex);
        returns->ready.push_back(bits);  // reserved for every slot: no allocation
    }
    returns->release();
}

// A free slot of kind, or a UsageError when there is none. Under the table's lock.
std::uint32_t take_slot(const detail::BindlessTableState& s, BindlessKind kind, const detail::Caller& caller) {
    auto& a = array_of(s, kind);
    collect(s);
    if (!a.free.empty()) {
        const std::uint32_t slot = a.free.back();
        a.free.resize(a.free.size() - 1);
        return slot;
    }
    caller.require(a.capacity != 0, "the table holds no ", kind_name[static_cast<int>(kind)], " descriptors (its ",
                   kind_name[static_cast<int>(kind)], "_capacity is 0)");
    if (a.fresh < a.capacity) {
        if (a.slots.size() <= a.fresh) a.slots.resize(std::min<std::size_t>(a.capacity, a.slots.size() * 2 + 64));
        return a.fresh++;
    }
    caller.refuse("the table is full: ", a.live, " ", kind_name[static_cast<int>(kind)], " slots in use and ",
                  a.pending, " removed ones waiting for the GPU of ", a.capacity);
}

// Hands out a slot of kind, writing it with write(slot); gives it back when write throws.
template <class Write>
BindlessIndex add_slot(const detail::BindlessTableState& s, BindlessKind kind, const detail::Caller& caller,
                       const Write& write) {
    LockGuard lock(s.mutex);
    auto& a = array_of(s, kind);
    const std::uint32_t slot = take_slot(s, kind, caller);
    try {
        write(slot);
    } catch (...) {
        a.free.push_back(slot);  // cannot fail: the slot came from free, or free has room from reserve below
        throw;
    }
    a.slots[slot].live = true;
    ++a.live;
    return {slot, kind, a.slots[slot].generation, s.id};
}

}  // namespace

std::uint32_t BindlessTable::max_capacity(const Device& device, BindlessKind kind) {
    detail::Caller{"vkrc::BindlessTable::max_capacity"}.require_handle(device, "the Device");
    const auto p = vulkan12_properties(device.physical_device());
    if (kind == BindlessKind::image) {
        return std::min({p.maxDescriptorSetUpdateAfterBindSampledImages, p.maxDescriptorSetUpdateAfterBindSamplers,
                         p.maxPerStageDescriptorUpdateAfterBindSampledImages,
                         p.maxPerStageDescriptorUpdateAfterBindSamplers, p.maxPerStageUpdateAfterBindResources});
    }
    return std::min({p.maxDescriptorSetUpdateAfterBindStorageBuffers,
                     p.maxPerStageDescriptorUpdateAfterBindStorageBuffers, p.maxPerStageUpdateAfterBindResources});
}

BindlessTable BindlessTable::create(const Device& device, const BindlessTableCreateInfo& info) {
    const detail::Caller caller{"vkrc::BindlessTable::create"};
    caller.require_handle(device, "the Device");
    std::uint32_t capacity[2] = {info.image_capacity, info.buffer_capacity};
    for (int k = 0; k < 2; ++k) {
        const std::uint32_t limit = max_capacity(device, static_cast<BindlessKind>(k));
        if (capacity[k] == BindlessTableCreateInfo::device_limit) capacity[k] = limit;
        caller.require(capacity[k] <= limit, kind_name[k], "_capacity ", capacity[k],
                       " is more than the device allows (", limit, ", the update-after-bind limits)");
    }
    const auto resources = vulkan12_properties(device.physical_device()).maxPerStageUpdateAfterBindResources;
    caller.require(std::uint64_t(capacity[0]) + capacity[1] <= resources, "image_capacity ", capacity[0],
                   " and buffer_capacity ", capacity[1],
                   " together are more than maxPerStageUpdateAfterBindResources (", resources, ")");
    caller.require(capacity[0] + capacity[1] != 0, "both capacities are 0");
    DescriptorSetLayoutCreateInfo layout_info{.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT};
    DescriptorPoolCreateInfo pool_info{.flags = VK_DESCRIPTOR_POOL_CREATE_UPDATE_AFTER_BIND_BIT, .max_sets = 1};
    for (std::uint32_t k = 0; k < 2; ++k) {
        if (capacity[k] == 0) continue;
        layout_info.bindings.push_back({.binding = k,
                                        .descriptor_type = kind_type[k],
                                        .descriptor_count = capacity[k],
                                        .stage_flags = info.stage_flags,
                                        .binding_flags = table_flags});
        pool_info.pool_sizes.push_back({kind_type[k], capacity[k]});
    }
    detail::Ref<detail::BindlessTableState> s(new detail::BindlessTableState);
    s->layout = DescriptorSetLayout::create(device, layout_info);
    s->pool = DescriptorPool::create(device, pool_info);
    s->set = s->pool.allocate(s->layout);
    s->returns = detail::Ref<detail::BindlessTableState::Returns>(new detail::BindlessTableState::Returns);
    // Room for every slot, so that giving one back never allocates.
    s->returns->ready.reserve(std::size_t(capacity[0]) + capacity[1]);
    for (int k = 0; k < 2; ++k) {
        s->arrays[k].capacity = capacity[k];
        s->arrays[k].free.reserve(capacity[k]);
    }
    return BindlessTable(std::move(s));
}

BindlessIndex BindlessTable::add(const ImageView& view, const Sampler& sampler, VkImageLayout layout) const {
    VKRC_REQUIRE_STATE("vkrc::BindlessTable::add");
    const detail::Caller caller{"vkrc::BindlessTable::add"};
    caller.require_handle(view, "the ImageView");
    caller.require_handle(sampler, "the Sampler");
    return add_slot(*state_, BindlessKind::image, caller, [&](std::uint32_t slot) {
        state_->set.write_image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, view, layout, sampler, slot);
    });
}

BindlessIndex BindlessTable::add(const Buffer& buffer, VkDeviceSize offset, VkDeviceSize range) const {
    VKRC_REQUIRE_STATE("vkrc::BindlessTable::add");
    const detail::Caller caller{"vkrc::BindlessTable::add"};
    caller.require_handle(buffer, "the Buffer");
    return add_slot(*state_, BindlessKind::buffer, caller, [&](std::uint32_t slot) {
        state_->set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer, offset, range, slot);
    });
}

void BindlessTable::remove(const BindlessIndex& index) const {
    VKRC_REQUIRE_STATE("vkrc::BindlessTable::remove");
    const detail::Caller caller{"vkrc::BindlessTable::remove"};
    auto& s = *state_;
    caller.require(index.table == s.id, "the index belongs to another table");
    LockGuard lock(s.mutex);
    auto& a = array_of(s, index.kind);
    const char* kind = kind_name[static_cast<int>(index.kind)];
    caller.require(index.index < a.fresh, kind, " index ", index.index, " was never handed out by this table");
    const auto& slot = a.slots[index.index];
    caller.require(slot.generation != index.generation + 1 || slot.live, kind, " index ", index.index,
                   " was already removed");
    caller.require(slot.generation == index.generation && slot.live, kind, " index ", index.index,
                   " is stale: its slot was removed and handed out again");
    a.slots[index.index].live = false;
    ++a.slots[index.index].generation;
    --a.live;
    ++a.pending;
    // The set's serial: every command buffer that may bind the set holds the
    // slot until it closes. Its object stays in the set until then.
    s.returns->add_ref();
    s.set.pool().device().state()->destroy_after_gpu(
        {&slot_returned, std::uint64_t(index.kind) << 32 | index.index, s.returns.get()}, s.set.state()->serial());
    collect(s);
}

std::uint32_t BindlessTable::live_count(BindlessKind kind) const {
    VKRC_REQUIRE_STATE("vkrc::BindlessTable::live_count");
    LockGuard lock(state_->mutex);
    return array_of(*state_, kind).live;
}

std::size_t BindlessTable::pending_count(BindlessKind kind) const {
    VKRC_REQUIRE_STATE("vkrc::BindlessTable::pending_count");
    LockGuard lock(state_->mutex);
    collect(*state_);
    return array_of(*state_, kind).pending;
}

BindlessTable::BindlessTable() noexcept = default;
BindlessTable::~BindlessTable() = default;
BindlessTable::BindlessTable(const BindlessTable& other) noexcept = default;
BindlessTable::BindlessTable(BindlessTable&& other) noexcept = default;
BindlessTable& BindlessTable::operator=(const BindlessTable& other) noexcept = default;
BindlessTable& BindlessTable::operator=(BindlessTable&& other) noexcept = default;

const DescriptorSetLayout& BindlessTable::layout() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::BindlessTable::layout").layout;
}
const DescriptorSet& BindlessTable::set() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::BindlessTable::set").set; }
std::uint32_t BindlessTable::capacity(BindlessKind kind) const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::BindlessTable::capacity").arrays[static_cast<int>(kind)].capacity;
}

VKRC_END_NAMESPACE
