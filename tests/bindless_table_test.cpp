// vkrc::BindlessTable (issue 30): slots handed out and taken back, a removed
// slot reused only once the GPU is done with it, clear errors for misuse,
// and adds and removes from several threads under the multi-thread policy.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/bindless_table.comp.h"

#include <cstdio>
#include <cstdlib>
#include <atomic>
#include <functional>
#include <mutex>
#include <map>
#include <random>
#include <span>
#include <thread>
#include <vector>

namespace {

using vkrc_test::VulkanTest;

std::string missing_table_features(const vkrc::PhysicalDevice& physical) {
    const auto f = vkrc_test::supported_features(physical).v12;
    return vkrc_test::missing_features({
        {"runtimeDescriptorArray", f.runtimeDescriptorArray},
        {"descriptorBindingPartiallyBound", f.descriptorBindingPartiallyBound},
        {"descriptorBindingSampledImageUpdateAfterBind", f.descriptorBindingSampledImageUpdateAfterBind},
        {"descriptorBindingStorageBufferUpdateAfterBind", f.descriptorBindingStorageBufferUpdateAfterBind},
        {"descriptorBindingUpdateUnusedWhilePending", f.descriptorBindingUpdateUnusedWhilePending},
    });
}

class BindlessTableTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (auto missing = missing_table_features(physical_device); !missing.empty())
            GTEST_SKIP() << "the device lacks descriptor indexing features: " << missing;
        vkrc::DeviceCreateInfo info;
        info.enabled_features.shaderSampledImageArrayDynamicIndexing = VK_TRUE;
        info.enabled_features.shaderStorageBufferArrayDynamicIndexing = VK_TRUE;
        info.vulkan12_features.runtimeDescriptorArray = VK_TRUE;
        info.vulkan12_features.descriptorBindingPartiallyBound = VK_TRUE;
        info.vulkan12_features.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
        info.vulkan12_features.descriptorBindingStorageBufferUpdateAfterBind = VK_TRUE;
        info.vulkan12_features.descriptorBindingUpdateUnusedWhilePending = VK_TRUE;
        device = vkrc::Device::create(physical_device, info);
        queue = device.default_queue();
        sampler = vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST,
                                                 .min_filter = VK_FILTER_NEAREST,
                                                 .mipmap_mode = VK_SAMPLER_MIPMAP_MODE_NEAREST});
    }
    void TearDown() override {
        sampler.reset();
        VulkanTest::TearDown();
    }

    // A 1x1 R32_UINT texture holding value, cleared by cmd before a compute read.
    vkrc::ImageView texture(const vkrc::CommandBuffer& cmd, std::uint32_t value) const {
        auto image = vkrc_test::uint_image(device, cmd, value, VK_IMAGE_USAGE_SAMPLED_BIT,
                                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        return vkrc::ImageView::create(image);
    }
    vkrc::Buffer readback(std::uint32_t words) const {
        return vkrc::Buffer::create(device, {.size = words * sizeof(std::uint32_t),
                                             .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                             .memory = {.usage = vkrc::MemoryUsage::readback}});
    }

    vkrc::Sampler sampler;
};

// shaders/bindless_table.comp's push constants.
struct Params {
    std::uint32_t out_index = 0;
    std::uint32_t base = 0;
    std::uint32_t count = 0;
    std::uint32_t texture[4] = {};
};

struct TablePipeline {
    vkrc::PipelineLayout layout;
    vkrc::ComputePipeline pipeline;
};

TablePipeline table_pipeline(const vkrc::Device& device, const vkrc::BindlessTable& table) {
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.set_layouts = {table.layout()}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Params)}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::bindless_table_comp));
    return {layout, pipeline};
}

void record_read(const vkrc::CommandBuffer& cmd, const TablePipeline& p, const vkrc::BindlessTable& table,
                 const Params& params) {
    cmd.bind_pipeline(p.pipeline);
    cmd.bind_descriptor_set(p.pipeline, 0, table.set());
    cmd.push_constants(p.layout.vk(), VK_SHADER_STAGE_COMPUTE_BIT, params);
    cmd.dispatch(1);
}

std::string usage_error(const std::function<void()>& f) {
    try {
        f();
    } catch (const vkrc::UsageError& e) {
        return e.what();
    }
    return "no UsageError";
}

TEST_F(BindlessTableTest, AddedObjectsAreReadThroughTheirIndexAfterTheirHandlesAreGone) {
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = 8, .buffer_capacity = 2});
    auto p = table_pipeline(device, table);
    auto out = readback(4);
    const auto out_index = table.add(out);
    vkrc_test::OneShotCommands s(queue);
    Params params{.out_index = out_index.index, .count = 4};
    for (std::uint32_t k = 0; k < 4; ++k) {
        const auto index = table.add(texture(s.cmd, 50 + k), sampler);  // the table holds the only reference
        EXPECT_EQ(index.kind, vkrc::BindlessKind::image);
        params.texture[k] = index.index;
    }
    EXPECT_EQ(table.live_count(vkrc::BindlessKind::image), 4u);
    record_read(s.cmd, p, table, params);
    const auto to_host = vkrc_test::compute_to_host();
    s.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    s.run(queue);
    std::uint32_t data[4] = {};
    out.allocation().read(0, data, 4);
    for (std::uint32_t k = 0; k < 4; ++k) EXPECT_EQ(data[k], 50 + k);
}

