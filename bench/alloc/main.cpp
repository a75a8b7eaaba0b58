// Allocation benchmark: replays one fixed pseudo-random pattern of allocations
// and frees (256 B to 16 MiB, log-uniform, half buffers and half optimal-tiling
// images) against the DedicatedAllocator and the PoolAllocator through the
// DeviceAllocator interface, and reports allocate+free pairs per second, the
// number of vkAllocateMemory calls, and peak bytes reserved vs requested.
//
// Usage: alloc [--ops N] [--dedicated-ops N] [--live N] [--seed N] [--csv PATH]
// Defaults: 100000 allocations (each freed) for both allocators, at most 512 live, seed 1.
#include <vkrc/vkrc.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

struct Step {
    bool allocate;
    std::size_t slot;     // which live slot is allocated into or freed
    std::size_t request;  // index into the request table (allocations only)
};

struct Pattern {
    std::vector<vkrc::AllocationRequest> requests;
    std::vector<Step> steps;
    std::size_t slots = 0;
    std::size_t allocations = 0;
};

// live: the most allocations alive at once. Each step allocates or frees a
// random live allocation; all are freed at the end.
Pattern make_pattern(const vkrc::Device& device, std::size_t operations, std::size_t live, std::uint32_t seed) {
    Pattern p;
    p.slots = live;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> log_size(std::log2(256.0), std::log2(16.0 * 1024 * 1024));
    std::vector<std::size_t> live_slots, free_slots;
    for (std::size_t i = live; i-- > 0;) free_slots.push_back(i);
    while (p.allocations < operations) {
        // A random walk between half the live target and the target: a
        // program that keeps loading and dropping resources.
        const bool allocate = !free_slots.empty() && (live_slots.size() < live / 2 || rng() % 2 == 0);
        if (allocate) {
            const auto size = static_cast<VkDeviceSize>(std::exp2(log_size(rng)));
            vkrc::AllocationRequest r;
            r.intent.usage = rng() % 4 == 0 ? vkrc::MemoryUsage::upload : vkrc::MemoryUsage::gpu_only;
            VkMemoryRequirements2 req{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
            if (rng() % 2 == 0) {
                VkBufferCreateInfo b{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
                b.size = size;
                b.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
                VkDeviceBufferMemoryRequirements q{VK_STRUCTURE_TYPE_DEVICE_BUFFER_MEMORY_REQUIREMENTS, nullptr, &b};
                device.fn().vkGetDeviceBufferMemoryRequirements(device.vk(), &q, &req);
                r.linear = true;
            } else {
                const auto side = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::sqrt(double(size) / 4)));
                VkImageCreateInfo i{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
                i.imageType = VK_IMAGE_TYPE_2D;
                i.format = VK_FORMAT_R8G8B8A8_UNORM;
                i.extent = {side, side, 1};
                i.mipLevels = 1;
                i.arrayLayers = 1;
                i.samples = VK_SAMPLE_COUNT_1_BIT;
                i.tiling = VK_IMAGE_TILING_OPTIMAL;
                i.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
                VkDeviceImageMemoryRequirements q{VK_STRUCTURE_TYPE_DEVICE_IMAGE_MEMORY_REQUIREMENTS, nullptr, &i};
                device.fn().vkGetDeviceImageMemoryRequirements(device.vk(), &q, &req);
                r.linear = false;
                // Discrete GPUs offer no host-visible type for optimal-tiling images.
                r.intent.usage = vkrc::MemoryUsage::gpu_only;
            }
            r.requirements = req.memoryRequirements;
            const std::size_t slot = free_slots.back();
            free_slots.pop_back();
            live_slots.push_back(slot);
            p.steps.push_back({true, slot, p.requests.size()});
            p.requests.push_back(r);
            ++p.allocations;
        } else {
            const std::size_t k = rng() % live_slots.size();
            const std::size_t slot = live_slots[k];
            live_slots[k] = live_slots.back();
            live_slots.pop_back();
            free_slots.push_back(slot);
            p.steps.push_back({false, slot, 0});
        }
    }
    for (std::size_t slot : live_slots) p.steps.push_back({false, slot, 0});
    return p;
}

// CPU time of this thread: the machines the benchmark runs on are shared, and
// the allocators' work (including the driver's and the kernel's) is on this thread.
double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

struct Result {
    std::string allocator;
    std::size_t operations = 0;
    double seconds = 0;  // thread CPU time of the timed pass
    double wall_seconds = 0;
    std::uint64_t vk_allocate_calls = 0;
    VkDeviceSize peak_reserved = 0;
    VkDeviceSize peak_requested = 0;
};

// The first `operations` allocations of the pattern (and their frees).
Result replay(const char* name, vkrc::DeviceAllocator& allocator, const vkrc::Device& device, const Pattern& p,
              std::size_t operations) {
    const vkrc::DeviceView view(*device.state());
    std::vector<vkrc::AllocationInfo> slots(p.slots);
    std::vector<bool> used(p.slots);
    Result r;
    r.allocator = name;
    const std::uint64_t calls_before = allocator.statistics(view).vk_allocate_calls;
    // Timed pass: allocator calls only.
    std::size_t done = 0;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = thread_seconds();
    for (const Step& s : p.steps) {
        if (s.allocate) {
            if (done == operations) continue;
            ++done;
            slots[s.slot] = allocator.allocate(view, p.requests[s.request]);
            used[s.slot] = true;
        } else if (used[s.slot]) {
            allocator.free(view, slots[s.slot]);
            used[s.slot] = false;
        }
    }
    r.seconds = thread_seconds() - cpu_start;
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.operations = done;
    r.vk_allocate_calls = allocator.statistics(view).vk_allocate_calls - calls_before;
    // Measuring pass: the same pattern again, reading the statistics after each allocation.
    done = 0;
    VkDeviceSize requested = 0;
    for (const Step& s : p.steps) {
        if (s.allocate) {
            if (done == operations) continue;
            ++done;
            slots[s.slot] = allocator.allocate(view, p.requests[s.request]);
            used[s.slot] = true;
            requested += p.requests[s.request].requirements.size;
            r.peak_requested = std::max(r.peak_requested, requested);
            r.peak_reserved = std::max(r.peak_reserved, allocator.statistics(view).total().block_bytes);
        } else if (used[s.slot]) {
            allocator.free(view, slots[s.slot]);
            requested -= slots[s.slot].size;
            used[s.slot] = false;
        }
    }
    allocator.release(view);
    return r;
}

std::size_t parse_count(const char* text, const char* option) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(text, &end, 10);
    if (!end || *end || v == 0) {
        std::fprintf(stderr, "alloc: %s needs a positive integer, got '%s'\n", option, text);
        std::exit(2);
    }
    return static_cast<std::size_t>(v);
}

}  // namespace

