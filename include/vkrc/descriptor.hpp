// Descriptor set layouts, descriptor pools and the sets they own.
#pragma once

#include "vkrc/acceleration_structure.hpp"
#include "vkrc/detail/pool_free_list.hpp"
#include "vkrc/resource.hpp"

#include "vkrc/detail/span.hpp"
#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class DescriptorSetLayoutState;
class DescriptorPoolState;
class DescriptorSetState;
}  // namespace detail

// Mirrors VkDescriptorSetLayoutBinding, plus the binding's entry of
// VkDescriptorSetLayoutBindingFlagsCreateInfo. Every member is optional
// (defaults: binding 0, one uniform buffer, all stages, no flags, no immutable samplers).
struct DescriptorSetLayoutBinding {
    std::uint32_t binding = 0;
    VkDescriptorType descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    // With VARIABLE_DESCRIPTOR_COUNT: the most a set may get (DescriptorPool::allocate picks).
    std::uint32_t descriptor_count = 1;
    VkShaderStageFlags stage_flags = VK_SHADER_STAGE_ALL;
    // Descriptor indexing: PARTIALLY_BOUND, UPDATE_AFTER_BIND (the layout then
    // needs UPDATE_AFTER_BIND_POOL), UPDATE_UNUSED_WHILE_PENDING,
    // VARIABLE_DESCRIPTOR_COUNT (the highest binding only). Each needs its
    // descriptorBinding* feature enabled on the device (vulkan12_features).
    VkDescriptorBindingFlags binding_flags = 0;
    // For SAMPLER and COMBINED_IMAGE_SAMPLER bindings: empty, or one sampler
    // per descriptor (descriptor_count of them), fixed in the layout, which
    // keeps them alive. Samplers with a Y'CbCr conversion must be given here.
    List<Sampler> immutable_samplers{};
};

// Mirrors VkDescriptorSetLayoutCreateInfo.
struct DescriptorSetLayoutCreateInfo {
    // Optional (default none). UPDATE_AFTER_BIND_POOL for update-after-bind
    // bindings; PUSH_DESCRIPTOR_BIT_KHR for CommandBuffer::push_descriptor_set.
    VkDescriptorSetLayoutCreateFlags flags = 0;
    // Optional (empty: an empty layout). Copied: the layout checks writes against it.
    List<DescriptorSetLayoutBinding> bindings{};
    // Optional pNext chain (vkrc chains the binding flags itself). Read during create().
    const void* next = nullptr;
};

class DescriptorSetLayout : public DeviceChild<detail::DescriptorSetLayoutState, VkDescriptorSetLayout> {
public:
    static DescriptorSetLayout create(const Device& device, const DescriptorSetLayoutCreateInfo& info);
    // A layout made by other code; info describes it as its creation did (the
    // bindings are copied to check writes; next is ignored). Owned: vkrc
    // destroys it after the GPU is done; borrowed: its maker does, after
    // every vkrc handle to it has gone.
    static DescriptorSetLayout adopt(const Device& device, VkDescriptorSetLayout layout,
                                     const DescriptorSetLayoutCreateInfo& info, Ownership ownership);

private:
    using DeviceChild::DeviceChild;
};

// Mirrors VkDescriptorPoolCreateInfo. With VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT
// a dropped set returns to the pool once the GPU is done with it (see
// DescriptorPool::allocate); without it sets are reclaimed only by
// reset_sets() or the pool's destruction.
struct DescriptorPoolCreateInfo {
    // Optional (default: sets freed one by one, see above). Flags you set
    // replace the default, as Vulkan's field is replaced (a pool without
    // FREE_DESCRIPTOR_SET, reclaimed only by reset_sets(), is a valid choice
    // vkrc must not override): for UPDATE_AFTER_BIND_POOL layouts write
    // FREE_DESCRIPTOR_SET_BIT | UPDATE_AFTER_BIND_BIT to keep freeing sets.
    VkDescriptorPoolCreateFlags flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    // Required, non-zero.
    std::uint32_t max_sets = 0;
    // Required, not empty. Read during create().
    List<VkDescriptorPoolSize> pool_sizes{};
    // Optional pNext chain. Read during create().
    const void* next = nullptr;
};

class DescriptorSet;
class DescriptorUpdateTemplate;

// Externally synchronised like VkDescriptorPool: allocate() and reset_sets() take
// the pool's lock under the multi-thread policy.
class DescriptorPool : public DeviceChild<detail::DescriptorPoolState, VkDescriptorPool> {
public:
    static DescriptorPool create(const Device& device, const DescriptorPoolCreateInfo& info);
    // A pool made by other code with these creation flags (FREE_DESCRIPTOR_SET
    // decides whether dropped sets are freed). Ownership as for DescriptorSetLayout::adopt.
    static DescriptorPool adopt(const Device& device, VkDescriptorPool pool, VkDescriptorPoolCreateFlags flags,
                                Ownership ownership);