// A removed slot is not handed out while gated work that could read it is
// in flight; once the GPU is done it is reused.
TEST_F(BindlessTableTest, ARemovedSlotIsReusedOnlyAfterTheGpuFinished) {
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = 2, .buffer_capacity = 1});
    auto p = table_pipeline(device, table);
    auto out = readback(1);
    const auto out_index = table.add(out);
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto fence = vkrc::Fence::create(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    const auto first = table.add(texture(cmd, 77), sampler);
    record_read(cmd, p, table, {.out_index = out_index.index, .count = 1, .texture = {first.index}});
    const auto to_host = vkrc_test::compute_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    const vkrc::SemaphoreSubmit wait(gate, 1);
    vkrc::submit(queue, {.waits = std::span(&wait, 1), .command_buffers = std::span(&cmd, 1)}, fence);
    table.remove(first);
    EXPECT_EQ(table.pending_count(vkrc::BindlessKind::image), 1u);
    vkrc_test::OneShotCommands s(queue);
    const auto second = table.add(texture(s.cmd, 1), sampler);
    EXPECT_NE(second.index, first.index) << "the removed slot was handed out while gated work may read it";
    EXPECT_EQ(usage_error([&] { table.add(texture(s.cmd, 2), sampler); }),
              "vkrc::BindlessTable::add: the table is full: 1 image slots in use and 1 removed ones waiting for the "
              "GPU of 2");
    gate.signal(1);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    std::uint32_t value = 0;
    out.allocation().read(0, &value, 1);
    EXPECT_EQ(value, 77u) << "the removed texture stayed alive for the gated read";
    const auto third = table.add(texture(s.cmd, 3), sampler);
    EXPECT_EQ(third.index, first.index) << "the slot is reused once the GPU is done";
    EXPECT_EQ(table.pending_count(vkrc::BindlessKind::image), 0u);
    s.run(queue);
}

TEST_F(BindlessTableTest, MisuseIsAUsageError) {
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = 2, .buffer_capacity = 1});
    auto other = vkrc::BindlessTable::create(device, {.image_capacity = 2, .buffer_capacity = 0});
    std::vector<vkrc::ImageView> views;
    {
        vkrc_test::OneShotCommands s(queue);
        for (std::uint32_t k = 0; k < 3; ++k) views.push_back(texture(s.cmd, k));
        s.run(queue);
    }
    const auto a = table.add(views[0], sampler);
    EXPECT_EQ(usage_error([&] { other.remove(a); }), "vkrc::BindlessTable::remove: the index belongs to another table");
    EXPECT_EQ(usage_error([&] { table.remove(vkrc::BindlessIndex{}); }),
              "vkrc::BindlessTable::remove: the index belongs to another table");
    auto forged = a;
    forged.index = 1;
    EXPECT_EQ(usage_error([&] { table.remove(forged); }),
              "vkrc::BindlessTable::remove: image index 1 was never handed out by this table");
    table.remove(a);
    EXPECT_EQ(usage_error([&] { table.remove(a); }), "vkrc::BindlessTable::remove: image index 0 was already removed");
    EXPECT_EQ(table.pending_count(vkrc::BindlessKind::image), 0u) << "nothing in flight: the slot is back at once";
    const auto b = table.add(views[1], sampler);
    const auto c = table.add(views[2], sampler);
    EXPECT_TRUE(b.index == a.index || c.index == a.index);
    EXPECT_EQ(usage_error([&] { table.remove(a); }),
              "vkrc::BindlessTable::remove: image index 0 is stale: its slot was removed and handed out again");
    EXPECT_EQ(usage_error([&] { table.add(views[0], sampler); }),
              "vkrc::BindlessTable::add: the table is full: 2 image slots in use and 0 removed ones waiting for the "
              "GPU of 2");
    EXPECT_EQ(usage_error([&] { other.add(readback(1)); }),
              "vkrc::BindlessTable::add: the table holds no buffer descriptors (its buffer_capacity is 0)");
    EXPECT_EQ(usage_error([&] { table.add(vkrc::ImageView{}, sampler); }),
              "vkrc::BindlessTable::add: the ImageView handle is empty");
    const auto limit = vkrc::BindlessTable::max_capacity(device, vkrc::BindlessKind::buffer);
    if (limit != UINT32_MAX) {
        EXPECT_NE(usage_error([&] {
                      vkrc::BindlessTable::create(device, {.image_capacity = 0, .buffer_capacity = limit + 1});
                  }).find("is more than the device allows"),
                  std::string::npos);
    }
}