int main(int argc, char** argv) try {
    std::size_t operations = 100000, dedicated_operations = 0, live = 512;
    std::uint32_t seed = 1;
    std::string csv;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (i + 1 >= argc) {
            std::fprintf(stderr, "alloc: %s needs a value\n", a.c_str());
            return 2;
        }
        if (a == "--ops") operations = parse_count(argv[++i], "--ops");
        else if (a == "--dedicated-ops") dedicated_operations = parse_count(argv[++i], "--dedicated-ops");
        else if (a == "--live") live = parse_count(argv[++i], "--live");
        else if (a == "--seed") seed = static_cast<std::uint32_t>(parse_count(argv[++i], "--seed"));
        else if (a == "--csv") csv = argv[++i];
        else {
            std::fprintf(stderr, "usage: alloc [--ops N] [--dedicated-ops N] [--live N] [--seed N] [--csv PATH]\n");
            return 2;
        }
    }
    // By default both allocators replay the whole pattern.
    if (dedicated_operations == 0 || dedicated_operations > operations) dedicated_operations = operations;

    auto instance = vkrc::Instance::create({.application_name = "vkrc alloc bench"});
    auto physical = vkrc::PhysicalDevice::select(instance);
    auto device = vkrc::Device::create(physical);
    const Pattern pattern = make_pattern(device, operations, live, seed);

    vkrc::DedicatedAllocator dedicated;
    vkrc::PoolAllocator pool;
    std::vector<Result> results;
    results.push_back(replay("dedicated", dedicated, device, pattern, dedicated_operations));
    results.push_back(replay("pool", pool, device, pattern, operations));

    std::printf("device: %s; pattern: seed %u, at most %zu live, 256 B - 16 MiB, buffers and images\n", physical.name(),
                seed, live);
    std::printf("%-10s %10s %14s %12s %18s %18s %8s\n", "allocator", "operations", "alloc+free/s", "vkAllocate",
                "peak reserved", "peak requested", "waste");
    for (const auto& r : results) {
        const double waste = r.peak_reserved ? 100.0 * (1.0 - double(r.peak_requested) / double(r.peak_reserved)) : 0.0;
        std::printf("%-10s %10zu %14.0f %12llu %18llu %18llu %7.1f%%\n", r.allocator.c_str(), r.operations,
                    r.operations / r.seconds, (unsigned long long)r.vk_allocate_calls,
                    (unsigned long long)r.peak_reserved, (unsigned long long)r.peak_requested, waste);
    }
    const double speedup = (results[1].operations / results[1].seconds) / (results[0].operations / results[0].seconds);
    std::printf("pool vs dedicated: %.1fx the allocate+free rate (rates from thread CPU time)\n", speedup);
    if (!csv.empty()) {
        std::ofstream out(csv);
        out << "allocator,operations,ops_per_s,vk_allocate_calls,peak_reserved_bytes,peak_requested_bytes,cpu_seconds,"
               "wall_seconds\n";
        for (const auto& r : results) {
            out << r.allocator << ',' << r.operations << ',' << std::llround(r.operations / r.seconds) << ','
                << r.vk_allocate_calls << ',' << r.peak_reserved << ',' << r.peak_requested << ',' << r.seconds << ','
                << r.wall_seconds << '\n';
        }
        if (!out) {
            std::fprintf(stderr, "alloc: cannot write %s\n", csv.c_str());
            return 1;
        }
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "alloc: %s\n", e.what());
    return 1;
}
