// A user-written allocator plugged into vkrc: buffers and images take their
// memory from ArenaAllocator (arena_allocator.hpp) instead of the default pool.
#include "arena_allocator.hpp"

#include <vkrc/vkrc.hpp>

#include <array>
#include <cstdio>

int main() try {
    auto instance = vkrc::Instance::create({.application_name = "vkrc allocator example"});
    auto physical = vkrc::PhysicalDevice::select(instance);
    auto device = vkrc::Device::create(physical);
    auto arena = std::make_shared<ArenaAllocator>(VkDeviceSize{16} << 20);

    vkrc::BufferCreateInfo buffer_info;
    buffer_info.size = 4096;
    buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    buffer_info.memory.usage = vkrc::MemoryUsage::upload;
    buffer_info.allocator = arena;
    {
        auto buffer = vkrc::Buffer::create(device, buffer_info);
        const std::array<float, 4> values{1, 2, 3, 4};
        buffer.allocation().write(16, std::span<const float>(values));
        vkrc::ImageCreateInfo image_info;
        image_info.format = VK_FORMAT_R8G8B8A8_UNORM;
        image_info.extent = {256, 256, 1};
        image_info.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
        image_info.allocator = arena;
        auto image = vkrc::Image::create(device, image_info);
        std::printf("buffer at offset %llu, image at offset %llu of the arena\n",
                    (unsigned long long)buffer.allocation().offset(), (unsigned long long)image.allocation().offset());
    }
    device.wait_idle();
    std::printf("arena: %llu allocations, %llu frees\n", (unsigned long long)arena->allocations,
                (unsigned long long)arena->frees);
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "allocator example: %s\n", e.what());
    return 1;
}
