#include "vkrc/descriptor.hpp"

#include "vkrc/descriptor_template.hpp"

#include "object_state.hpp"
#include "enum_names.hpp"

#include <algorithm>
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

DescriptorSetState::~DescriptorSetState() {
    auto& p = *pool.state();
    if (!p.can_free_sets || !owns_handle()) return;
    LockGuard lock(p.mutex);
    if (p.generation == generation) p.pending.push(*p.device.state(), handle, serial());
}

}  // namespace detail

namespace {

// Immutable samplers: one per descriptor of a sampler binding, of the
// layout's device (VUID-VkDescriptorSetLayoutBinding-descriptorType-00282).
void check_immutable_samplers(const Device& device, const DescriptorSetLayoutBinding& b) {
    if (b.immutable_samplers.empty()) return;
    const std::string where = "vkrc::DescriptorSetLayout::create: binding " + std::to_string(b.binding);
    if (b.descriptor_type != VK_DESCRIPTOR_TYPE_SAMPLER &&
        b.descriptor_type != VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER)
        throw UsageError(where + " has immutable samplers but type " + detail::enum_text(b.descriptor_type));
    if (b.immutable_samplers.size() != b.descriptor_count) {
        throw UsageError(where + " has " + std::to_string(b.immutable_samplers.size()) + " immutable samplers for " +
                         std::to_string(b.descriptor_count) + " descriptors");
    }
    for (const auto& sampler : b.immutable_samplers) {
        if (!sampler || !(sampler.device() == device))
            throw UsageError(where + ": an immutable sampler is empty or belongs to another device");
    }
}

// The cheap checks of a layout's bindings that give a clearer message than
// the validation layer: immutable samplers, and binding flags
// (VUID-VkDescriptorSetLayoutCreateInfo-flags-03000,
// VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-pBindingFlags-03004).
void check_bindings(const Device& device, const DescriptorSetLayoutCreateInfo& info, const char* who) {
    std::uint32_t highest = 0;
    for (const auto& b : info.bindings) highest = std::max(highest, b.binding);
    for (const auto& b : info.bindings) {
        check_immutable_samplers(device, b);
        if ((b.binding_flags & VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT) &&
            !(info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT)) {
            throw UsageError(std::string(who) + ": binding " + std::to_string(b.binding) +
                             " is UPDATE_AFTER_BIND but the layout lacks "
                             "VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT");
        }
        if ((b.binding_flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) && b.binding != highest) {
            throw UsageError(std::string(who) + ": binding " + std::to_string(b.binding) +
                             " has VARIABLE_DESCRIPTOR_COUNT but is not the highest binding (" +
                             std::to_string(highest) + ")");
        }
    }
}

// The bindings a layout checks writes against, and its variable-count binding.
void keep_bindings(detail::DescriptorSetLayoutState& s, const List<DescriptorSetLayoutBinding>& bindings) {
    s.bindings = bindings;
    for (const auto& b : bindings) {
        if (b.binding_flags & VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT) {
            s.has_variable_binding = true;
            s.variable_binding = b.binding;
        }
    }
}

}  // namespace

DescriptorSetLayout DescriptorSetLayout::create(const Device& device, const DescriptorSetLayoutCreateInfo& info) {
    detail::require_handle(device, "vkrc::DescriptorSetLayout::create", "the Device");
    if ((info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR) &&
        !device.extension_enabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME)) {
        throw UsageError(
            "vkrc::DescriptorSetLayout::create: PUSH_DESCRIPTOR_BIT_KHR needs VK_KHR_push_descriptor enabled on the "
            "device");
    }
    check_bindings(device, info, "vkrc::DescriptorSetLayout::create");
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
    constexpr const char* who = "vkrc::DescriptorSetLayout::adopt";
    detail::require_handle(device, who, "the Device");
    if (layout == VK_NULL_HANDLE) throw UsageError(std::string(who) + ": the VkDescriptorSetLayout is VK_NULL_HANDLE");
    check_bindings(device, info, who);
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
    auto s = detail::adopted_state<detail::DescriptorPoolState>("vkrc::DescriptorPool::adopt", device, "the Device",
                                                                pool, "VkDescriptorPool", ownership);
    s->can_free_sets = (flags & VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT) != 0;
    return DescriptorPool(std::move(s));
}

DescriptorPool DescriptorPool::create(const Device& device, const DescriptorPoolCreateInfo& info) {
    detail::require_handle(device, "vkrc::DescriptorPool::create", "the Device");
    if (info.max_sets == 0) throw UsageError("vkrc::DescriptorPool::create: max_sets is 0");
    if (info.pool_sizes.empty()) throw UsageError("vkrc::DescriptorPool::create: pool_sizes is empty");
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
void check_variable_count(const detail::DescriptorSetLayoutState& layout, std::uint32_t count, const char* who) {
    if (!layout.has_variable_binding) {
        if (count == 0) return;
        throw UsageError(std::string(who) + ": variable_descriptor_count is " + std::to_string(count) +
                         " but the layout has no VARIABLE_DESCRIPTOR_COUNT binding");
    }
    for (const auto& b : layout.bindings) {
        if (b.binding == layout.variable_binding && count > b.descriptor_count) {
            throw UsageError(std::string(who) + ": variable_descriptor_count " + std::to_string(count) +
                             " is more than binding " + std::to_string(b.binding) + "'s descriptor_count " +
                             std::to_string(b.descriptor_count));
        }
    }
}

}  // namespace