    // variable_descriptor_count: for a layout whose last binding has
    // VARIABLE_DESCRIPTOR_COUNT, how many descriptors the set's binding gets
    // (at most its descriptor_count; VkDescriptorSetVariableDescriptorCountAllocateInfo).
    // Must be 0 for other layouts (UsageError otherwise).
    // With FREE_DESCRIPTOR_SET, a set dropped earlier with the same layout and
    // count whose GPU work is done is handed out again, with no driver call
    // (its descriptors are as last written, as a new set's are undefined).
    // Dropped sets are freed when vkAllocateDescriptorSets finds the pool out
    // of memory (then allocation is tried once more), before an allocation
    // that reuses none when nothing else holds their layout, and by
    // reset_sets(); a dropped set keeps its layout alive until then.
    DescriptorSet allocate(const DescriptorSetLayout& layout, std::uint32_t variable_descriptor_count = 0) const;
    // vkResetDescriptorPool: every set allocated from it becomes invalid (its
    // handle may still be dropped). The caller ensures the GPU no longer uses them.
    void reset_sets() const;
    // Sets dropped while the GPU may use them, not yet reusable or freed.
    std::size_t pending_free_count() const;

private:
    using DeviceChild::DeviceChild;
};

// A descriptor set; keeps its pool alive.
class DescriptorSet : public VulkanObject<detail::DescriptorSetState, VkDescriptorSet> {
public:
    // A set allocated by other code from pool with layout (variable_descriptor_count
    // as it was allocated with). Owned: dropping it frees it as an allocated
    // set is freed (with FREE_DESCRIPTOR_SET, once the GPU is done); borrowed:
    // vkrc never frees it. It is invalid after the pool's reset_sets().
    static DescriptorSet adopt(const DescriptorPool& pool, const DescriptorSetLayout& layout, VkDescriptorSet set,
                               Ownership ownership, std::uint32_t variable_descriptor_count = 0);
    const DescriptorPool& pool() const VKRC_UNCHECKED_NOEXCEPT;

    // Every write keeps what it writes alive (the buffer, view or sampler,
    // found by raw handle when vkrc made it for this device; a raw handle vkrc
    // does not know is the caller's to keep alive until the work using it is
    // done). Overwriting a descriptor, and resetting, freeing or dropping the
    // set, releases the old object as a drop does: its destruction waits for
    // the GPU (docs/design.md, "Descriptor references"). A write to a set
    // invalidated by its pool's reset_sets() is a UsageError.
    //
    // vkUpdateDescriptorSets with one buffer descriptor.
    // Throws UsageError when the binding does not exist, has another
    // descriptor type, or the buffer belongs to another device or lacks the
    // usage the type needs.
    void write_buffer(std::uint32_t binding, VkDescriptorType type, const Buffer& buffer, VkDeviceSize offset = 0,
                      VkDeviceSize range = VK_WHOLE_SIZE, std::uint32_t array_element = 0) const;
    void write_buffer(std::uint32_t binding, VkDescriptorType type, VkBuffer buffer, VkDeviceSize offset = 0,
                      VkDeviceSize range = VK_WHOLE_SIZE, std::uint32_t array_element = 0) const;
    // vkUpdateDescriptorSets with one image/sampler descriptor.
    // Same checks as write_buffer for the view and sampler.
    void write_image(std::uint32_t binding, VkDescriptorType type, const ImageView& view, VkImageLayout layout,
                     const Sampler& sampler = {}, std::uint32_t array_element = 0) const;
    void write_image(std::uint32_t binding, VkDescriptorType type, VkImageView view, VkImageLayout layout,
                     VkSampler sampler = VK_NULL_HANDLE, std::uint32_t array_element = 0) const;
    // One vkUpdateDescriptorSets writing infos.size() consecutive array
    // elements of binding from array_element on (bindless tables). Throws
    // UsageError when the binding does not exist, has another type, or the
    // elements do not all lie in it (its descriptor_count, or the set's
    // variable count); the raw handles are not checked further.
    void write_buffers(std::uint32_t binding, VkDescriptorType type, Span<const VkDescriptorBufferInfo> infos,
                       std::uint32_t array_element = 0) const;
    void write_images(std::uint32_t binding, VkDescriptorType type, Span<const VkDescriptorImageInfo> infos,
                      std::uint32_t array_element = 0) const;
    // Texel buffer descriptors (UNIFORM_TEXEL_BUFFER, STORAGE_TEXEL_BUFFER),
    // checked as write_buffer / write_buffers are.
    void write_buffer_view(std::uint32_t binding, VkDescriptorType type, const BufferView& view,
                           std::uint32_t array_element = 0) const;
    void write_buffer_views(std::uint32_t binding, VkDescriptorType type, Span<const VkBufferView> views,
                            std::uint32_t array_element = 0) const;
    // ACCELERATION_STRUCTURE_KHR descriptors (VkWriteDescriptorSetAccelerationStructureKHR
    // chained by vkrc), checked as write_buffer / write_buffers are. A top
    // level written keeps its bottom levels alive through its own references.
    void write_acceleration_structure(std::uint32_t binding, const AccelerationStructure& structure,
                                      std::uint32_t array_element = 0) const;
    void write_acceleration_structures(std::uint32_t binding, Span<const VkAccelerationStructureKHR> structures,
                                       std::uint32_t array_element = 0) const;
    // vkUpdateDescriptorSetWithTemplate: data is laid out as the template's
    // entries say (read during the call). The template's type must be
    // DESCRIPTOR_SET and its layout this set's, and each entry must lie in
    // its binding (UsageError otherwise). The objects are counted from the
    // template's entries (an adopted template made without entries counts nothing).
    void update_with_template(const DescriptorUpdateTemplate& update_template, const void* data) const;

private:
    friend class DescriptorPool;
    using VulkanObject::VulkanObject;
};

