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
    EXPECT_GE(log->take_expected(fill_usage_vuid), 1u);
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
    EXPECT_GE(log->take_expected(fill_usage_vuid), 1u);
    EXPECT_NE(std::find(heard->object_names.begin(), heard->object_names.end(), "DebugUtils raw buffer"),
              heard->object_names.end());
}

// The validation layer checks that each handle is a live object of the type
// given, so a wrong type mapping fails the test (a validation error).
TEST_F(VulkanTest, DebugUtilsNamesEveryKindOfObject) {
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT});
    auto image = vkrc::Image::create(
        device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .extent = {4, 4, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    vkrc::set_name(device, device, "device");
    vkrc::set_name(device, queue, "queue");
    vkrc::set_name(device, buffer, "buffer");
    vkrc::set_name(device, image, "image");
    vkrc::set_name(device, vkrc::ImageView::create(image), "image view");
    vkrc::set_name(device, vkrc::BufferView::create(buffer, {.format = VK_FORMAT_R32_UINT}), "buffer view");
    vkrc::set_name(device, vkrc::Sampler::create(device), "sampler");
    vkrc::set_name(device, vkrc::Fence::create(device), "fence");
    vkrc::set_name(device, vkrc::Semaphore::create_timeline(device), "semaphore");
    vkrc::set_name(device, vkrc::Event::create(device), "event");
    vkrc::set_name(device, pool, "command pool");
    vkrc::set_name(device, cmd, "command buffer");
    vkrc::set_name(device, vkrc::PipelineLayout::create(device), "pipeline layout");
    vkrc::set_name(device, vkrc::PipelineCache::create(device), "pipeline cache");
    vkrc::set_name(device, buffer.allocation().memory(), "memory");
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
    EXPECT_GE(log->take_expected(fill_usage_vuid), 2u);
}

TEST(DebugUtils, MessengerNeedsTheExtension) {
    auto instance = vkrc::Instance::create();
    EXPECT_THROW(vkrc::DebugMessenger::create(instance, {.callback = [](const vkrc::DebugMessage&) {}}),
                 vkrc::UsageError);
    auto log = std::make_shared<ValidationLog>();
    auto validated = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    EXPECT_THROW(vkrc::DebugMessenger::create(validated, {}), vkrc::UsageError);  // no callback
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