DescriptorSet DescriptorPool::allocate(const DescriptorSetLayout& layout,
                                       std::uint32_t variable_descriptor_count) const {
    detail::require_handle(layout, "vkrc::DescriptorPool::allocate", "the DescriptorSetLayout");
    if (!(layout.device() == device())) {
        throw UsageError("vkrc::DescriptorPool::allocate: the DescriptorSetLayout belongs to another device");
    }
    check_variable_count(*layout.state(), variable_descriptor_count, "vkrc::DescriptorPool::allocate");
    auto& p = *state_;
    auto& d = *p.device.state();
    detail::Ref<detail::DescriptorSetState> s(new detail::DescriptorSetState);
    s->pool = *this;
    s->layout = layout;
    s->variable_count = variable_descriptor_count;
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
    thread_local List<VkDescriptorSet> ready;
    LockGuard lock(p.mutex);
    ready.clear();
    p.pending.take_ready(d, ready);
    if (!ready.empty()) {
        check(d.fn.vkFreeDescriptorSets(d.device, p.handle, static_cast<std::uint32_t>(ready.size()), ready.data()),
              "vkFreeDescriptorSets");
    }
    check(d.fn.vkAllocateDescriptorSets(d.device, &ai, &s->handle), "vkAllocateDescriptorSets");
    s->generation = p.generation;
    return DescriptorSet(std::move(s));
}

DescriptorSet DescriptorSet::adopt(const DescriptorPool& pool, const DescriptorSetLayout& layout, VkDescriptorSet set,
                                   Ownership ownership, std::uint32_t variable_descriptor_count) {
    constexpr const char* who = "vkrc::DescriptorSet::adopt";
    detail::require_handle(pool, who, "the DescriptorPool");
    detail::require_handle(layout, who, "the DescriptorSetLayout");
    if (set == VK_NULL_HANDLE) throw UsageError(std::string(who) + ": the VkDescriptorSet is VK_NULL_HANDLE");
    if (!(layout.device() == pool.device())) {
        throw UsageError(std::string(who) + ": the DescriptorSetLayout belongs to another device");
    }
    check_variable_count(*layout.state(), variable_descriptor_count, who);
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
    LockGuard lock(p.mutex);
    check(p.device.fn().vkResetDescriptorPool(p.device.vk(), p.handle, 0), "vkResetDescriptorPool");
    p.pending.clear();
    ++p.generation;
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

// The layout binding a write targets must exist, have the write's type and
// hold the count elements from array_element on (VUID-VkWriteDescriptorSet-dstBinding-00315,
// -descriptorType-00319, -dstArrayElement-00321); vkrc does not let a write
// run on into the next binding. The variable binding holds the set's count.
void check_write(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                 std::uint32_t array_element, std::size_t count, const char* who) {
    if (!s.layout) return;
    const auto& layout = *s.layout.state();
    for (const auto& b : layout.bindings) {
        if (b.binding != binding) continue;
        if (b.descriptor_type != type) {
            throw UsageError(std::string(who) + ": binding " + std::to_string(binding) + " has descriptor type " +
                             detail::enum_text(b.descriptor_type) + " in the set layout, the write has type " +
                             detail::enum_text(type));
        }
        const bool variable = layout.has_variable_binding && layout.variable_binding == binding;
        const std::uint32_t size = variable ? s.variable_count : b.descriptor_count;
        if (array_element >= size || count > size - array_element) {
            const std::string elements = count == 1 ? "array element " + std::to_string(array_element) + " is"
                                                    : "array elements " + std::to_string(array_element) + " to " +
                                                          std::to_string(array_element + count - 1) + " are";
            throw UsageError(std::string(who) + ": " + elements + " past binding " + std::to_string(binding) + "'s " +
                             std::to_string(size) + " descriptors");
        }
        return;
    }
    throw UsageError(std::string(who) + ": the set layout has no binding " + std::to_string(binding));
}

}  // namespace

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, const Buffer& buffer,
                                 VkDeviceSize offset, VkDeviceSize range, std::uint32_t array_element) const {
    constexpr const char* who = "vkrc::DescriptorSet::write_buffer";
    detail::require_handle(buffer, who, "the Buffer");
    if (!(buffer.device() == pool().device()))
        throw UsageError(std::string(who) + ": the buffer belongs to another device");
    const VkBufferUsageFlags needs =
        type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC
            ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
            : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (is_buffer_type(type) && !(buffer.usage() & needs)) {
        throw UsageError(std::string(who) + ": the buffer lacks the usage descriptor type " + detail::enum_text(type) +
                         " needs (VUID-VkWriteDescriptorSet-descriptorType-00330/00331)");
    }
    write_buffer(binding, type, buffer.vk(), offset, range, array_element);
}