// 500 rounds, up to 3 frames in flight: each round adds and removes random
// textures (the test keeps a handle to some, drops others at once), then
// records a read of up to four live ones. A frame's results are checked when
// its fence is waited for: a slot reused while a frame could still read it
// would show another texture's value.
TEST_F(BindlessTableTest, FuzzAddRemoveReuseWithFramesInFlight) {
    const std::uint32_t seed = vkrc_test::test_seed();
    std::mt19937 rng(seed);
    constexpr std::uint32_t capacity = 24, frames = 3, rounds = 500;
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = capacity, .buffer_capacity = frames});
    auto p = table_pipeline(device, table);
    auto pool = vkrc::CommandPool::create(
        device, {.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, .queue_family_index = queue.family_index()});
    struct Frame {
        vkrc::CommandBuffer cmd;
        vkrc::Fence fence;
        vkrc::Buffer out;
        vkrc::BindlessIndex out_index;
        std::vector<std::uint32_t> expected;
        bool submitted = false;
    };
    std::vector<Frame> ring(frames);
    for (auto& f : ring) {
        f.cmd = pool.allocate();
        f.fence = vkrc::Fence::create(device);
        f.out = readback(4);
        f.out_index = table.add(f.out);
    }
    struct Live {
        vkrc::BindlessIndex index;
        std::uint32_t value;
        vkrc::ImageView kept;  // empty: the table holds the only reference
    };
    std::vector<Live> live;
    std::uint32_t next_value = 1000, checked = 0, full = 0;
    for (std::uint32_t round = 0; round < rounds; ++round) {
        auto& f = ring[round % frames];
        if (f.submitted) {
            ASSERT_EQ(f.fence.wait(), VK_SUCCESS);
            std::uint32_t data[4] = {};
            f.out.allocation().read(0, data, f.expected.size());
            for (std::size_t i = 0; i < f.expected.size(); ++i)
                ASSERT_EQ(data[i], f.expected[i]) << "seed " << seed << " round " << round << " read " << i;
            checked += static_cast<std::uint32_t>(f.expected.size());
            f.fence.unsignal();
        }
        f.cmd.begin();
        const std::uint32_t removes = rng() % 4;
        for (std::uint32_t r = 0; r < removes && !live.empty(); ++r) {
            const std::size_t i = rng() % live.size();
            table.remove(live[i].index);
            live.erase(live.begin() + static_cast<std::ptrdiff_t>(i));
        }
        const std::uint32_t adds = rng() % 4;
        for (std::uint32_t a = 0; a < adds; ++a) {
            auto view = texture(f.cmd, next_value);
            try {
                const auto index = table.add(view, sampler);
                for (const auto& l : live) ASSERT_NE(l.index.index, index.index) << "seed " << seed;
                live.push_back({index, next_value++, rng() % 2 ? view : vkrc::ImageView{}});
            } catch (const vkrc::UsageError&) {
                ++full;  // every slot live or waiting for the frames in flight
            }
        }
        if (rng() % 8 == 0) {
            for (auto& l : live) l.kept.reset();  // random drops of the test's own handles
        }
        Params params{.out_index = f.out_index.index};
        f.expected.clear();
        for (std::uint32_t k = 0; k < 4 && k < live.size(); ++k) {
            const auto& l = live[rng() % live.size()];
            params.texture[params.count++] = l.index.index;
            f.expected.push_back(l.value);
        }
        if (params.count != 0) record_read(f.cmd, p, table, params);
        const auto to_host = vkrc_test::compute_to_host();
        f.cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
        f.cmd.end();
        vkrc::submit(queue, {.command_buffers = std::span(&f.cmd, 1)}, f.fence);
        f.submitted = true;
    }
    device.wait_idle();
    std::printf("bindless table fuzz: %u reads checked, %u adds refused as full\n", checked, full);
    EXPECT_GT(checked, rounds);
}

#if VKRC_IS_MULTI_THREAD
// Adds and removes from four threads at once (TSan runs this): every index
// handed out is unique among the live ones, and the counts add up.
TEST_F(BindlessTableTest, AddsAndRemovesFromSeveralThreads) {
    constexpr std::uint32_t threads = 4, per_thread = 200;
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = 64, .buffer_capacity = 64});
    std::vector<vkrc::Buffer> buffers;
    for (std::uint32_t i = 0; i < threads; ++i) buffers.push_back(readback(1));
    std::vector<std::thread> workers;
    std::atomic<bool> duplicate{false};
    std::mutex owners_mutex;
    std::map<std::uint32_t, std::uint32_t> owners;  // live index -> thread
    for (std::uint32_t t = 0; t < threads; ++t) {
        workers.emplace_back([&, t] {
            std::vector<vkrc::BindlessIndex> mine;
            for (std::uint32_t i = 0; i < per_thread; ++i) {
                const auto index = table.add(buffers[t]);
                {
                    std::lock_guard lock(owners_mutex);
                    if (!owners.emplace(index.index, t).second) duplicate = true;
                }
                mine.push_back(index);
                if (mine.size() > 8) {
                    {
                        std::lock_guard lock(owners_mutex);
                        owners.erase(mine.front().index);
                    }
                    table.remove(mine.front());
                    mine.erase(mine.begin());
                }
            }
        });
    }
    for (auto& w : workers) w.join();
    EXPECT_FALSE(duplicate.load());
    EXPECT_EQ(table.live_count(vkrc::BindlessKind::buffer), threads * 8);  // each keeps its last 8
}
#endif

}  // namespace
