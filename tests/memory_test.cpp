#include "support/vk_test.hpp"
#include "support/wrapped_allocator.hpp"

#include "../examples/allocator/arena_allocator.hpp"

#include <vkrc/upload.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <latch>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <span>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace {

using vkrc::detail::mapped_range;
using vkrc::detail::MemoryRange;
using vkrc_test::VulkanTest;

constexpr VkDeviceSize MiB = VkDeviceSize{1} << 20;
constexpr VkDeviceSize KiB = VkDeviceSize{1} << 10;

// ------------------------------------------------------------ pure range arithmetic

struct RangeCase {
    const char* name;
    VkDeviceSize allocation_offset, allocation_size, memory_size, atom, offset, size;
    MemoryRange expected;
};

TEST(MappedRange, RoundsOutToTheAtomAndClamps) {
    const RangeCase cases[] = {
        {"aligned middle", 256, 512, 4096, 64, 64, 128, {320, 128}},
        {"unaligned offset and size", 256, 512, 4096, 64, 3, 5, {256, 64}},
        {"straddles two atoms", 256, 512, 4096, 64, 60, 8, {256, 128}},
        {"ends exactly at the allocation end", 256, 512, 4096, 64, 500, 12, {704, 64}},
        {"whole size", 256, 512, 4096, 64, 0, VK_WHOLE_SIZE, {256, 512}},
        {"whole size from an unaligned offset", 256, 512, 4096, 64, 100, VK_WHOLE_SIZE, {320, 448}},
        // An allocation whose size is not a multiple of the atom: its last
        // atom is rounded up, no further.
        {"unaligned allocation size", 256, 500, 4096, 64, 490, 10, {704, 64}},
        {"unaligned allocation, whole size", 256, 500, 4096, 64, 0, VK_WHOLE_SIZE, {256, 512}},
        // At the block end the size may stop at the memory's end.
        {"ends at the block end", 4000, 96, 4096, 64, 90, 6, {4032, 64}},
        {"block end not atom-aligned", 4000, 100, 4100, 64, 0, 100, {3968, 132}},
        {"block end not atom-aligned, whole", 4000, 100, 4100, 64, 50, VK_WHOLE_SIZE, {4032, 68}},
        {"dedicated, memory ends mid-atom", 0, 1000, 1000, 256, 999, 1, {768, 232}},
        {"atom of one", 10, 20, 100, 1, 3, 4, {13, 4}},
        {"zero size", 256, 512, 4096, 64, 70, 0, {320, 0}},
        {"first byte of memory", 0, 64, 4096, 64, 0, 1, {0, 64}},
    };
    for (const auto& c : cases) {
        const MemoryRange r =
            mapped_range(c.allocation_offset, c.allocation_size, c.memory_size, c.atom, c.offset, c.size);
        EXPECT_EQ(r.offset, c.expected.offset) << c.name;
        EXPECT_EQ(r.size, c.expected.size) << c.name;
        // Vulkan's rule for VkMappedMemoryRange, and coverage of the bytes.
        EXPECT_EQ(r.offset % c.atom, 0u) << c.name;
        if (r.size != 0) {
            EXPECT_TRUE(r.size % c.atom == 0 || r.offset + r.size == c.memory_size) << c.name;
            const VkDeviceSize begin = c.allocation_offset + c.offset;
            const VkDeviceSize end = c.size == VK_WHOLE_SIZE ? c.allocation_offset + c.allocation_size : begin + c.size;
            EXPECT_LE(r.offset, begin) << c.name;
            EXPECT_GE(r.offset + r.size, end) << c.name;
            EXPECT_LE(r.offset + r.size, c.memory_size) << c.name;
        }
    }
}

static_assert(mapped_range(0, 100, 100, 64, 0, VK_WHOLE_SIZE) == MemoryRange{0, 100});

// ------------------------------------------------------------ memory types

VkPhysicalDeviceMemoryProperties fake_properties() {
    VkPhysicalDeviceMemoryProperties p{};
    p.memoryHeapCount = 2;
    p.memoryHeaps[0] = {8ull << 30, VK_MEMORY_HEAP_DEVICE_LOCAL_BIT};
    p.memoryHeaps[1] = {16ull << 30, 0};
    p.memoryTypeCount = 4;
    p.memoryTypes[0] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0};
    p.memoryTypes[1] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 1};
    p.memoryTypes[2] = {
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT,
        1};
    p.memoryTypes[3] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_PROTECTED_BIT, 0};
    return p;
}

TEST(MemoryType, IntentPicksTheType) {
    const auto p = fake_properties();
    EXPECT_EQ(vkrc::find_memory_type(p, 0xf, {vkrc::MemoryUsage::gpu_only}), 0);
    EXPECT_EQ(vkrc::find_memory_type(p, 0xf, {vkrc::MemoryUsage::upload}), 1);
    EXPECT_EQ(vkrc::find_memory_type(p, 0xf, {vkrc::MemoryUsage::readback}), 2);
    // Only the resource's allowed types count.
    EXPECT_EQ(vkrc::find_memory_type(p, 0b0110, {vkrc::MemoryUsage::gpu_only}), 1);
    EXPECT_EQ(vkrc::find_memory_type(p, 0b0001, {vkrc::MemoryUsage::upload}), -1);
    // Protected memory only when required.
    vkrc::MemoryIntent protected_intent{vkrc::MemoryUsage::custom, VK_MEMORY_PROPERTY_PROTECTED_BIT};
    EXPECT_EQ(vkrc::find_memory_type(p, 0xf, protected_intent), 3);
    EXPECT_EQ(vkrc::find_memory_type(p, 0b1000, {vkrc::MemoryUsage::gpu_only}), -1);
    // A flag no type has.
    vkrc::MemoryIntent lazy{vkrc::MemoryUsage::custom, VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT};
    EXPECT_EQ(vkrc::find_memory_type(p, 0xf, lazy), -1);
    EXPECT_THROW(vkrc::choose_memory_type(p, 0xf, lazy, "test"), vkrc::UsageError);
}

// ------------------------------------------------------------ every allocator

enum class Kind { pool, dedicated, user };

std::string kind_name(const ::testing::TestParamInfo<Kind>& info) {
    switch (info.param) {
        case Kind::pool: return "pool";
        case Kind::dedicated: return "dedicated";
        case Kind::user: return "user";
    }
    return "?";
}