void DescriptorSet::write_image(std::uint32_t binding, VkDescriptorType type, const ImageView& view,
                                VkImageLayout layout, const Sampler& sampler, std::uint32_t array_element) const {
    constexpr const char* who = "vkrc::DescriptorSet::write_image";
    const auto& device = pool().device();
    if (view && !(view.image().device() == device)) {
        throw UsageError(std::string(who) + ": the image view belongs to another device");
    }
    if (sampler && !(sampler.device() == device))
        throw UsageError(std::string(who) + ": the sampler belongs to another device");
    write_image(binding, type, view ? view.vk() : VK_NULL_HANDLE, layout, sampler ? sampler.vk() : VK_NULL_HANDLE,
                array_element);
}

namespace {
// One vkUpdateDescriptorSets of count descriptors; exactly one of the infos is set.
void update(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
            std::uint32_t array_element, std::size_t count, const VkDescriptorBufferInfo* buffer_info,
            const VkDescriptorImageInfo* image_info) {
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = s.handle;
    w.dstBinding = binding;
    w.dstArrayElement = array_element;
    w.descriptorCount = static_cast<std::uint32_t>(count);
    w.descriptorType = type;
    w.pBufferInfo = buffer_info;
    w.pImageInfo = image_info;
    const auto& d = s.pool.device();
    d.fn().vkUpdateDescriptorSets(d.vk(), 1, &w, 0, nullptr);
}
}  // namespace

namespace {

void write_buffer_infos(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                        Span<const VkDescriptorBufferInfo> infos, std::uint32_t array_element, const char* who) {
    if (!is_buffer_type(type)) {
        throw UsageError(std::string(who) + ": descriptor type " + detail::enum_text(type) + " is not a buffer type");
    }
    check_write(s, binding, type, array_element, infos.size(), who);
    if (!infos.empty()) update(s, binding, type, array_element, infos.size(), infos.data(), nullptr);
}

void write_image_infos(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                       Span<const VkDescriptorImageInfo> infos, std::uint32_t array_element, const char* who) {
    if (!is_image_type(type)) {
        throw UsageError(std::string(who) + ": descriptor type " + detail::enum_text(type) +
                         " is not an image or sampler type");
    }
    check_write(s, binding, type, array_element, infos.size(), who);
    if (!infos.empty()) update(s, binding, type, array_element, infos.size(), nullptr, infos.data());
}

}  // namespace

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, VkBuffer buffer, VkDeviceSize offset,
                                 VkDeviceSize range, std::uint32_t array_element) const {
    VKRC_REQUIRE_STATE("vkrc::DescriptorSet::write_buffer");
    const VkDescriptorBufferInfo info{buffer, offset, range};
    write_buffer_infos(*state_, binding, type, Span(&info, 1), array_element, "vkrc::DescriptorSet::write_buffer");
}

void DescriptorSet::write_image(std::uint32_t binding, VkDescriptorType type, VkImageView view, VkImageLayout layout,
                                VkSampler sampler, std::uint32_t array_element) const {
    VKRC_REQUIRE_STATE("vkrc::DescriptorSet::write_image");
    const VkDescriptorImageInfo info{sampler, view, layout};
    write_image_infos(*state_, binding, type, Span(&info, 1), array_element, "vkrc::DescriptorSet::write_image");
}

void DescriptorSet::write_buffers(std::uint32_t binding, VkDescriptorType type,
                                  Span<const VkDescriptorBufferInfo> infos, std::uint32_t array_element) const {
    VKRC_REQUIRE_STATE("vkrc::DescriptorSet::write_buffers");
    write_buffer_infos(*state_, binding, type, infos, array_element, "vkrc::DescriptorSet::write_buffers");
}

void DescriptorSet::write_images(std::uint32_t binding, VkDescriptorType type, Span<const VkDescriptorImageInfo> infos,
                                 std::uint32_t array_element) const {
    VKRC_REQUIRE_STATE("vkrc::DescriptorSet::write_images");
    write_image_infos(*state_, binding, type, infos, array_element, "vkrc::DescriptorSet::write_images");
}

void DescriptorSet::update_with_template(const DescriptorUpdateTemplate& update_template, const void* data) const {
    VKRC_REQUIRE_STATE("vkrc::DescriptorSet::update_with_template");
    constexpr const char* who = "vkrc::DescriptorSet::update_with_template";
    detail::require_handle(update_template, who, "the DescriptorUpdateTemplate");
    if (update_template.template_type() != VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET) {
        throw UsageError(std::string(who) + ": the template is for push descriptors");
    }
    // VUID-vkUpdateDescriptorSetWithTemplate-descriptorUpdateTemplate-00387 asks
    // for a compatible layout; vkrc asks for the same one.
    if (state_->layout && !(update_template.descriptor_set_layout() == state_->layout)) {
        throw UsageError(std::string(who) + ": the template was made for another descriptor set layout");
    }
    const auto& d = state_->pool.device();
    d.fn().vkUpdateDescriptorSetWithTemplate(d.vk(), state_->handle, update_template.vk(), data);
}

VKRC_END_NAMESPACE
