// VK_EXT_debug_utils: DebugMessenger handles and set_name.
#include "support/vk_test.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace {

using vkrc_test::ValidationLog;
using vkrc_test::VulkanTest;

// What a DebugMessenger's callback saw: message texts and object names.
struct Heard {
    std::vector<std::string> messages;
    std::vector<std::string> object_names;
};

vkrc::DebugMessenger listen(const vkrc::Instance& instance, const std::shared_ptr<Heard>& heard) {
    return vkrc::DebugMessenger::create(instance, {.callback = [heard](const vkrc::DebugMessage& m) {
                                            heard->messages.emplace_back(m.message);
                                            for (const auto& o : m.objects) {
                                                if (o.pObjectName) heard->object_names.emplace_back(o.pObjectName);
                                            }
                                        }});
}

// Records vkCmdFillBuffer into a buffer without TRANSFER_DST usage, which the
// validation layer reports with the buffer among the message's objects.
void provoke_message_about(const vkrc::Device& device, const vkrc::Queue& queue, const vkrc::Buffer& buffer) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    device.fn().vkCmdFillBuffer(cmd.vk(), buffer.vk(), 0, 4, 0);
    cmd.end();
}

constexpr const char* fill_usage_vuid = "VUID-vkCmdFillBuffer-dstBuffer-00029";

TEST_F(VulkanTest, DebugUtilsNamesAppearInValidationMessages) {
    auto heard = std::make_shared<Heard>();
    auto messenger = listen(instance, heard);
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    vkrc::set_name(device, buffer, "DebugUtils buffer");
    provoke_message_about(device, queue, buffer);
    EXPECT_TRUE(log->take_expected(fill_usage_vuid, 1));
    ASSERT_FALSE(heard->messages.empty());
    EXPECT_NE(heard->messages.front().find("[DebugUtils buffer]"), std::string::npos) << heard->messages.front();
    EXPECT_NE(std::find(heard->object_names.begin(), heard->object_names.end(), "DebugUtils buffer"),
              heard->object_names.end());
}

TEST_F(VulkanTest, DebugUtilsRawHandlesAreNamedToo) {
    auto heard = std::make_shared<Heard>();
    auto messenger = listen(instance, heard);
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    VkBuffer raw = buffer.vk();
    vkrc::set_name(device, raw, "DebugUtils raw buffer");
    provoke_message_about(device, queue, buffer);
    EXPECT_TRUE(log->take_expected(fill_usage_vuid, 1));
    EXPECT_NE(std::find(heard->object_names.begin(), heard->object_names.end(), "DebugUtils raw buffer"),
              heard->object_names.end());
}

// What vkSetDebugUtilsObjectNameEXT received: a wrapper put into the
// device's function table records each call, then passes it on to the layer.
struct NameCall {
    VkObjectType type;
    std::uint64_t handle;
    std::string name;
    bool operator==(const NameCall&) const = default;
};
std::vector<NameCall> name_calls;
PFN_vkSetDebugUtilsObjectNameEXT layer_set_name = nullptr;

VKAPI_ATTR VkResult VKAPI_CALL recording_set_name(VkDevice device, const VkDebugUtilsObjectNameInfoEXT* info) {
    name_calls.push_back({info->objectType, info->objectHandle, info->pObjectName});
    return layer_set_name(device, info);
}

// A vkrc handle or a raw one.
template <class H>
NameCall named(VkObjectType type, const H& handle, const char* name) {
    if constexpr (requires { handle.vk(); }) {
        return {type, reinterpret_cast<std::uint64_t>(handle.vk()), name};
    } else {
        return {type, reinterpret_cast<std::uint64_t>(handle), name};
    }
}

