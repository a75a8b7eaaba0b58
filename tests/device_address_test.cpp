// Buffer memory: device addresses (memory allocated with DEVICE_ADDRESS by
// both shipped allocators, Buffer::device_address(), and a shader that
// follows them), and the refusal of sparse resources.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/device_address.comp.h"

#include <span>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

struct Params {
    VkDeviceAddress src;
    VkDeviceAddress dst;
    std::uint32_t count;
    std::uint32_t pad;
};

// dst[i] = src[i] * 3 + 1 through buffer references, both buffers from allocator.
void run_through_addresses(const vkrc::Device& device, const vkrc::Queue& queue,
                           const vkrc::SharedAllocator& allocator) {
    constexpr std::uint32_t count = 100;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    auto src = vkrc::Buffer::create(
        device,
        {.size = count * 4, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::upload}, .allocator = allocator});
    auto dst = vkrc::Buffer::create(
        device,
        {.size = count * 4, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::readback}, .allocator = allocator});
    ASSERT_NE(src.device_address(), 0u);
    ASSERT_NE(dst.device_address(), 0u);
    std::vector<std::uint32_t> values(count);
    for (std::uint32_t i = 0; i < count; ++i) values[i] = i * 7;
    src.allocation().write(0, values.data(), count);

    auto layout = vkrc::PipelineLayout::create(
        device, {.push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Params)}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::device_address_comp));
    vkrc_test::OneShotCommands s(queue);
    s.cmd.bind_pipeline(pipeline);
    s.cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT,
                         Params{src.device_address(), dst.device_address(), count, 0});
    s.cmd.dispatch((count + 63) / 64);
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    std::vector<std::uint32_t> out(count);
    dst.allocation().read(0, out.data(), count);
    for (std::uint32_t i = 0; i < count; ++i) ASSERT_EQ(out[i], i * 7 * 3 + 1) << "element " << i;
}

class DeviceAddressTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (!vkrc_test::supported_features(physical_device).v12.bufferDeviceAddress)
            GTEST_SKIP() << "the device lacks bufferDeviceAddress";
        vkrc::DeviceCreateInfo info;
        info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
        device = vkrc::Device::create(physical_device, info);
        queue = device.default_queue();
    }
};

TEST_F(DeviceAddressTest, DeviceAddressWithTheDedicatedAllocator) {
    run_through_addresses(device, queue, vkrc::make_allocator<vkrc::DedicatedAllocator>());
}

TEST_F(DeviceAddressTest, DeviceAddressWithThePoolAllocator) {
    run_through_addresses(device, queue, vkrc::make_allocator<vkrc::PoolAllocator>());
}

// The pool keeps device-address blocks apart, so other buffers do not pay for the flag.
TEST_F(DeviceAddressTest, DeviceAddressBlocksAreKeptApartByThePoolAllocator) {
    auto plain = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    auto addressed = vkrc::Buffer::create(
        device, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT});
    EXPECT_EQ(plain.device_address(), 0u);
    EXPECT_NE(addressed.device_address(), 0u);
    ASSERT_EQ(plain.allocation().memory_type(), addressed.allocation().memory_type());
    EXPECT_NE(plain.allocation().memory(), addressed.allocation().memory());
    auto second = vkrc::Buffer::create(
        device, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT});
    EXPECT_EQ(second.allocation().memory(), addressed.allocation().memory()) << "one block serves both";
    EXPECT_NE(second.device_address(), addressed.device_address());
}

// vkrc binds one allocation to each resource, which sparse resources must
// not have: they are refused before anything is created.
TEST_F(VulkanTest, SparseBuffersAndImagesAreRefused) {
    for (VkBufferCreateFlags flags :
         {VkBufferCreateFlags(VK_BUFFER_CREATE_SPARSE_BINDING_BIT),
          VkBufferCreateFlags(VK_BUFFER_CREATE_SPARSE_BINDING_BIT | VK_BUFFER_CREATE_SPARSE_RESIDENCY_BIT)}) {
        try {
            vkrc::Buffer::create(device, {.flags = flags, .size = 4096, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
            ADD_FAILURE() << "a sparse buffer was created";
        } catch (const vkrc::UsageError& e) {
            EXPECT_NE(std::string(e.what()).find("vkrc::Buffer::create: sparse flags are not supported"),
                      std::string::npos)
                << e.what();
        }
    }
    EXPECT_THROW(vkrc::Image::create(device, {.flags = VK_IMAGE_CREATE_SPARSE_BINDING_BIT,
                                              .format = VK_FORMAT_R8G8B8A8_UNORM,
                                              .usage = VK_IMAGE_USAGE_SAMPLED_BIT}),
                 vkrc::UsageError);
}

}  // namespace
