// Plugs a user-written allocator into vkrc:
//     allocator [--validation]
// Buffers and images take their memory from an ArenaAllocator
// (arena_allocator.hpp: one bump arena per memory type) instead of the
// device's default PoolAllocator. The example checks that both resources
// came from the arena and went back to it.
#include "arena_allocator.hpp"

#include <vkrc/vkrc.hpp>

#include <array>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <span>

int main(int argc, char** argv) try {
    const bool validation = argc > 1 && std::strcmp(argv[1], "--validation") == 0;
    auto instance = vkrc::Instance::create({.application_name = "vkrc allocator", .validation = validation});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));

    // 1. The allocator is shared: every resource made with it, and the device
    //    (until its teardown, so that deferred frees find it), hold a reference.
    auto arena = vkrc::make_allocator<ArenaAllocator>(VkDeviceSize{16} << 20);
    {
        // 2. Resources name it in their create-info; everything else is as usual.
        auto buffer = vkrc::Buffer::create(device, {.size = 4096,
                                                    .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                                    .memory = {.usage = vkrc::MemoryUsage::upload},
                                                    .allocator = arena});
        const std::array<float, 4> values{1, 2, 3, 4};
        buffer.allocation().write(16, std::span<const float>(values));
        auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                                  .extent = {256, 256, 1},
                                                  .usage = VK_IMAGE_USAGE_SAMPLED_BIT,
                                                  .allocator = arena});
        std::printf("buffer at offset %llu, image at offset %llu of the arena\n",
                    (unsigned long long)buffer.allocation().offset(), (unsigned long long)image.allocation().offset());
        // 3. Leaving the scope drops both: their memory returns to the arena
        //    once the GPU is done with them (here at once: nothing was submitted).
    }
    device.wait_idle();
    std::printf("arena: %llu allocations, %llu frees\n", (unsigned long long)arena->allocations,
                (unsigned long long)arena->frees);
    return arena->allocations == 2 && arena->frees == 2 ? 0 : 1;
} catch (const std::exception& e) {
    std::fprintf(stderr, "allocator example: %s\n", e.what());
    return 1;
}
