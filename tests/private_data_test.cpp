// Private data slots: a value per object, set and read back on several object types.
#include "support/features.hpp"
#include "support/vk_test.hpp"

namespace {

using vkrc_test::VulkanTest;

TEST_F(VulkanTest, PrivateDataOnSeveralObjectTypes) {
    if (!vkrc_test::supported_features(physical_device).v13.privateData) GTEST_SKIP() << "the device lacks privateData";
    vkrc::DeviceCreateInfo info;
    info.vulkan13_features.privateData = VK_TRUE;
    device = vkrc::Device::create(physical_device, info);
    queue = device.default_queue();

    auto slot = vkrc::PrivateDataSlot::create(device);
    auto other_slot = vkrc::PrivateDataSlot::create(device);
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto sampler = vkrc::Sampler::create(device);
    auto layout = vkrc::DescriptorSetLayout::create(device, {});

    slot.set(VK_OBJECT_TYPE_DEVICE, device.vk(), 1);
    slot.set(VK_OBJECT_TYPE_BUFFER, buffer.vk(), 2);
    slot.set(VK_OBJECT_TYPE_IMAGE, image.vk(), 3);
    slot.set(VK_OBJECT_TYPE_SAMPLER, sampler.vk(), 0xffff'ffff'ffff'ffffull);
    other_slot.set(VK_OBJECT_TYPE_BUFFER, buffer.vk(), 20);

    EXPECT_EQ(slot.get(VK_OBJECT_TYPE_DEVICE, device.vk()), 1u);
    EXPECT_EQ(slot.get(VK_OBJECT_TYPE_BUFFER, buffer.vk()), 2u);
    EXPECT_EQ(slot.get(VK_OBJECT_TYPE_IMAGE, image.vk()), 3u);
    EXPECT_EQ(slot.get(VK_OBJECT_TYPE_SAMPLER, sampler.vk()), 0xffff'ffff'ffff'ffffull);
    EXPECT_EQ(slot.get(VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, layout.vk()), 0u) << "never set";
    EXPECT_EQ(other_slot.get(VK_OBJECT_TYPE_BUFFER, buffer.vk()), 20u) << "slots are independent";
    EXPECT_EQ(other_slot.get(VK_OBJECT_TYPE_IMAGE, image.vk()), 0u);
    slot.set(VK_OBJECT_TYPE_BUFFER, buffer.vk(), 5);
    EXPECT_EQ(slot.get(VK_OBJECT_TYPE_BUFFER, buffer.vk()), 5u);
    EXPECT_EQ(slot.device(), device);
}

// A slot made with the raw API: owned, vkrc destroys it (the layer reports a
// leak otherwise); borrowed, its maker does (a double destroy would be reported).
TEST_F(VulkanTest, PrivateDataAdoptedSlot) {
    if (!vkrc_test::supported_features(physical_device).v13.privateData) GTEST_SKIP() << "the device lacks privateData";
    vkrc::DeviceCreateInfo info;
    info.vulkan13_features.privateData = VK_TRUE;
    device = vkrc::Device::create(physical_device, info);
    queue = device.default_queue();
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    for (const auto ownership : {vkrc::Ownership::owned, vkrc::Ownership::borrowed}) {
        VkPrivateDataSlotCreateInfo ci{VK_STRUCTURE_TYPE_PRIVATE_DATA_SLOT_CREATE_INFO};
        VkPrivateDataSlot raw = VK_NULL_HANDLE;
        ASSERT_EQ(device.fn().vkCreatePrivateDataSlot(device.vk(), &ci, nullptr, &raw), VK_SUCCESS);
        {
            auto slot = vkrc::PrivateDataSlot::adopt(device, raw, ownership);
            slot.set(VK_OBJECT_TYPE_BUFFER, buffer.vk(), 7);
            EXPECT_EQ(slot.get(VK_OBJECT_TYPE_BUFFER, buffer.vk()), 7u);
        }
        device.wait_idle();  // runs a (wrongly) deferred destruction before the raw one
        if (ownership == vkrc::Ownership::borrowed) device.fn().vkDestroyPrivateDataSlot(device.vk(), raw, nullptr);
    }
    EXPECT_THROW(vkrc::PrivateDataSlot::adopt(device, VK_NULL_HANDLE, vkrc::Ownership::owned), vkrc::UsageError);
}

}  // namespace