namespace detail {

class DescriptorSetLayoutState final : public DeviceChildState<VkDescriptorSetLayout> {
public:
    static constexpr const char* type_name = "vkrc::DescriptorSetLayout";
    ~DescriptorSetLayoutState() override;
    // For checking writes against the layout.
    List<DescriptorSetLayoutBinding> bindings;
    // The binding with VARIABLE_DESCRIPTOR_COUNT, if any.
    bool has_variable_binding = false;
    std::uint32_t variable_binding = 0;
    // Where each binding's descriptors start in a set's references
    // (parallel to bindings); the variable binding's come last, after fixed_slots.
    List<std::uint32_t> first_slot;
    std::uint32_t fixed_slots = 0;
};

// What one descriptor keeps alive: the object written into it and, for a
// combined image sampler, its sampler.
struct DescriptorRefs {
    Ref<const RefCounted> object;
    Ref<const RefCounted> sampler;
};
class DescriptorSetState;

// A set dropped from a FREE_DESCRIPTOR_SET pool, kept for an allocate() of
// the same layout and variable count. The set's reference to its layout
// moves with it, so reusing the set writes nothing on the layout, which
// threads allocating from pools of their own share.
struct DroppedSet {
    VkDescriptorSet handle = VK_NULL_HANDLE;
    DescriptorSetLayout layout;
    std::uint32_t variable_count = 0;
};

class DescriptorPoolState final : public DeviceChildState<VkDescriptorPool> {
public:
    static constexpr const char* type_name = "vkrc::DescriptorPool";
    ~DescriptorPoolState() override;
    bool can_free_sets = false;
    mutable Mutex mutex;
    // Under mutex: sets dropped while the GPU may use them; those it is done
    // with, kept for reuse (freed when the pool runs out); and how many
    // resets happened (a set from before a reset is already gone).
    PoolFreeList<DroppedSet> pending;
    List<DroppedSet> reusable;
    std::uint64_t generation = 0;
    // Under mutex: the sets that hold references, released by reset_sets().
    DescriptorSetState* sets_with_refs = nullptr;
};

class DescriptorSetState final : public VulkanObjectState<VkDescriptorSet> {
public:
    static constexpr const char* type_name = "vkrc::DescriptorSet";
    ~DescriptorSetState() override;
    DescriptorPool pool;
    DescriptorSetLayout layout;  // checks writes (the raw layout may go once the set exists)
    std::uint64_t generation = 0;
    std::uint32_t variable_count = 0;  // of the layout's variable binding, if it has one
    // Under the pool's mutex: one entry per descriptor (made at the first
    // write), and the set's links in the pool's sets_with_refs.
    List<DescriptorRefs> refs;
    DescriptorSetState* previous_with_refs = nullptr;
    DescriptorSetState* next_with_refs = nullptr;
};

// Drops the references of the given array elements of binding (their
// objects' destruction then waits for the GPU like any drop's); the
// descriptors stay as written. For bindless tables, whose PARTIALLY_BOUND
// slots nothing reads once given back.
void release_descriptors(const DescriptorSetState& set, std::uint32_t binding,
                         Span<const std::uint32_t> elements) noexcept;

}  // namespace detail

inline const DescriptorPool& DescriptorSet::pool() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::DescriptorSet::pool").pool;
}

VKRC_END_NAMESPACE
