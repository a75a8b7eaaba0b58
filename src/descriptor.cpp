#include "vkrc/descriptor.hpp"

#include "enum_names.hpp"

#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {

DescriptorSetLayoutState::~DescriptorSetLayoutState() {
    defer_destroy<&DeviceFunctions::vkDestroyDescriptorSetLayout>(*device.state(), layout, serial());
}

DescriptorPoolState::~DescriptorPoolState() {
    // Destroying the pool frees every set still in it, pending ones included.
    defer_destroy<&DeviceFunctions::vkDestroyDescriptorPool>(*device.state(), pool, serial());
}

DescriptorSetState::~DescriptorSetState() {
    auto& p = *pool.state();
    if (!p.can_free_sets || set == VK_NULL_HANDLE) return;
    LockGuard lock(p.mutex);
    if (p.generation == generation) p.pending.push(*p.device.state(), set, serial());
}

}  // namespace detail

DescriptorSetLayout DescriptorSetLayout::create(const Device& device, const DescriptorSetLayoutCreateInfo& info) {
    if (!device) throw UsageError("vkrc::DescriptorSetLayout::create: the Device handle is empty");
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    bindings.reserve(info.bindings.size());
    for (const auto& b : info.bindings) {
        bindings.push_back({b.binding, b.descriptor_type, b.descriptor_count, b.stage_flags, nullptr});
    }
    VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    ci.flags = info.flags;
    ci.bindingCount = static_cast<std::uint32_t>(bindings.size());
    ci.pBindings = bindings.data();
    detail::Ref<detail::DescriptorSetLayoutState> s(new detail::DescriptorSetLayoutState);
    s->device = device;
    s->bindings = info.bindings;
    check(device.fn().vkCreateDescriptorSetLayout(device.vk(), &ci, nullptr, &s->layout),
          "vkCreateDescriptorSetLayout");
    return DescriptorSetLayout(std::move(s));
}

DescriptorPool DescriptorPool::create(const Device& device, const DescriptorPoolCreateInfo& info) {
    if (!device) throw UsageError("vkrc::DescriptorPool::create: the Device handle is empty");
    if (info.max_sets == 0) throw UsageError("vkrc::DescriptorPool::create: max_sets is 0");
    if (info.pool_sizes.empty()) throw UsageError("vkrc::DescriptorPool::create: pool_sizes is empty");
    VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    ci.flags = info.flags;
    ci.maxSets = info.max_sets;
    ci.poolSizeCount = static_cast<std::uint32_t>(info.pool_sizes.size());
    ci.pPoolSizes = info.pool_sizes.data();
    detail::Ref<detail::DescriptorPoolState> s(new detail::DescriptorPoolState);
    s->device = device;
    s->can_free_sets = (info.flags & VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT) != 0;
    check(device.fn().vkCreateDescriptorPool(device.vk(), &ci, nullptr, &s->pool), "vkCreateDescriptorPool");
    return DescriptorPool(std::move(s));
}

DescriptorSet DescriptorPool::allocate(const DescriptorSetLayout& layout) const {
    if (!layout) throw UsageError("vkrc::DescriptorPool::allocate: the DescriptorSetLayout handle is empty");
    if (!(layout.device() == device())) {
        throw UsageError("vkrc::DescriptorPool::allocate: the DescriptorSetLayout belongs to another device");
    }
    auto& p = *state_;
    auto& d = *p.device.state();
    detail::Ref<detail::DescriptorSetState> s(new detail::DescriptorSetState);
    s->pool = *this;
    s->layout = layout;
    VkDescriptorSetLayout raw_layout = layout.vk();
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = p.pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &raw_layout;
    thread_local List<VkDescriptorSet> ready;
    LockGuard lock(p.mutex);
    ready.clear();
    p.pending.take_ready(d, ready);
    if (!ready.empty()) {
        check(d.fn.vkFreeDescriptorSets(d.device, p.pool, static_cast<std::uint32_t>(ready.size()), ready.data()),
              "vkFreeDescriptorSets");
    }
    check(d.fn.vkAllocateDescriptorSets(d.device, &ai, &s->set), "vkAllocateDescriptorSets");
    s->generation = p.generation;
    return DescriptorSet(std::move(s));
}

