// A bindless table: one update-after-bind descriptor set of combined image
// samplers and storage buffers whose slots vkrc hands out and takes back.
#pragma once

#include "vkrc/descriptor.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class BindlessTableState;
}  // namespace detail

// The table's two arrays: binding 0, combined image samplers
// (`sampler2D textures[]`); binding 1, storage buffers (`buffer B {...} buffers[]`).
enum class BindlessKind : std::uint8_t { image = 0, buffer = 1 };

// A slot handed out by BindlessTable::add. index is what shaders index the
// kind's array with; the rest lets remove() refuse a stale or foreign one.
struct BindlessIndex {
    std::uint32_t index = 0;
    BindlessKind kind = BindlessKind::image;
    std::uint32_t generation = 0;  // of the slot, bumped by each remove
    std::uint64_t table = 0;       // the table's identity
};

// What a table holds. The device must have enabled (vulkan12_features)
// descriptorBindingPartiallyBound, descriptorBindingUpdateUnusedWhilePending
// and, for each kind with a capacity, descriptorBindingSampledImageUpdateAfterBind
// or descriptorBindingStorageBufferUpdateAfterBind; shaders indexing the
// arrays with non-uniform values need runtimeDescriptorArray and the
// shader*ArrayNonUniformIndexing features.
struct BindlessTableCreateInfo {
    // As many as the device allows (BindlessTable::max_capacity).
    static constexpr std::uint32_t device_limit = UINT32_MAX;
    // Optional (defaults 4096 images, 1024 buffers; 0: none of the kind).
    // More than the device allows is a UsageError naming the limit.
    std::uint32_t image_capacity = 4096;
    std::uint32_t buffer_capacity = 1024;
    // Optional (default all stages): the stages that read the table.
    VkShaderStageFlags stage_flags = VK_SHADER_STAGE_ALL;
};

// The set is PARTIALLY_BOUND, UPDATE_AFTER_BIND and UPDATE_UNUSED_WHILE_PENDING,
// so add() writes while earlier frames that bind the table are in flight. A
// removed slot keeps its object alive and is not handed out again until
// every command buffer that was open when it was removed has closed and the
// GPU has finished the work submitted until then (the queue timelines that
// deferred destruction uses); then its object is released (a drop) and the
// slot is reused. So remove an index once the work that reads it is
// submitted or still recording (not recorded and waiting for a later
// submit); ONE_TIME_SUBMIT command buffers close at their submit, while a
// reusable one that stays executable holds removed slots until it is reset
// or begun again. Thread-safe under the multi-thread policy (one lock per table).
class BindlessTable : public Handle<detail::BindlessTableState> {
public:
    static BindlessTable create(const Device& device, const BindlessTableCreateInfo& info = {});
    // The most descriptors of kind a table of device can hold: the device's
    // maxDescriptorSetUpdateAfterBind* and maxPerStageDescriptorUpdateAfterBind*
    // limits, and maxPerStageUpdateAfterBindResources (which both kinds share).
    static std::uint32_t max_capacity(const Device& device, BindlessKind kind);

    // Writes a combined image sampler into a free slot and returns it. The
    // table keeps view and sampler alive. Throws UsageError when either is
    // empty or of another device, or when the table is full.
    BindlessIndex add(const ImageView& view, const Sampler& sampler,
                      VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL) const;
    // The same for a storage buffer (it needs STORAGE_BUFFER usage).
    BindlessIndex add(const Buffer& buffer, VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE) const;
    // Gives the slot back (see the class comment). Throws UsageError for an
    // index of another table, one already removed, or a stale one (its slot
    // was removed and handed out again).
    void remove(const BindlessIndex& index) const;

    const DescriptorSetLayout& layout() const VKRC_UNCHECKED_NOEXCEPT;
    // Bind it with the layout at the set number your pipeline layout gives it.
    const DescriptorSet& set() const VKRC_UNCHECKED_NOEXCEPT;
    std::uint32_t capacity(BindlessKind kind) const VKRC_UNCHECKED_NOEXCEPT;
    // Slots of kind in use (added and not removed).
    std::uint32_t live_count(BindlessKind kind) const;
    // Slots of kind removed and still waiting for the GPU.
    std::size_t pending_count(BindlessKind kind) const;

    // Out of line: the table's state is vkrc's own (src/bindless.cpp), so
    // an includer compiles no part of it.
    BindlessTable() noexcept;
    ~BindlessTable();
    BindlessTable(const BindlessTable& other) noexcept;
    BindlessTable(BindlessTable&& other) noexcept;
    BindlessTable& operator=(const BindlessTable& other) noexcept;
    BindlessTable& operator=(BindlessTable&& other) noexcept;

private:
    using Handle::Handle;
};

VKRC_END_NAMESPACE