// Every kind of object reaches Vulkan with its own object type and handle
// (read back from the call), and the validation layer, which checks that
// each handle is a live object of the type given, reports nothing; a wrong
// type, given on purpose, it reports exactly once.
TEST_F(VulkanTest, DebugUtilsNamesEveryKindOfObject) {
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT});
    auto image = vkrc::Image::create(
        device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .extent = {4, 4, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    auto view = vkrc::ImageView::create(image);
    auto buffer_view = vkrc::BufferView::create(buffer, {.format = VK_FORMAT_R32_UINT});
    auto sampler = vkrc::Sampler::create(device);
    auto fence = vkrc::Fence::create(device);
    auto semaphore = vkrc::Semaphore::create_timeline(device);
    auto event = vkrc::Event::create(device);
    auto layout = vkrc::PipelineLayout::create(device);
    auto cache = vkrc::PipelineCache::create(device);
    const VkDeviceMemory memory = buffer.allocation().memory();
    auto& table = device.state()->fn;
    layer_set_name = table.vkSetDebugUtilsObjectNameEXT;
    table.vkSetDebugUtilsObjectNameEXT = recording_set_name;
    name_calls.clear();
    vkrc::set_name(device, device, "device");
    vkrc::set_name(device, queue, "queue");
    vkrc::set_name(device, buffer, "buffer");
    vkrc::set_name(device, image, "image");
    vkrc::set_name(device, view, "image view");
    vkrc::set_name(device, buffer_view, "buffer view");
    vkrc::set_name(device, sampler, "sampler");
    vkrc::set_name(device, fence, "fence");
    vkrc::set_name(device, semaphore, "semaphore");
    vkrc::set_name(device, event, "event");
    vkrc::set_name(device, pool, "command pool");
    vkrc::set_name(device, cmd, "command buffer");
    vkrc::set_name(device, layout, "pipeline layout");
    vkrc::set_name(device, cache, "pipeline cache");
    vkrc::set_name(device, memory, "memory");
    table.vkSetDebugUtilsObjectNameEXT = layer_set_name;
    const std::vector<NameCall> expected{named(VK_OBJECT_TYPE_DEVICE, device, "device"),
                                         named(VK_OBJECT_TYPE_QUEUE, queue, "queue"),
                                         named(VK_OBJECT_TYPE_BUFFER, buffer, "buffer"),
                                         named(VK_OBJECT_TYPE_IMAGE, image, "image"),
                                         named(VK_OBJECT_TYPE_IMAGE_VIEW, view, "image view"),
                                         named(VK_OBJECT_TYPE_BUFFER_VIEW, buffer_view, "buffer view"),
                                         named(VK_OBJECT_TYPE_SAMPLER, sampler, "sampler"),
                                         named(VK_OBJECT_TYPE_FENCE, fence, "fence"),
                                         named(VK_OBJECT_TYPE_SEMAPHORE, semaphore, "semaphore"),
                                         named(VK_OBJECT_TYPE_EVENT, event, "event"),
                                         named(VK_OBJECT_TYPE_COMMAND_POOL, pool, "command pool"),
                                         named(VK_OBJECT_TYPE_COMMAND_BUFFER, cmd, "command buffer"),
                                         named(VK_OBJECT_TYPE_PIPELINE_LAYOUT, layout, "pipeline layout"),
                                         named(VK_OBJECT_TYPE_PIPELINE_CACHE, cache, "pipeline cache"),
                                         named(VK_OBJECT_TYPE_DEVICE_MEMORY, memory, "memory")};
    EXPECT_EQ(name_calls, expected);
    vkrc_test::expect_no_validation_messages(*log);
    // The layer's check is live: a fence named as a buffer is reported.
    vkrc::set_name(device, VK_OBJECT_TYPE_BUFFER, reinterpret_cast<std::uint64_t>(fence.vk()), "not a buffer");
    EXPECT_TRUE(log->take_expected("VUID-VkDebugUtilsObjectNameInfoEXT-objectType-02590", 1));
}

TEST_F(VulkanTest, DebugUtilsMessengersAreIndependent) {
    auto first = std::make_shared<Heard>();
    auto second = std::make_shared<Heard>();
    auto a = listen(instance, first);
    auto b = listen(instance, second);
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    provoke_message_about(device, queue, buffer);
    EXPECT_EQ(first->messages.size(), second->messages.size());
    EXPECT_FALSE(first->messages.empty());
    b.reset();  // destroyed: hears nothing more
    auto heard_before = second->messages.size();
    provoke_message_about(device, queue, buffer);
    EXPECT_GT(first->messages.size(), heard_before);
    EXPECT_EQ(second->messages.size(), heard_before);
    EXPECT_TRUE(log->take_expected(fill_usage_vuid, 2));
}

TEST(DebugUtils, MessengerNeedsTheExtension) {
    auto instance = vkrc::Instance::create();
    EXPECT_THROW(vkrc::DebugMessenger::create(instance, {.callback = [](const vkrc::DebugMessage&) {}}),
                 vkrc::UsageError);
    auto log = std::make_shared<ValidationLog>();
    auto validated = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    EXPECT_THROW(vkrc::DebugMessenger::create(validated, {}), vkrc::UsageError);  // no callback
    validated.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

TEST(DebugUtils, NamesAreIgnoredWithoutTheExtension) {
    auto instance = vkrc::Instance::create();
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements()));
    EXPECT_EQ(device.fn().vkSetDebugUtilsObjectNameEXT, nullptr);
    auto fence = vkrc::Fence::create(device);
    EXPECT_NO_THROW(vkrc::set_name(device, fence, "not applied"));
}

TEST(DebugUtils, AdoptedMessengerIsDestroyedWhenOwned) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    auto made = listen(instance, std::make_shared<Heard>());
    // Borrowed: the adopted handle's end leaves the messenger to its maker.
    vkrc::DebugMessenger::adopt(instance, made.vk(), vkrc::Ownership::borrowed).reset();
    EXPECT_THROW(vkrc::DebugMessenger::adopt(instance, VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
    made.reset();
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);  // a double destroy or a leak would be reported
}

}  // namespace