void DescriptorPool::reset_sets() const {
    auto& p = *state_;
    LockGuard lock(p.mutex);
    check(p.device.fn().vkResetDescriptorPool(p.device.vk(), p.pool, 0), "vkResetDescriptorPool");
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
// hold array_element (VUID-VkWriteDescriptorSet-dstBinding-00315,
// -descriptorType-00319, -dstArrayElement-00321).
void check_write(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                 std::uint32_t array_element, const char* who) {
    if (!s.layout) return;
    for (const auto& b : s.layout.state()->bindings) {
        if (b.binding != binding) continue;
        if (b.descriptor_type != type) {
            throw UsageError(std::string(who) + ": binding " + std::to_string(binding) + " has descriptor type " +
                             detail::enum_text(b.descriptor_type) + " in the set layout, the write has type " +
                             detail::enum_text(type));
        }
        if (array_element >= b.descriptor_count) {
            throw UsageError(std::string(who) + ": array element " + std::to_string(array_element) +
                             " is past binding " + std::to_string(binding) + "'s " +
                             std::to_string(b.descriptor_count) + " descriptors");
        }
        return;
    }
    throw UsageError(std::string(who) + ": the set layout has no binding " + std::to_string(binding));
}

}  // namespace

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, const Buffer& buffer,
                                 VkDeviceSize offset, VkDeviceSize range, std::uint32_t array_element) const {
    constexpr const char* who = "vkrc::DescriptorSet::write_buffer";
    if (!buffer) throw UsageError(std::string(who) + ": the Buffer handle is empty");
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
// One descriptor, one vkUpdateDescriptorSets; exactly one of the infos is set.
void update_one(const detail::DescriptorSetState& s, std::uint32_t binding, VkDescriptorType type,
                std::uint32_t array_element, const VkDescriptorBufferInfo* buffer_info,
                const VkDescriptorImageInfo* image_info) {
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = s.set;
    w.dstBinding = binding;
    w.dstArrayElement = array_element;
    w.descriptorCount = 1;
    w.descriptorType = type;
    w.pBufferInfo = buffer_info;
    w.pImageInfo = image_info;
    const auto& d = s.pool.device();
    d.fn().vkUpdateDescriptorSets(d.vk(), 1, &w, 0, nullptr);
}
}  // namespace

void DescriptorSet::write_buffer(std::uint32_t binding, VkDescriptorType type, VkBuffer buffer, VkDeviceSize offset,
                                 VkDeviceSize range, std::uint32_t array_element) const {
    if (!is_buffer_type(type)) {
        throw UsageError("vkrc::DescriptorSet::write_buffer: descriptor type " + detail::enum_text(type) +
                         " is not a buffer type");
    }
    check_write(*state_, binding, type, array_element, "vkrc::DescriptorSet::write_buffer");
    const VkDescriptorBufferInfo info{buffer, offset, range};
    update_one(*state_, binding, type, array_element, &info, nullptr);
}

void DescriptorSet::write_image(std::uint32_t binding, VkDescriptorType type, VkImageView view, VkImageLayout layout,
                                VkSampler sampler, std::uint32_t array_element) const {
    if (!is_image_type(type)) {
        throw UsageError("vkrc::DescriptorSet::write_image: descriptor type " + detail::enum_text(type) +
                         " is not an image or sampler type");
    }
    check_write(*state_, binding, type, array_element, "vkrc::DescriptorSet::write_image");
    const VkDescriptorImageInfo info{sampler, view, layout};
    update_one(*state_, binding, type, array_element, nullptr, &info);
}

VKRC_END_NAMESPACE
