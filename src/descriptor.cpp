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

DescriptorSet DescriptorPool::allocate(const DescriptorSetLayout& layout,
                                       std::uint32_t variable_descriptor_count) const {
    const detail::Caller caller{"vkrc::DescriptorPool::allocate"};
    caller.require_handle(layout, "the DescriptorSetLayout");
    caller.require(layout.device() == device(), "the DescriptorSetLayout belongs to another device");
    check_variable_count(caller, *layout.state(), variable_descriptor_count);
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
void check_write(const detail::Caller& caller, const detail::DescriptorSetState& s, std::uint32_t binding,
                 VkDescriptorType type, std::uint32_t array_element, std::size_t count) {
    if (!s.layout) return;
    const auto& layout = *s.layout.state();
    for (const auto& b : layout.bindings) {
        if (b.binding != binding) continue;
        caller.require(b.descriptor_type == type, "binding ", binding, " has descriptor type ", b.descriptor_type,
                       " in the set layout, the write has type ", type);
        const bool variable = layout.has_variable_binding && layout.variable_binding == binding;
        const std::uint32_t size = variable ? s.variable_count : b.descriptor_count;
        if (array_element >= size || count > size - array_element) {
            const std::string elements = count == 1 ? "array element " + std::to_string(array_element) + " is"
                                                    : "array elements " + std::to_string(array_element) + " to " +
                                                          std::to_string(array_element + count - 1) + " are";
            caller.refuse(elements, " past binding ", binding, "'s ", size, " descriptors");
        }
        return;
    }
    caller.refuse("the set layout has no binding ", binding);
}

}  // namespace

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
                        Span<const VkDescriptorBufferInfo> infos, std::uint32_t array_element,
                        const detail::Caller& caller) {
    caller.require(is_buffer_type(type), "descriptor type ", type, " is not a buffer type");
    check_write(caller, s, binding, type, array_element, infos.size());
    if (!infos.empty()) update(s, binding, type, array_element, infos.size(), infos.data(), nullptr);
}

void write_image_infos(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                       Span<const VkDescriptorImageInfo> infos, std::uint32_t array_element,
                       const detail::Caller& caller) {
    caller.require(is_image_type(type), "descriptor type ", type, " is not an image or sampler type");
    check_write(caller, s, binding, type, array_element, infos.size());
    if (!infos.empty()) update(s, binding, type, array_element, infos.size(), nullptr, infos.data());
}

}  // namespace

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, VkBuffer buffer, VkDeviceSize offset,
                                 VkDeviceSize range, std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_buffer"};
    VKRC_REQUIRE_STATE(caller.name());
    const VkDescriptorBufferInfo info{buffer, offset, range};
    write_buffer_infos(*state_, binding, type, Span(&info, 1), array_element, caller);
}

void DescriptorSet::write_image(std::uint32_t binding, VkDescriptorType type, VkImageView view, VkImageLayout layout,
                                VkSampler sampler, std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_image"};
    VKRC_REQUIRE_STATE(caller.name());
    const VkDescriptorImageInfo info{sampler, view, layout};
    write_image_infos(*state_, binding, type, Span(&info, 1), array_element, caller);
}

void DescriptorSet::write_buffers(std::uint32_t binding, VkDescriptorType type,
                                  Span<const VkDescriptorBufferInfo> infos, std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_buffers"};
    VKRC_REQUIRE_STATE(caller.name());
    write_buffer_infos(*state_, binding, type, infos, array_element, caller);
}

void DescriptorSet::write_images(std::uint32_t binding, VkDescriptorType type, Span<const VkDescriptorImageInfo> infos,
                                 std::uint32_t array_element) const {
    const detail::Caller caller{"vkrc::DescriptorSet::write_images"};
    VKRC_REQUIRE_STATE(caller.name());
    write_image_infos(*state_, binding, type, infos, array_element, caller);
}

void DescriptorSet::update_with_template(const DescriptorUpdateTemplate& update_template, const void* data) const {
    const detail::Caller caller{"vkrc::DescriptorSet::update_with_template"};
    VKRC_REQUIRE_STATE(caller.name());
    caller.require_handle(update_template, "the DescriptorUpdateTemplate");
    caller.require(update_template.template_type() == VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET,
                   "the template is for push descriptors");
    // VUID-vkUpdateDescriptorSetWithTemplate-descriptorUpdateTemplate-00387 asks
    // for a compatible layout; vkrc asks for the same one.
    caller.require(!state_->layout || update_template.descriptor_set_layout() == state_->layout,
                   "the template was made for another descriptor set layout");
    const auto& d = state_->pool.device();
    d.fn().vkUpdateDescriptorSetWithTemplate(d.vk(), state_->handle, update_template.vk(), data);
}

VKRC_END_NAMESPACE