class AllocatorTest : public VulkanTest, public ::testing::WithParamInterface<Kind> {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        switch (GetParam()) {
            case Kind::pool: {
                vkrc::PoolAllocatorCreateInfo info;
                info.min_block_size = 1 * MiB;
                info.max_block_size = 4 * MiB;
                allocator = vkrc::make_allocator<vkrc::PoolAllocator>(info);
                break;
            }
            case Kind::dedicated: allocator = vkrc::make_allocator<vkrc::DedicatedAllocator>(); break;
            case Kind::user: allocator = vkrc::make_allocator<ArenaAllocator>(16 * MiB); break;
        }
    }
    void TearDown() override {
        allocator.reset();
        VulkanTest::TearDown();
    }
    vkrc::Buffer make_buffer(VkDeviceSize size, vkrc::MemoryUsage usage) {
        vkrc::BufferCreateInfo info;
        info.size = size;
        info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
        info.memory.usage = usage;
        info.allocator = allocator;
        return vkrc::Buffer::create(device, info);
    }
    vkrc::DeviceView view() const { return vkrc::DeviceView(*device.state()); }
    vkrc::AllocationRequest request(VkDeviceSize size, vkrc::MemoryUsage usage = vkrc::MemoryUsage::upload) const {
        vkrc::AllocationRequest r;
        r.requirements = {size, 256, 0xffffffffu};
        r.intent.usage = usage;
        return r;
    }

    vkrc::SharedAllocator allocator;
};

TEST_P(AllocatorTest, BufferWriteReadAtAnyAlignment) {
    auto buffer = make_buffer(1000, vkrc::MemoryUsage::upload);
    const auto& memory = buffer.allocation();
    ASSERT_TRUE(memory.host_visible());
    EXPECT_GE(memory.size(), 1000u);
    EXPECT_EQ(&memory.allocator(), allocator.get());
    const std::array<std::uint64_t, 5> values{1, 2, 3, 0x0102030405060708ull, ~0ull};
    // Offset 3: no 8-byte alignment.
    memory.write(3, std::span<const std::uint64_t>(values));
    std::array<std::uint64_t, 5> out{};
    memory.read(3, std::span<std::uint64_t>(out));
    EXPECT_EQ(out, values);
    memory.write_value<std::uint16_t>(999 - 1, 0xbeef);
    EXPECT_EQ(memory.read_value<std::uint16_t>(998), 0xbeef);
    // Zero elements: nothing to do, even at the end.
    memory.write(1000, values.data(), 0);
    vkrc::WriteOnlyView writer;  // kept as a member would be, assigned later
    writer = memory.write_only();
    EXPECT_EQ(writer.size(), memory.size());
    writer.write(11, std::span<const std::uint64_t>(values.data(), 1));
    EXPECT_EQ(memory.read_value<std::uint64_t>(11), 1u);
    // Explicit flushes and invalidations of exact ranges, ends and whole size.
    memory.flush(0, VK_WHOLE_SIZE);
    memory.flush(995, 5);
    memory.flush(memory.size(), VK_WHOLE_SIZE);
    memory.invalidate(7, 3);
    memory.invalidate(0, memory.size());
}

TEST_P(AllocatorTest, WritesOutsideTheAllocationThrow) {
    auto buffer = make_buffer(256, vkrc::MemoryUsage::upload);
    const auto& memory = buffer.allocation();
    std::array<std::uint32_t, 4> values{};
#if VKRC_RUNTIME_CHECKS
    EXPECT_THROW(memory.write(memory.size() - 15, std::span<const std::uint32_t>(values)), vkrc::UsageError);
    EXPECT_THROW(memory.write(memory.size() + 1, values.data(), 0), vkrc::UsageError);
    EXPECT_THROW(memory.read(~VkDeviceSize{0}, values.data(), 1), vkrc::UsageError);
    // size * count overflows: caught before any byte is copied.
    const std::size_t huge = std::numeric_limits<std::size_t>::max() / 4 + 2;
    try {
        memory.write(0, values.data(), huge);
        ADD_FAILURE() << "no throw";
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("overflows"), std::string::npos) << e.what();
    }
    EXPECT_THROW(memory.write_only().write(0, values.data(), huge), vkrc::UsageError);
    // An empty view (a member not yet assigned) has no bytes to write.
    vkrc::WriteOnlyView empty;
    EXPECT_EQ(empty.size(), 0u);
    EXPECT_THROW(empty.write_value(0, values[0]), vkrc::UsageError);
#endif
    EXPECT_THROW(memory.flush(memory.size() + 1, VK_WHOLE_SIZE), vkrc::UsageError);
    EXPECT_THROW(memory.invalidate(memory.size() - 1, 2), vkrc::UsageError);
}

TEST_P(AllocatorTest, GpuOnlyMemoryIsNotForTheHost) {
    auto buffer = make_buffer(256, vkrc::MemoryUsage::gpu_only);
    const auto& memory = buffer.allocation();
    EXPECT_FALSE(memory.host_visible());
    EXPECT_EQ(memory.mapped(), nullptr);
    std::uint32_t v = 1;
    try {
        memory.write_value(0, v);
        ADD_FAILURE() << "no throw";
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("not host-visible"), std::string::npos) << e.what();
    }
    EXPECT_THROW(memory.read(0, &v, 1), vkrc::UsageError);
    EXPECT_THROW((void)memory.write_only(), vkrc::UsageError);
}

TEST_P(AllocatorTest, ZeroSizeRequestsAreRejected) {
    EXPECT_THROW(make_buffer(0, vkrc::MemoryUsage::upload), vkrc::UsageError);
    EXPECT_THROW(allocator->allocate(view(), request(0)), vkrc::UsageError);
}

TEST_P(AllocatorTest, RequestLargerThanTheHeapLeaksNothing) {
    const auto& props = physical_device.memory_properties();
    VkDeviceSize largest = 0;
    for (std::uint32_t i = 0; i < props.memoryHeapCount; ++i) largest = std::max(largest, props.memoryHeaps[i].size);
    const auto before = allocator->statistics(view()).total();
    EXPECT_THROW(allocator->allocate(view(), request(largest + 1)), vkrc::UsageError);
    EXPECT_THROW(vkrc::Allocation::create(device, request(largest + 1), allocator), vkrc::UsageError);
    const auto after = allocator->statistics(view()).total();
    EXPECT_EQ(after.block_count, before.block_count);
    EXPECT_EQ(after.allocation_count, before.allocation_count);
    // Validation reports any leaked object at teardown.
}

TEST_P(AllocatorTest, MissingMemoryTypeIsAClearError) {
    vkrc::BufferCreateInfo info;
    info.size = 64;
    info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.memory = {vkrc::MemoryUsage::custom,
                   VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT};
    info.allocator = allocator;
    try {
        vkrc::Buffer::create(device, info);
        ADD_FAILURE() << "no throw";
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("no memory type"), std::string::npos) << e.what();
    }
    // The VkBuffer made before the allocation failed is destroyed (validation
    // would report it at teardown).
}

