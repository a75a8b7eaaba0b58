// The cost of descriptor writes with references counted (issue 30): one
// storage-buffer write and a 1000-slot update of combined image samplers,
// vkrc against the raw vkUpdateDescriptorSets a C program makes, on the same
// device, set and objects. Each case runs its operation --reps times per
// block, --blocks blocks, cases interleaved; ns per operation is the median
// block's. Under callgrind (bench/descriptors_run.sh) each case's operations
// are also collected alone and dumped once per case, so the script gets
// instructions per operation (deterministic where timers are noise).
//
// Cases (an operation each):
//   raw-write1       vkUpdateDescriptorSets, one VkWriteDescriptorSet, one buffer
//   vkrc-write1      DescriptorSet::write_buffer (counts the buffer, releases the old one)
//   raw-update1000   one vkUpdateDescriptorSets of 1000 image descriptors
//   vkrc-update1000  DescriptorSet::write_images of the same 1000
//   vkrc-table1000   BindlessTable: 1000 add() then 1000 remove() (nothing in flight)
//
// Usage: descriptors [--blocks N] [--reps N] [--csv PATH]
#include <vkrc/vkrc.hpp>

#include <valgrind/callgrind.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace {

constexpr std::uint32_t slots = 1000;

struct Case {
    const char* name;
    std::function<void()> op;
    std::vector<double> ns;  // per operation, one per block
};

struct Options {
    int blocks = 21;
    int reps = 200;
    std::string csv;
};

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--blocks")) o.blocks = std::max(1, std::atoi(argv[i + 1]));
        else if (!std::strcmp(argv[i], "--reps")) o.reps = std::max(1, std::atoi(argv[i + 1]));
        else if (!std::strcmp(argv[i], "--csv")) o.csv = argv[i + 1];
    }
    return o;
}

vkrc::Device make_device(const vkrc::Instance& instance) {
    auto physical = vkrc::PhysicalDevice::select(instance, {});
    vkrc::DeviceCreateInfo info;
    info.vulkan12_features.descriptorBindingPartiallyBound = VK_TRUE;
    info.vulkan12_features.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
    info.vulkan12_features.descriptorBindingStorageBufferUpdateAfterBind = VK_TRUE;
    info.vulkan12_features.descriptorBindingUpdateUnusedWhilePending = VK_TRUE;
    return vkrc::Device::create(physical, info);
}

// Runs op reps times in a block, blocks times, and under callgrind collects
// the first block alone and dumps it as the case's name.
void measure(std::vector<Case>& cases, const Options& o) {
    for (auto& c : cases) {
        c.op();  // warm: first writes allocate the set's references
        if (RUNNING_ON_VALGRIND) {
            CALLGRIND_ZERO_STATS;
            CALLGRIND_TOGGLE_COLLECT;
            for (int r = 0; r < o.reps; ++r) c.op();
            CALLGRIND_TOGGLE_COLLECT;
            CALLGRIND_DUMP_STATS_AT(c.name);
        }
    }
    if (RUNNING_ON_VALGRIND) return;
    for (int b = 0; b < o.blocks; ++b) {
        for (auto& c : cases) {
            const auto start = std::chrono::steady_clock::now();
            for (int r = 0; r < o.reps; ++r) c.op();
            const std::chrono::duration<double, std::nano> took = std::chrono::steady_clock::now() - start;
            c.ns.push_back(took.count() / o.reps);
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);
    auto instance = vkrc::Instance::create({.application_name = "vkrc descriptors bench"});
    auto device = make_device(instance);
    std::printf("device: %s; reps %d, blocks %d\n", device.physical_device().name(), o.reps, o.blocks);

    auto buffer_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    auto image_layout = vkrc::DescriptorSetLayout::create(
        device,
        {.bindings = {
             {.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .descriptor_count = slots}}});
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 4,
                                              .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2},
                                                             {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2 * slots}}});
    auto raw_buffer_set = pool.allocate(buffer_layout);
    auto buffer_set = pool.allocate(buffer_layout);
    auto raw_image_set = pool.allocate(image_layout);
    auto image_set = pool.allocate(image_layout);
    auto buffer = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto view = vkrc::ImageView::create(image);
    auto sampler = vkrc::Sampler::create(device, {});
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = slots, .buffer_capacity = 1});
    const std::vector<VkDescriptorImageInfo> infos(slots,
                                                   {sampler.vk(), view.vk(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    std::vector<vkrc::BindlessIndex> indices(slots);

    const VkDevice raw_device = device.vk();
    const auto update = device.fn().vkUpdateDescriptorSets;
    const VkDescriptorBufferInfo buffer_info{buffer.vk(), 0, VK_WHOLE_SIZE};
    std::vector<Case> cases;
    cases.push_back({"raw-write1",
                     [&] {
                         VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
                         w.dstSet = raw_buffer_set.vk();
                         w.descriptorCount = 1;
                         w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
                         w.pBufferInfo = &buffer_info;
                         update(raw_device, 1, &w, 0, nullptr);
                     },
                     {}});
    cases.push_back(
        {"vkrc-write1", [&] { buffer_set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer); }, {}});
    cases.push_back({"raw-update1000",
                     [&] {
                         VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
                         w.dstSet = raw_image_set.vk();
                         w.descriptorCount = slots;
                         w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
                         w.pImageInfo = infos.data();
                         update(raw_device, 1, &w, 0, nullptr);
                     },
                     {}});
    cases.push_back(
        {"vkrc-update1000", [&] { image_set.write_images(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, infos); }, {}});
    cases.push_back({"vkrc-table1000",
                     [&] {
                         for (auto& index : indices) index = table.add(view, sampler);
                         for (const auto& index : indices) table.remove(index);
                     },
                     {}});
    measure(cases, o);
    if (RUNNING_ON_VALGRIND) return 0;

    std::FILE* csv = o.csv.empty() ? nullptr : std::fopen(o.csv.c_str(), "w");
    if (csv) std::fprintf(csv, "case,reps,blocks,ns_per_op_median,ns_per_op_min\n");
    for (auto& c : cases) {
        std::sort(c.ns.begin(), c.ns.end());
        const std::size_t n = c.ns.size();  // an even count's median is the mean of the middle two
        const double median = n % 2 ? c.ns[n / 2] : (c.ns[n / 2 - 1] + c.ns[n / 2]) / 2;
        std::printf("%-16s %12.0f ns per operation (median of %d blocks, min %.0f)\n", c.name, median, o.blocks,
                    c.ns.front());
        if (csv) std::fprintf(csv, "%s,%d,%d,%.1f,%.1f\n", c.name, o.reps, o.blocks, median, c.ns.front());
    }
    if (csv) std::fclose(csv);
    return 0;
}