TEST_P(AllocatorTest, FreeIntoTheWrongAllocatorThrows) {
    auto other = vkrc::make_allocator<vkrc::DedicatedAllocator>();
    auto mine = allocator->allocate(view(), request(512));
    EXPECT_EQ(mine.allocator, allocator.get());
    EXPECT_THROW(other->free(view(), mine), vkrc::UsageError);
    auto theirs = other->allocate(view(), request(512));
    EXPECT_THROW(allocator->free(view(), theirs), vkrc::UsageError);
    other->free(view(), theirs);
    allocator->free(view(), mine);
    // Used directly, not through a device: the caller releases it.
    allocator->release(view());
}

TEST_P(AllocatorTest, ImagesAndViews) {
    vkrc::ImageCreateInfo info;
    info.format = VK_FORMAT_R8G8B8A8_UNORM;
    info.extent = {64, 32, 1};
    info.mip_levels = 3;
    info.array_layers = 2;
    info.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    info.allocator = allocator;
    auto image = vkrc::Image::create(device, info);
    EXPECT_EQ(image.extent(2).width, 16u);
    EXPECT_EQ(image.extent(2).height, 8u);
    vkrc::ImageViewCreateInfo view_info;
    view_info.view_type = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
    auto view = vkrc::ImageView::create(image, view_info);
    EXPECT_EQ(view.subresource_range().aspectMask, VkImageAspectFlags(VK_IMAGE_ASPECT_COLOR_BIT));
    EXPECT_EQ(view.format(), VK_FORMAT_R8G8B8A8_UNORM);
    // The view keeps the image (and its memory) alive.
    VkImage raw = image.vk();
    image.reset();
    EXPECT_EQ(view.image().vk(), raw);
    EXPECT_TRUE(view.image().allocation());
}

TEST_P(AllocatorTest, BufferViewsAndSamplers) {
    auto buffer = make_buffer(4096, vkrc::MemoryUsage::gpu_only);
    vkrc::BufferViewCreateInfo info;
    info.format = VK_FORMAT_R32_UINT;
    auto view = vkrc::BufferView::create(buffer, info);
    buffer.reset();
    EXPECT_TRUE(view.buffer());
    auto sampler = vkrc::Sampler::create(device, {});
    EXPECT_NE(sampler.vk(), VK_NULL_HANDLE);
}

// Memory is returned only after the GPU work submitted before the drop
// completes: the work, held behind a host-opened gate, copies the dropped
// buffer, and the copy read back afterwards holds what was written into it.
TEST_P(AllocatorTest, MemoryOutlivesPendingGpuWork) {
    vkrc_test::GpuGate gate(device);
    auto buffer = make_buffer(4096, vkrc::MemoryUsage::upload);
    const std::vector<std::uint32_t> words(1024, 0xa110c8edu);
    buffer.allocation().write(0, std::span(words));
    auto readback = vkrc::Buffer::create(
        device,
        {.size = 4096, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    const VkBufferCopy region{0, 0, 4096};
    cmd.copy_buffer(buffer, readback, std::span(&region, 1));
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    gate.submit(queue, cmd, fence);  // pending until the host opens the gate
    buffer.reset();
    EXPECT_EQ(device.deferred_count(), 2u);  // the VkBuffer, then its memory
    if (GetParam() != Kind::user) {
        EXPECT_EQ(allocator->statistics(view()).total().allocation_count, 1u);
    }
    EXPECT_EQ(fence.status(), VK_NOT_READY);
    gate.open();
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    EXPECT_EQ(device.deferred_count(), 0u);
    if (GetParam() != Kind::user) {
        EXPECT_EQ(allocator->statistics(view()).total().allocation_count, 0u);
    } else {
        EXPECT_EQ(static_cast<ArenaAllocator&>(*allocator).frees, 1u);
    }
    std::vector<std::uint32_t> copied(1024);
    readback.allocation().read(0, std::span(copied));
    EXPECT_EQ(copied, words);
}

// The device keeps every allocator used with it, and calls release() at teardown.
TEST_P(AllocatorTest, DeviceReleasesItsAllocatorsAtTeardown) {
    auto buffer = make_buffer(4096, vkrc::MemoryUsage::upload);
    vkrc::SharedAllocator observer = allocator;
    allocator.reset();
    EXPECT_EQ(observer->use_count(), 2u);  // the device holds it
    release_all();
    EXPECT_TRUE(buffer);
    buffer.reset();  // the last handle: the device goes, after its deferred frees
    EXPECT_EQ(observer->use_count(), 1u);
}

// A create-info names its allocator through a view: naming one shared by
// every thread writes no reference count on it (the contention benchmark's
// buffer-pool case); the device keeps it from its first use.
TEST_P(AllocatorTest, CreateInfosNameTheAllocatorWithoutCountingIt) {
    static_assert(std::is_convertible_v<const vkrc::SharedAllocator&, vkrc::AllocatorView>);
    static_assert(!std::is_convertible_v<vkrc::SharedAllocator&&, vkrc::AllocatorView>,
                  "a view of a temporary would dangle in a create-info kept past the statement");
    EXPECT_EQ(allocator->use_count(), 1u);
    auto first = make_buffer(256, vkrc::MemoryUsage::gpu_only);
    EXPECT_EQ(allocator->use_count(), 2u) << "the device keeps the allocator from its first use";
    const vkrc::BufferCreateInfo info{.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .allocator = allocator};
    EXPECT_EQ(allocator->use_count(), 2u) << "the create-info owns no reference";
    auto second = vkrc::Buffer::create(device, info);
    EXPECT_EQ(second.allocation().info().allocator, allocator.get());
    EXPECT_EQ(allocator->use_count(), 2u);
}

TEST_P(AllocatorTest, StatisticsAndBudget) {
    auto a = make_buffer(1000, vkrc::MemoryUsage::upload);
    auto b = make_buffer(3000, vkrc::MemoryUsage::readback);
    const auto stats = allocator->statistics(view());
    EXPECT_EQ(stats.heap_count, physical_device.memory_properties().memoryHeapCount);
    const auto total = stats.total();
    EXPECT_GT(total.budget, 0u);
    if (GetParam() != Kind::user) {
        EXPECT_EQ(total.allocation_count, 2u);
        EXPECT_GE(total.allocation_bytes, 4000u);
        EXPECT_GE(total.block_bytes, total.allocation_bytes);
        EXPECT_GE(total.block_count, 1u);
        EXPECT_GE(stats.vk_allocate_calls, total.block_count);
    }
}

TEST_P(AllocatorTest, BufferUploadAndDownload) {
    auto buffer = make_buffer(1000, vkrc::MemoryUsage::gpu_only);
    std::vector<std::byte> data(333);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = std::byte(i * 7 + 1);
    vkrc::upload_buffer(queue, buffer, 5, data);
    EXPECT_EQ(vkrc::download_buffer(queue, buffer, 5, data.size()), data);
    auto tail = vkrc::download_buffer(queue, buffer, 5 + 330, 3);
    EXPECT_EQ(tail, std::vector<std::byte>(data.end() - 3, data.end()));
    EXPECT_THROW(vkrc::upload_buffer(queue, buffer, 700, data), vkrc::UsageError);
    EXPECT_THROW(vkrc::download_buffer(queue, buffer, 999, 2), vkrc::UsageError);
}

// Every mip level and array layer arrives, through the layout transitions.
TEST_P(AllocatorTest, ImageUploadEveryLevelAndLayer) {
    vkrc::ImageCreateInfo info;
    info.format = VK_FORMAT_R8G8B8A8_UINT;
    info.extent = {37, 20, 1};  // odd sizes: levels 37x20, 18x10, 9x5, 4x2
    info.mip_levels = 4;
    info.array_layers = 3;
    info.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    info.allocator = allocator;
    auto image = vkrc::Image::create(device, info);
    const VkDeviceSize size = vkrc::image_data_size(image);
    EXPECT_EQ(size, (37u * 20 + 18 * 10 + 9 * 5 + 4 * 2) * 4 * 3);
    std::vector<std::byte> data(size);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = std::byte((i * 31) >> 2);
    EXPECT_THROW(vkrc::upload_image(queue, image, std::span(data).first(size - 1)), vkrc::UsageError);
    vkrc::upload_image(queue, image, data, {VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    std::size_t offset = 0;
    for (std::uint32_t level = 0; level < 4; ++level) {
        const auto e = image.extent(level);
        const std::size_t layer_size = std::size_t(e.width) * e.height * 4;
        for (std::uint32_t layer = 0; layer < 3; ++layer) {
            auto got = vkrc::download_image(queue, image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, level, layer);
            ASSERT_EQ(got.size(), layer_size);
            EXPECT_TRUE(std::equal(got.begin(), got.end(), data.begin() + offset))
                << "level " << level << " layer " << layer;
            offset += layer_size;
        }
    }
    // A second upload from the layout the first left.
    std::fill(data.begin(), data.end(), std::byte{0x5a});
    vkrc::upload_image(queue, image, data,
                       {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL});
    auto last = vkrc::download_image(queue, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 3, 2);
    EXPECT_EQ(last, std::vector<std::byte>(4 * 2 * 4, std::byte{0x5a}));
    EXPECT_THROW(vkrc::download_image(queue, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 4, 0), vkrc::UsageError);
}

// lavapipe's memory is coherent; this test marks every memory type
// non-coherent in the physical device's cached properties so that vkrc
// really flushes and invalidates, and records each range it passes to Vulkan.
std::vector<VkMappedMemoryRange> recorded_ranges;
PFN_vkFlushMappedMemoryRanges real_flush = nullptr;
PFN_vkInvalidateMappedMemoryRanges real_invalidate = nullptr;

VKAPI_ATTR VkResult VKAPI_CALL record_flush(VkDevice d, std::uint32_t n, const VkMappedMemoryRange* r) {
    recorded_ranges.insert(recorded_ranges.end(), r, r + n);
    return real_flush(d, n, r);
}
VKAPI_ATTR VkResult VKAPI_CALL record_invalidate(VkDevice d, std::uint32_t n, const VkMappedMemoryRange* r) {
    recorded_ranges.insert(recorded_ranges.end(), r, r + n);
    return real_invalidate(d, n, r);
}

TEST_P(AllocatorTest, NonCoherentFlushesCoverExactlyTheBytes) {
    auto& props = physical_device.state()->memory_properties;
    const auto saved = props;
    for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i) {
        props.memoryTypes[i].propertyFlags &= ~VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    }
    auto& fn = device.state()->fn;
    real_flush = fn.vkFlushMappedMemoryRanges;
    real_invalidate = fn.vkInvalidateMappedMemoryRanges;
    fn.vkFlushMappedMemoryRanges = record_flush;
    fn.vkInvalidateMappedMemoryRanges = record_invalidate;
    const VkDeviceSize atom = physical_device.properties().limits.nonCoherentAtomSize;

    // Checks the ranges recorded since the last call against the bytes
    // [offset, offset + size) of allocation a.
    auto expect_ranges = [&](const vkrc::Allocation& a, VkDeviceSize offset, VkDeviceSize size, const char* what) {
        ASSERT_EQ(recorded_ranges.size(), 1u) << what;
        const auto r = recorded_ranges.front();
        recorded_ranges.clear();
        const auto& info = a.info();
        EXPECT_EQ(r.memory, info.memory) << what;
        EXPECT_EQ(r.offset % atom, 0u) << what;
        const VkDeviceSize end = r.size == VK_WHOLE_SIZE ? info.memory_size : r.offset + r.size;
        EXPECT_TRUE(r.size % atom == 0 || end == info.memory_size) << what;
        EXPECT_LE(r.offset, info.offset + offset) << what;
        EXPECT_GE(end, info.offset + offset + size) << what;
        // Nothing beyond the atoms holding the bytes, nor past the memory.
        EXPECT_LT(info.offset + offset - r.offset, atom) << what;
        EXPECT_LE(end, std::min(info.memory_size, (info.offset + offset + size + atom - 1) / atom * atom)) << what;
    };
    {
        auto buffer = make_buffer(1000, vkrc::MemoryUsage::upload);
        const auto& a = buffer.allocation();
        ASSERT_FALSE(a.host_coherent());
        const std::array<std::uint8_t, 7> bytes{1, 2, 3, 4, 5, 6, 7};
        a.write(3, std::span<const std::uint8_t>(bytes).first(5));
        expect_ranges(a, 3, 5, "unaligned write");
        a.write(a.size() - 7, std::span<const std::uint8_t>(bytes));
        expect_ranges(a, a.size() - 7, 7, "write ending at the allocation end");
        a.flush();
        expect_ranges(a, 0, a.size(), "VK_WHOLE_SIZE");
        a.flush(a.size() - 1, VK_WHOLE_SIZE);
        expect_ranges(a, a.size() - 1, 1, "VK_WHOLE_SIZE from the last byte");
        a.write(atom - 1, bytes.data(), 2);
        expect_ranges(a, atom - 1, 2, "write across an atom boundary");
        try {
            (void)a.write_only();  // its writes are plain copies: coherent memory only
            ADD_FAILURE() << "no throw";
        } catch (const vkrc::UsageError& e) {
            EXPECT_NE(std::string(e.what()).find("not host-coherent"), std::string::npos) << e.what();
        }
        std::array<std::uint8_t, 7> out{};
        a.read(a.size() - 7, std::span<std::uint8_t>(out));
        expect_ranges(a, a.size() - 7, 7, "read at the allocation end");
        EXPECT_EQ(out, bytes);
        a.write(0, bytes.data(), 0);
        EXPECT_TRUE(recorded_ranges.empty()) << "a zero-size write flushes nothing";
    }
    // Ranges that end exactly at the end of their memory: for the pool a
    // fresh block of exactly the request, for the dedicated allocator its own
    // memory, also of a size that is not a multiple of the atom.
    for (VkDeviceSize size : {1 * MiB, 1 * MiB - 100}) {
        vkrc::AllocationRequest r;
        r.requirements = {size, atom, 0xffffffffu};
        r.intent.usage = vkrc::MemoryUsage::upload;
        auto a = vkrc::Allocation::create(device, r, allocator);
        if (GetParam() == Kind::dedicated || (GetParam() == Kind::pool && size == 1 * MiB)) {
            EXPECT_EQ(a.info().offset + size, a.info().memory_size);
        }
        const std::array<std::uint8_t, 3> bytes{9, 8, 7};
        a.write(a.size() - 3, std::span<const std::uint8_t>(bytes));
        expect_ranges(a, a.size() - 3, 3, "write at the block end");
        a.flush(a.size() - 3, VK_WHOLE_SIZE);
        expect_ranges(a, a.size() - 3, 3, "VK_WHOLE_SIZE at the block end");
    }
    queue.wait_idle();
    fn.vkFlushMappedMemoryRanges = real_flush;
    fn.vkInvalidateMappedMemoryRanges = real_invalidate;
    props = saved;
}

INSTANTIATE_TEST_SUITE_P(Allocators, AllocatorTest, ::testing::Values(Kind::pool, Kind::dedicated, Kind::user),
                         kind_name);

// ------------------------------------------------------------ pool specifics

class PoolTest : public VulkanTest {
protected:
    vkrc::DeviceView view() const { return vkrc::DeviceView(*device.state()); }
    static vkrc::AllocationRequest request(VkDeviceSize size, VkDeviceSize alignment = 256) {
        vkrc::AllocationRequest r;
        r.requirements = {size, alignment, 0xffffffffu};
        r.intent.usage = vkrc::MemoryUsage::upload;
        return r;
    }
    static vkrc::PoolAllocatorCreateInfo small_blocks() {
        vkrc::PoolAllocatorCreateInfo info;
        info.min_block_size = 1 * MiB;
        info.max_block_size = 1 * MiB;
        info.dedicated_threshold = 1 * MiB;
        return info;
    }
};

TEST_F(PoolTest, SubAllocatesAndMergesFreedNeighbours) {
    vkrc::PoolAllocator pool(small_blocks());
    auto a = pool.allocate(view(), request(256 * 1024));
    auto b = pool.allocate(view(), request(256 * 1024));
    auto c = pool.allocate(view(), request(256 * 1024));
    EXPECT_EQ(a.memory, b.memory);
    EXPECT_EQ(b.memory, c.memory);
    EXPECT_EQ(a.memory_size, 1 * MiB);
    EXPECT_FALSE(a.dedicated);
    EXPECT_EQ(pool.statistics(view()).vk_allocate_calls, 1u);
    // Ranges do not overlap.
    EXPECT_GE(b.offset, a.offset + a.size);
    EXPECT_GE(c.offset, b.offset + b.size);
    // Free the middle, then its neighbours: the block is one free range again,
    // so a whole-block request fits without a new vkAllocateMemory.
    pool.free(view(), b);
    pool.free(view(), a);
    pool.free(view(), c);
    auto whole = pool.allocate(view(), request(1 * MiB));
    EXPECT_EQ(whole.memory, a.memory);
    EXPECT_EQ(whole.offset, 0u);
    EXPECT_EQ(pool.statistics(view()).vk_allocate_calls, 1u);
    pool.free(view(), whole);
    pool.release(view());
}

// Issue 34: gfxreconstruct's default (page-guard) capture copies each page
// the host wrote to the device at submit, whole, which overwrote GPU-written
// bytes sharing the page (the teapot's frames differed under capture). In
// host-visible memory, upload ranges never share a block with gpu_only or
// readback ones, nor custom ones with either.
TEST_F(PoolTest, HostWrittenAndGpuWrittenRangesNeverShareABlock) {
    const auto& props = physical_device.memory_properties();
    std::uint32_t type = 0;
    while (type < props.memoryTypeCount &&
           !(props.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
        ++type;
    }
    ASSERT_LT(type, props.memoryTypeCount);
    vkrc::PoolAllocator pool(small_blocks());
    const auto allocate = [&](vkrc::MemoryUsage usage) {
        auto r = request(4096);
        r.requirements.memoryTypeBits = 1u << type;  // every usage in the one host-visible type
        r.intent.usage = usage;
        return pool.allocate(view(), r);
    };
    const auto upload = allocate(vkrc::MemoryUsage::upload), upload2 = allocate(vkrc::MemoryUsage::upload);
    const auto gpu = allocate(vkrc::MemoryUsage::gpu_only), readback = allocate(vkrc::MemoryUsage::readback);
    const auto custom = allocate(vkrc::MemoryUsage::custom);
    EXPECT_EQ(upload.memory, upload2.memory);
    EXPECT_EQ(gpu.memory, readback.memory);  // neither is written by the host
    EXPECT_NE(upload.memory, gpu.memory);
    EXPECT_NE(custom.memory, upload.memory);
    EXPECT_NE(custom.memory, gpu.memory);
    EXPECT_EQ(pool.statistics(view()).total().block_count, 3u);
    for (const auto& a : {upload, upload2, gpu, readback, custom}) pool.free(view(), a);
    pool.release(view());
}

TEST_F(PoolTest, HonoursAlignmentAndGranularity) {
    vkrc::PoolAllocator pool(small_blocks());
    const VkDeviceSize granularity = physical_device.properties().limits.bufferImageGranularity;
    std::vector<vkrc::AllocationInfo> all;
    for (VkDeviceSize alignment : {1, 4, 16, 256, 4096, 65536}) {
        auto r = request(100, alignment);
        r.linear = alignment % 2 == 0;
        all.push_back(pool.allocate(view(), r));
        EXPECT_EQ(all.back().offset % alignment, 0u);
        if (granularity <= 4096) EXPECT_EQ(all.back().offset % granularity, 0u);
    }
    for (auto& a : all) pool.free(view(), a);
    pool.release(view());
}

TEST_F(PoolTest, LargeRequestsAreDedicatedAndEmptyBlocksReleased) {
    vkrc::PoolAllocator pool(small_blocks());
    auto big = pool.allocate(view(), request(3 * MiB));  // above dedicated_threshold
    EXPECT_TRUE(big.dedicated);
    EXPECT_EQ(big.offset, 0u);
    pool.free(view(), big);
    EXPECT_EQ(pool.statistics(view()).total().block_count, 0u);
    // Three blocks' worth, then all freed: spare_blocks (two) stay.
    std::vector<vkrc::AllocationInfo> all;
    for (int i = 0; i < 6; ++i) all.push_back(pool.allocate(view(), request(400 * 1024)));
    EXPECT_EQ(pool.statistics(view()).total().block_count, 3u);
    for (auto& a : all) pool.free(view(), a);
    const auto total = pool.statistics(view()).total();
    EXPECT_EQ(total.block_count, 2u);
    EXPECT_EQ(total.allocation_count, 0u);
    EXPECT_EQ(total.allocation_bytes, 0u);
    pool.release(view());
    EXPECT_EQ(pool.statistics(view()).total().block_count, 0u);
}

// Issue 32: the first block of a kind is min_block_size (1 MiB by default,
// cheap to allocate and map at start-up), not a large one.
TEST_F(PoolTest, FirstBlockIsSmall) {
    vkrc::PoolAllocator pool;
    const auto a = pool.allocate(view(), request(4096));
    EXPECT_EQ(a.memory_size, 1 * MiB);
    EXPECT_EQ(pool.statistics(view()).total().block_bytes, 1 * MiB);
    pool.free(view(), a);
    pool.release(view());
}

// The block sizes chosen for a fixed sequence of requests: min_block_size
// doubled until it holds twice the request and an eighth of the pool.
TEST_F(PoolTest, BlocksHoldTwiceTheRequestAndGrowByAnEighth) {
    vkrc::PoolAllocatorCreateInfo info;
    info.min_block_size = 64 * KiB;
    info.max_block_size = 16 * MiB;
    vkrc::PoolAllocator pool(info);
    // 28 KiB ranges: two to a 64 KiB block (twice the request fits) until the
    // pool holds 512 KiB; then a 576 KiB pool's eighth (72 KiB) asks for 128 KiB.
    std::vector<vkrc::AllocationInfo> all;
    std::vector<VkDeviceSize> block_sizes;
    for (int i = 0; i < 20; ++i) {
        all.push_back(pool.allocate(view(), request(28 * KiB)));
        if (i == 0 || all[all.size() - 2].memory != all.back().memory) block_sizes.push_back(all.back().memory_size);
    }
    const std::vector<VkDeviceSize> expected{64 * KiB, 64 * KiB, 64 * KiB, 64 * KiB, 64 * KiB,
                                             64 * KiB, 64 * KiB, 64 * KiB, 64 * KiB, 128 * KiB};
    EXPECT_EQ(block_sizes, expected);
    // A request needs a block of twice its size: 300 KiB gets 1 MiB (the
    // first doubling of 64 KiB to hold 600 KiB), not another 128 KiB.
    all.push_back(pool.allocate(view(), request(300 * KiB)));
    EXPECT_EQ(all.back().memory_size, 1 * MiB);
    EXPECT_EQ(pool.statistics(view()).vk_allocate_calls, 11u);
    for (auto& a : all) pool.free(view(), a);
    pool.release(view());
}

// dedicated_threshold 0 means max_block_size / 2: a request just above it
// has its own VkDeviceMemory, one at it a block of the pool.
TEST_F(PoolTest, DefaultDedicatedThresholdIsHalfTheLargestBlock) {
    vkrc::PoolAllocatorCreateInfo info;
    info.max_block_size = 4 * MiB;
    vkrc::PoolAllocator pool(info);
    const auto at = pool.allocate(view(), request(2 * MiB));
    const auto above = pool.allocate(view(), request(2 * MiB + 256));
    EXPECT_FALSE(at.dedicated);
    EXPECT_EQ(at.memory_size, 4 * MiB);
    EXPECT_TRUE(above.dedicated);
    EXPECT_EQ(above.memory_size, 2 * MiB + 256);
    pool.free(view(), at);
    pool.free(view(), above);
    pool.release(view());
}

// Empty blocks beyond spare_blocks are released, the smallest first.
TEST_F(PoolTest, EmptyBlocksBeyondTheSparesAreReleasedSmallestFirst) {
    for (std::uint32_t spares : {0u, 1u, 2u}) {
        vkrc::PoolAllocatorCreateInfo info;
        info.max_block_size = 4 * MiB;
        info.spare_blocks = spares;
        vkrc::PoolAllocator pool(info);
        const auto small = pool.allocate(view(), request(4096));        // the first block, 1 MiB
        const auto large = pool.allocate(view(), request(1536 * KiB));  // does not fit: a 4 MiB block
        EXPECT_EQ(small.memory_size, 1 * MiB);
        EXPECT_EQ(large.memory_size, 4 * MiB);
        pool.free(view(), small);
        pool.free(view(), large);
        const auto total = pool.statistics(view()).total();
        const VkDeviceSize kept[] = {0, 4 * MiB, 5 * MiB};
        EXPECT_EQ(total.block_bytes, kept[spares]) << spares << " spare blocks";
        // A kept block serves again without a vkAllocateMemory.
        const auto again = pool.allocate(view(), request(4096));
        EXPECT_EQ(pool.statistics(view()).vk_allocate_calls, spares == 0 ? 3u : 2u);
        pool.free(view(), again);
        pool.release(view());
    }
}

TEST_F(PoolTest, ServesOneDeviceAtATime) {
    auto other = vkrc::Device::create(physical_device);
    vkrc::PoolAllocator pool(small_blocks());
    auto a = pool.allocate(view(), request(64));
    EXPECT_THROW(pool.allocate(vkrc::DeviceView(*other.state()), request(64)), vkrc::UsageError);
    pool.free(view(), a);
    pool.release(view());
    auto b = pool.allocate(vkrc::DeviceView(*other.state()), request(64));
    pool.free(vkrc::DeviceView(*other.state()), b);
    pool.release(vkrc::DeviceView(*other.state()));
}

// The device keeps every allocator it allocated through until teardown, so
// that deferred frees still reach them: the first 32 are found without the
// allocator list's lock, the rest under it. 40 allocators, each used twice
// (found the second time), dropped by their maker before their buffers and
// the device: each is released once, after its ranges came back.
TEST_F(PoolTest, DeviceKeepsEveryAllocatorPastTheLockFreeOnes) {
    struct Counts {
        std::atomic<int> allocations{0}, frees{0}, releases{0};
    };
    class Counting final : public vkrc_test::WrappedPoolAllocator {
    public:
        explicit Counting(Counts& counts) : counts_(counts) {}
        vkrc::AllocationInfo allocate(vkrc::DeviceView d, const vkrc::AllocationRequest& r) override {
            ++counts_.allocations;
            return WrappedPoolAllocator::allocate(d, r);
        }
        void free(vkrc::DeviceView d, const vkrc::AllocationInfo& a) override {
            WrappedPoolAllocator::free(d, a);
            ++counts_.frees;
        }
        void release(vkrc::DeviceView d) noexcept override {
            WrappedPoolAllocator::release(d);
            ++counts_.releases;
        }

    private:
        Counts& counts_;
    };
    constexpr int allocators = 40;
    std::vector<Counts> counts(allocators);
    {
        auto other = vkrc::Device::create(physical_device);
        std::vector<vkrc::Buffer> buffers;
        for (int i = 0; i < allocators; ++i) {
            const vkrc::SharedAllocator a = vkrc::make_allocator<Counting>(counts[std::size_t(i)]);
            for (int use = 0; use < 2; ++use) {
                buffers.push_back(vkrc::Buffer::create(
                    other, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .allocator = a}));
            }
        }
        buffers.clear();
        for (const Counts& c : counts) EXPECT_EQ(c.releases.load(), 0) << "released while the device lives";
    }
    for (int i = 0; i < allocators; ++i) {
        const Counts& c = counts[std::size_t(i)];
        EXPECT_EQ(c.allocations.load(), 2) << "allocator " << i;
        EXPECT_EQ(c.frees.load(), 2) << "allocator " << i;
        EXPECT_EQ(c.releases.load(), 1) << "allocator " << i;
    }
}

TEST_F(PoolTest, DefaultAllocatorIsAPool) {
    vkrc::BufferCreateInfo info;
    info.size = 100;
    info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    info.memory.usage = vkrc::MemoryUsage::upload;
    auto a = vkrc::Buffer::create(device, info);
    auto b = vkrc::Buffer::create(device, info);
    EXPECT_NE(dynamic_cast<vkrc::PoolAllocator*>(&vkrc::default_allocator(device)), nullptr);
    EXPECT_EQ(&a.allocation().allocator(), &vkrc::default_allocator(device));
    EXPECT_EQ(a.allocation().memory(), b.allocation().memory());
    const auto total = vkrc::memory_statistics(device).total();
    EXPECT_EQ(total.allocation_count, 2u);
    EXPECT_EQ(total.block_count, 1u);
}

TEST_F(PoolTest, DriverPreferenceForDedicatedMemoryIsHonoured) {
    vkrc::PoolAllocator pool(small_blocks());
    auto r = request(4096);
    r.prefers_dedicated = true;
    auto a = pool.allocate(view(), r);
    EXPECT_TRUE(a.dedicated);
    r.prefers_dedicated = false;
    r.requires_dedicated = true;
    auto b = pool.allocate(view(), r);
    EXPECT_TRUE(b.dedicated);
    r.requires_dedicated = false;
    r.intent.dedicated = true;
    auto c = pool.allocate(view(), r);
    EXPECT_TRUE(c.dedicated);
    EXPECT_EQ(pool.statistics(view()).vk_allocate_calls, 3u);
    for (auto* x : {&a, &b, &c}) pool.free(view(), *x);
    EXPECT_EQ(pool.statistics(view()).total().block_count, 0u);
    pool.release(view());
}

// lavapipe allows 2^32 - 1 allocations; the test lowers the cached limit.
TEST_F(PoolTest, MaxMemoryAllocationCountIsRespected) {
    auto& limits = physical_device.state()->properties.limits;
    const auto saved = limits.maxMemoryAllocationCount;
    limits.maxMemoryAllocationCount = 2;
    vkrc::DedicatedAllocator dedicated;
    auto a = dedicated.allocate(view(), request(64));
    auto b = dedicated.allocate(view(), request(64));
    try {
        dedicated.allocate(view(), request(64));
        ADD_FAILURE() << "no throw";
    } catch (const vkrc::Error& e) {
        EXPECT_EQ(e.result(), VK_ERROR_TOO_MANY_OBJECTS);
    }
    dedicated.free(view(), a);
    dedicated.free(view(), b);

    vkrc::PoolAllocator pool(small_blocks());
    auto x = pool.allocate(view(), request(1 * MiB));  // fills a first block
    auto y = pool.allocate(view(), request(1 * MiB));  // and a second
    EXPECT_THROW(pool.allocate(view(), request(1 * MiB)), vkrc::Error);
    pool.free(view(), x);
    auto z = pool.allocate(view(), request(1000));  // the freed block still serves
    EXPECT_EQ(z.memory, x.memory);
    EXPECT_EQ(pool.statistics(view()).total().block_count, 2u);
    pool.free(view(), y);
    pool.free(view(), z);
    pool.release(view());
    limits.maxMemoryAllocationCount = saved;
}

TEST_F(PoolTest, AdoptedBuffersAndImages) {
    VkBufferCreateInfo b{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    b.size = 256;
    b.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer raw_buffer = VK_NULL_HANDLE;
    ASSERT_EQ(device.fn().vkCreateBuffer(device.vk(), &b, nullptr, &raw_buffer), VK_SUCCESS);
    {
        auto buffer = vkrc::Buffer::adopt(device, raw_buffer, 256, b.usage, vkrc::Ownership::borrowed);
        EXPECT_EQ(buffer.vk(), raw_buffer);
        EXPECT_FALSE(buffer.allocation());
    }
    // Borrowed: still ours to destroy; owned: vkrc destroys it (validation
    // reports a leak or a double destruction otherwise).
    auto owned = vkrc::Buffer::adopt(device, raw_buffer, 256, b.usage, vkrc::Ownership::owned);
    owned.reset();

    vkrc::ImageCreateInfo info;
    info.format = VK_FORMAT_R8G8B8A8_UNORM;
    info.extent = {16, 16, 1};
    info.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    auto made = vkrc::Image::create(device, info);
    {
        // A second, borrowed wrapper of the same VkImage (as for swapchain images).
        auto borrowed = vkrc::Image::adopt(device, made.vk(), info, vkrc::Ownership::borrowed);
        auto view = vkrc::ImageView::create(borrowed);
        EXPECT_EQ(view.image().extent().width, 16u);
    }
    EXPECT_THROW(vkrc::Image::adopt(device, VK_NULL_HANDLE, info, vkrc::Ownership::borrowed), vkrc::UsageError);
}

TEST_F(PoolTest, ShardsAreCheckedAndResolved) {
    vkrc::PoolAllocatorCreateInfo info;
    info.shards = vkrc::max_pool_shards + 1;
    try {
        vkrc::PoolAllocator pool(info);
        ADD_FAILURE() << "no throw";
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("shards"), std::string::npos) << e.what();
    }
    info.shards = 3;
    EXPECT_EQ(vkrc::PoolAllocator(info).shard_count(), VKRC_IS_MULTI_THREAD ? 3u : 1u);
    info.shards = 0;
    const auto resolved = vkrc::PoolAllocator(info).shard_count();
    EXPECT_GE(resolved, 1u);
    EXPECT_LE(resolved, VKRC_IS_MULTI_THREAD ? 8u : 1u);
}

#if VKRC_IS_MULTI_THREAD
// Runs body(t) on thread_count threads at once.
template <class Body>
void on_threads(int thread_count, Body body) {
    std::vector<std::thread> threads;
    for (int t = 0; t < thread_count; ++t) threads.emplace_back(body, t);
    for (auto& th : threads) th.join();
}

// Eight threads allocate and free at once through a pool of four shards,
// then each frees another's ranges; the statistics must count exactly the
// live ranges throughout, and only one spare block per shard may remain.
TEST_F(PoolTest, ShardedConcurrentAllocateAndFree) {
    auto info = small_blocks();
    info.shards = 4;
    vkrc::PoolAllocator pool(info);
    ASSERT_EQ(pool.shard_count(), 4u);
    constexpr int thread_count = 8;
    std::vector<std::vector<vkrc::AllocationInfo>> live(thread_count);
    const auto seed = vkrc_test::test_seed();
    on_threads(thread_count, [&](int t) {
        std::mt19937 rng(seed + static_cast<unsigned>(t));
        auto& mine = live[static_cast<std::size_t>(t)];
        for (int i = 0; i < 1000; ++i) {
            if (mine.size() < 24 && (rng() % 3 != 0 || mine.empty())) {
                // Now and then one above dedicated_threshold.
                const VkDeviceSize size = rng() % 40 == 0 ? 2 * MiB : 64 + rng() % 100000;
                mine.push_back(pool.allocate(view(), request(size, VkDeviceSize{1} << (rng() % 10))));
            } else {
                const auto k = static_cast<std::ptrdiff_t>(rng() % mine.size());
                pool.free(view(), mine[static_cast<std::size_t>(k)]);
                mine.erase(mine.begin() + k);
            }
        }
    });
    std::vector<vkrc::AllocationInfo> all;
    for (auto& mine : live) all.insert(all.end(), mine.begin(), mine.end());
    std::sort(all.begin(), all.end(), [](const auto& x, const auto& y) {
        return x.memory != y.memory ? x.memory < y.memory : x.offset < y.offset;
    });
    VkDeviceSize bytes = 0;
    std::set<VkDeviceMemory> memories;
    for (std::size_t i = 0; i < all.size(); ++i) {
        bytes += all[i].size;
        memories.insert(all[i].memory);
        if (i > 0 && all[i].memory == all[i - 1].memory) {
            EXPECT_LE(all[i - 1].offset + all[i - 1].size, all[i].offset) << "overlapping ranges";
        }
    }
    auto total = pool.statistics(view()).total();
    EXPECT_EQ(total.allocation_count, all.size());
    EXPECT_GE(total.allocation_bytes, bytes);
    // Every block in use holds a live range; spare_blocks per shard may be empty.
    EXPECT_GE(total.block_count, memories.size());
    EXPECT_LE(total.block_count, memories.size() + info.spare_blocks * pool.shard_count());

    on_threads(thread_count, [&](int t) {
        for (auto& a : live[static_cast<std::size_t>((t + 1) % thread_count)]) pool.free(view(), a);
    });
    total = pool.statistics(view()).total();
    EXPECT_EQ(total.allocation_count, 0u);
    EXPECT_EQ(total.allocation_bytes, 0u);
    EXPECT_LE(total.block_count, info.spare_blocks * pool.shard_count());
    EXPECT_EQ(total.block_bytes, total.block_count * MiB);
    EXPECT_GE(pool.statistics(view()).vk_allocate_calls, memories.size());
    pool.release(view());
    EXPECT_EQ(pool.statistics(view()).total().block_count, 0u);
}

// A range freed by another thread goes back to the shard that made it: the
// maker's next range is the same one, and the other thread's shard has a
// block of its own.
TEST_F(PoolTest, FreeFromAnotherThreadGoesBackToItsShard) {
    auto info = small_blocks();
    info.shards = 2;
    vkrc::PoolAllocator pool(info);
    vkrc::AllocationInfo a, b, again;
    std::latch a_made(1), a_freed(1);
    std::thread maker([&] {
        a = pool.allocate(view(), request(4096));
        a_made.count_down();
        a_freed.wait();
        again = pool.allocate(view(), request(4096));
    });
    a_made.wait();
    // The next thread to allocate gets the other home shard.
    std::thread other([&] {
        b = pool.allocate(view(), request(4096));
        pool.free(view(), a);
    });
    other.join();
    a_freed.count_down();
    maker.join();
    EXPECT_NE(b.memory, a.memory);
    EXPECT_EQ(again.memory, a.memory);
    EXPECT_EQ(again.offset, a.offset);
    const auto stats = pool.statistics(view());
    EXPECT_EQ(stats.vk_allocate_calls, 2u);
    EXPECT_EQ(stats.total().block_count, 2u);
    EXPECT_EQ(stats.total().allocation_count, 2u);
    pool.free(view(), again);
    pool.free(view(), b);
    pool.release(view());
}

// Eight threads allocate and free at once through one pool (run under TSan).
TEST_F(PoolTest, ConcurrentAllocateAndFree) {
    vkrc::PoolAllocatorCreateInfo info;
    info.min_block_size = 1 * MiB;
    info.max_block_size = 4 * MiB;
    info.shards = 4;
    auto pool = vkrc::make_allocator<vkrc::PoolAllocator>(info);
    std::vector<std::thread> threads;
    const auto seed = vkrc_test::test_seed();
    for (int t = 0; t < 8; ++t) {
        threads.emplace_back([&, t] {
            std::mt19937 rng(seed + static_cast<unsigned>(t));
            std::vector<vkrc::Allocation> live;
            for (int i = 0; i < 300; ++i) {
                if (live.size() < 16 && (rng() % 3 != 0 || live.empty())) {
                    auto r = request(64 + rng() % 100000, VkDeviceSize{1} << (rng() % 10));
                    live.push_back(vkrc::Allocation::create(device, r, pool));
                    live.back().write_value<std::uint32_t>(0, std::uint32_t(t));
                } else {
                    std::size_t k = rng() % live.size();
                    EXPECT_EQ(live[k].read_value<std::uint32_t>(0), std::uint32_t(t));
                    live.erase(live.begin() + k);
                }
            }
        });
    }
    for (auto& th : threads) th.join();
    const auto total = pool->statistics(view()).total();
    EXPECT_EQ(total.allocation_count, 0u);
    EXPECT_LE(total.block_count, info.spare_blocks * pool->shard_count());  // the spares of each shard at most
}
#endif

}  // namespace
