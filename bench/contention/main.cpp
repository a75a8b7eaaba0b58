// Contention benchmark (issue 17): N threads doing the same kind of work at
// once, ops/s against the thread count. Cases:
//   handle-shared     copy and drop a copy of ONE Buffer shared by every thread
//                     (its reference count's cache line bounces between cores)
//   handle-own        the same, each thread its own Buffer (the uncontended baseline)
//   alloc-pool        allocate + free 64 KiB through a PoolAllocator, no resource:
//   alloc-dedicated   the allocator's own cost and lock (and, dedicated, vkAllocateMemory)
//   alloc-pool-own    alloc-pool with a PoolAllocator per thread: no shared lock or
//                     blocks, what a per-thread fast path could reach at best
//   buffer-pool       Buffer::create + drop (64 KiB storage buffer), PoolAllocator
//   buffer-pool-own   the same, a PoolAllocator per thread
//   buffer-dedicated  the same, DedicatedAllocator
//   buffer-raw        raw Vulkan: create, requirements, vkAllocateMemory, bind, destroy, free
//   buffer-bound      raw Vulkan: create, requirements, bind to the thread's own memory, destroy
//                     (the driver's share when no allocator runs at all)
//   image-*           the same four for a 64x64 RGBA8 optimal-tiling sampled image
//   sets-free         allocate + drop one descriptor set, a FREE_DESCRIPTOR_SET pool per thread
//   sets-reset        allocate 64 sets, drop them, reset the pool (a pool per thread; 64 ops)
//   sets-raw          sets-free in raw Vulkan: vkAllocateDescriptorSets + vkFreeDescriptorSets
//                     from the thread's pool (the driver's share)
// The allocators (but the -own cases'), the set layout and the device are
// shared by all threads, as in a program; the descriptor pools and raw memory
// are per thread.
//
// A measurement starts N threads, lets each set up and do one warm-up
// operation, releases them together, stops them after --ms milliseconds
// (once each has done an operation) and counts what they completed:
// ops/s = operations / (start to the last thread's end). After an untimed
// warm-up block, each block measures every case at every thread count in
// turn, then the first count again (repeat 2: an A/A control of the
// block-to-block noise). Run several processes (bench/contention_run.sh) so
// that the intervals include the spread between runs.
//
// --instructions N instead counts, on one thread, the instructions of each
// case's first N operations after a warm-up one: each case is collected
// alone under callgrind and dumped (bench/contention_instructions.sh), so
// that the per-object cost of either policy is a deterministic count. The
// target contention_st is this program under vkrc::st, for that mode.
//
// Usage: contention [--threads 1,2,4,8,16] [--blocks N] [--ms N] [--cases a,b,...] [--csv PATH]
//                   [--instructions N]
#include <vkrc/vkrc.hpp>

#include <valgrind/callgrind.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

constexpr VkDeviceSize buffer_bytes = 64 * 1024;
constexpr std::uint32_t image_side = 64;
constexpr std::uint32_t reset_batch = 64;  // sets per reset in sets-reset

// What every thread shares.
struct Shared {
    vkrc::Device device;
    vkrc::SharedAllocator pool = vkrc::make_allocator<vkrc::PoolAllocator>();
    vkrc::SharedAllocator dedicated = vkrc::make_allocator<vkrc::DedicatedAllocator>();
    std::vector<vkrc::SharedAllocator> own_pools;  // the -own cases', one per thread index
    vkrc::Buffer buffer;                           // handle-shared's object
    vkrc::DescriptorSetLayout layout;
    vkrc::AllocationRequest request;  // alloc-*: a buffer's
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    VkImageCreateInfo image_info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    std::uint32_t buffer_type = 0;  // the raw cases' memory types
    std::uint32_t image_type = 0;
};

vkrc::Buffer make_buffer(const Shared& s, const vkrc::SharedAllocator& allocator) {
    return vkrc::Buffer::create(s.device,
                                {.size = s.buffer_info.size, .usage = s.buffer_info.usage, .allocator = allocator});
}

vkrc::Image make_image(const Shared& s, const vkrc::SharedAllocator& allocator) {
    const auto& i = s.image_info;
    return vkrc::Image::create(s.device,
                               {.format = i.format, .extent = i.extent, .usage = i.usage, .allocator = allocator});
}

// One thread's work: each call does some operations and returns how many.
using Step = std::function<std::size_t()>;

// Copies and drops a copy of object, 16 times per step.
Step copy_step(vkrc::Buffer object) {
    return [object] {
        for (int i = 0; i < 16; ++i) {
            vkrc::Buffer copy = object;
            // Keeps the copy (and its count's increment and decrement) in the loop.
            asm volatile("" : : "r"(&copy) : "memory");
        }
        return std::size_t{16};
    };
}

Step alloc_step(const Shared& s, vkrc::SharedAllocator allocator) {
    const vkrc::DeviceView view(*s.device.state());
    return [view, allocator, request = s.request] {
        allocator->free(view, allocator->allocate(view, request));
        return std::size_t{1};
    };
}

// The raw cases: a buffer or an image, with its own VkDeviceMemory each time
// (bound == false) or bound at offset 0 of the thread's one allocation.
class RawResource {
public:
    RawResource(const Shared& s, bool image, bool bound)
        : device_(s.device), fn_(&s.device.fn()), s_(&s), image_(image) {
        if (bound) memory_ = allocate(1u << 20);
    }
    ~RawResource() {
        if (memory_) fn_->vkFreeMemory(device_.vk(), memory_, nullptr);
    }
    RawResource(const RawResource&) = delete;
    RawResource& operator=(const RawResource&) = delete;

    std::size_t step() {
        const VkDevice d = device_.vk();
        VkBuffer buffer = VK_NULL_HANDLE;
        VkImage image = VK_NULL_HANDLE;
        VkMemoryRequirements r{};
        if (image_) {
            vkrc::check(fn_->vkCreateImage(d, &s_->image_info, nullptr, &image), "vkCreateImage");
            fn_->vkGetImageMemoryRequirements(d, image, &r);
        } else {
            vkrc::check(fn_->vkCreateBuffer(d, &s_->buffer_info, nullptr, &buffer), "vkCreateBuffer");
            fn_->vkGetBufferMemoryRequirements(d, buffer, &r);
        }
        const VkDeviceMemory memory = memory_ ? memory_ : allocate(r.size);
        if (image_) vkrc::check(fn_->vkBindImageMemory(d, image, memory, 0), "vkBindImageMemory");
        else vkrc::check(fn_->vkBindBufferMemory(d, buffer, memory, 0), "vkBindBufferMemory");
        if (image_) fn_->vkDestroyImage(d, image, nullptr);
        else fn_->vkDestroyBuffer(d, buffer, nullptr);
        if (!memory_) fn_->vkFreeMemory(d, memory, nullptr);
        return 1;
    }

private:
    VkDeviceMemory allocate(VkDeviceSize size) const {
        VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        info.allocationSize = size;
        info.memoryTypeIndex = image_ ? s_->image_type : s_->buffer_type;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        vkrc::check(fn_->vkAllocateMemory(device_.vk(), &info, nullptr, &memory), "vkAllocateMemory");
        return memory;
    }

    vkrc::Device device_;
    const vkrc::DeviceFunctions* fn_;
    const Shared* s_;
    bool image_;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
};

Step raw_step(const Shared& s, bool image, bool bound) {
    auto raw = std::make_shared<RawResource>(s, image, bound);
    return [raw] { return raw->step(); };
}

vkrc::DescriptorPool make_set_pool(const Shared& s, VkDescriptorPoolCreateFlags flags) {
    return vkrc::DescriptorPool::create(
        s.device, {.flags = flags,
                   .max_sets = reset_batch,
                   .pool_sizes = {VkDescriptorPoolSize{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, reset_batch}}});
}

Step sets_free_step(const Shared& s) {
    return [pool = make_set_pool(s, VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT), layout = s.layout] {
        vkrc::DescriptorSet set = pool.allocate(layout);
        return std::size_t{1};
    };
}

Step sets_reset_step(const Shared& s) {
    auto sets = std::make_shared<std::vector<vkrc::DescriptorSet>>();
    return [pool = make_set_pool(s, 0), layout = s.layout, sets] {
        for (std::uint32_t i = 0; i < reset_batch; ++i) sets->push_back(pool.allocate(layout));
        sets->clear();
        pool.reset_sets();
        return std::size_t{reset_batch};
    };
}

// sets-raw: the thread's pool is a vkrc one, used only through its raw handle.
Step sets_raw_step(const Shared& s) {
    return [pool = make_set_pool(s, VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT), &s] {
        const VkDevice d = s.device.vk();
        const VkDescriptorSetLayout layout = s.layout.vk();
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = pool.vk();
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &layout;
        VkDescriptorSet set = VK_NULL_HANDLE;
        vkrc::check(s.device.fn().vkAllocateDescriptorSets(d, &ai, &set), "vkAllocateDescriptorSets");
        vkrc::check(s.device.fn().vkFreeDescriptorSets(d, pool.vk(), 1, &set), "vkFreeDescriptorSets");
        return std::size_t{1};
    };
}

struct Case {
    const char* name;
    // Called on the measuring thread with its index.
    std::function<Step(const Shared&, unsigned thread)> make;
};

enum class Source { pool, dedicated, own_pool };

const vkrc::SharedAllocator& allocator_of(const Shared& s, Source source, unsigned thread) {
    if (source == Source::own_pool) return s.own_pools[thread];
    return source == Source::pool ? s.pool : s.dedicated;
}

std::vector<Case> all_cases() {
    auto alloc = [](Source source) {
        return [source](const Shared& s, unsigned t) { return alloc_step(s, allocator_of(s, source, t)); };
    };
    auto resource = [](bool image, Source source) {
        return [image, source](const Shared& s, unsigned t) -> Step {
            const vkrc::SharedAllocator allocator = allocator_of(s, source, t);
            if (image) return [&s, allocator] { return make_image(s, allocator) ? std::size_t{1} : 0; };
            return [&s, allocator] { return make_buffer(s, allocator) ? std::size_t{1} : 0; };
        };
    };
    auto raw = [](bool image, bool bound) {
        return [image, bound](const Shared& s, unsigned) { return raw_step(s, image, bound); };
    };
    return {
        {"handle-shared", [](const Shared& s, unsigned) { return copy_step(s.buffer); }},
        {"handle-own", [](const Shared& s, unsigned) { return copy_step(make_buffer(s, s.pool)); }},
        {"alloc-pool", alloc(Source::pool)},
        {"alloc-pool-own", alloc(Source::own_pool)},
        {"alloc-dedicated", alloc(Source::dedicated)},
        {"buffer-pool", resource(false, Source::pool)},
        {"buffer-pool-own", resource(false, Source::own_pool)},
        {"buffer-dedicated", resource(false, Source::dedicated)},
        {"buffer-raw", raw(false, false)},
        {"buffer-bound", raw(false, true)},
        {"image-pool", resource(true, Source::pool)},
        {"image-dedicated", resource(true, Source::dedicated)},
        {"image-raw", raw(true, false)},
        {"image-bound", raw(true, true)},
        {"sets-free", [](const Shared& s, unsigned) { return sets_free_step(s); }},
        {"sets-reset", [](const Shared& s, unsigned) { return sets_reset_step(s); }},
        {"sets-raw", [](const Shared& s, unsigned) { return sets_raw_step(s); }},
    };
}

struct Measurement {
    std::size_t operations = 0;
    double seconds = 0;
    double rate() const { return double(operations) / seconds; }
};

// threads threads run c's step until stopped, after block_ms milliseconds.
Measurement measure(const Case& c, const Shared& s, unsigned threads, unsigned block_ms) {
    using Clock = std::chrono::steady_clock;
    std::atomic<unsigned> ready{0}, started{0};
    std::atomic<bool> go{false}, stop{false};
    Clock::time_point start;
    std::vector<std::size_t> operations(threads);
    std::vector<Clock::time_point> ends(threads);
    std::mutex error_mutex;
    std::exception_ptr error;
    std::vector<std::thread> workers;
    for (unsigned t = 0; t < threads; ++t) {
        workers.emplace_back([&, t] {
            try {
                Step step = c.make(s, t);
                step();  // warm-up: the pool's block, the driver's first-use work
                ready.fetch_add(1);
                ready.notify_one();
                go.wait(false);
                std::size_t n = step();
                started.fetch_add(1);
                started.notify_one();
                while (!stop.load(std::memory_order_relaxed)) n += step();
                ends[t] = Clock::now();
                operations[t] = n;
            } catch (...) {
                const std::lock_guard lock(error_mutex);
                error = std::current_exception();
                // Counted as ready and started, so that the main thread goes on.
                if (!go.load()) ready.fetch_add(1);
                ready.notify_one();
                started.fetch_add(1);
                started.notify_one();
            }
        });
    }
    for (unsigned n = ready.load(); n < threads; n = ready.load()) ready.wait(n);
    start = Clock::now();
    go.store(true);
    go.notify_all();
    std::this_thread::sleep_for(std::chrono::milliseconds(block_ms));
    // On a loaded machine a thread may wake late: stop only once every
    // thread has done an operation, so that the rate covers all of them.
    for (unsigned n = started.load(); n < threads; n = started.load()) started.wait(n);
    stop.store(true);
    for (auto& w : workers) w.join();
    if (error) std::rethrow_exception(error);
    Measurement m;
    for (unsigned t = 0; t < threads; ++t) {
        m.operations += operations[t];
        m.seconds = std::max(m.seconds, std::chrono::duration<double>(ends[t] - start).count());
    }
    return m;
}

Shared make_shared_state(const vkrc::Device& device, unsigned max_threads) {
    Shared s;
    s.device = device;
    for (unsigned t = 0; t < max_threads; ++t) s.own_pools.push_back(vkrc::make_allocator<vkrc::PoolAllocator>());
    s.buffer_info.size = buffer_bytes;
    s.buffer_info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    auto& i = s.image_info;
    i.imageType = VK_IMAGE_TYPE_2D;
    i.format = VK_FORMAT_R8G8B8A8_UNORM;
    i.extent = {image_side, image_side, 1};
    i.mipLevels = 1;
    i.arrayLayers = 1;
    i.samples = VK_SAMPLE_COUNT_1_BIT;
    i.tiling = VK_IMAGE_TILING_OPTIMAL;
    i.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    s.buffer = make_buffer(s, s.pool);
    s.layout = vkrc::DescriptorSetLayout::create(device, {.bindings = {vkrc::DescriptorSetLayoutBinding{}}});

    VkMemoryRequirements2 b{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    const VkDeviceBufferMemoryRequirements bq{VK_STRUCTURE_TYPE_DEVICE_BUFFER_MEMORY_REQUIREMENTS, nullptr,
                                              &s.buffer_info};
    device.fn().vkGetDeviceBufferMemoryRequirements(device.vk(), &bq, &b);
    VkMemoryRequirements2 im{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    const VkDeviceImageMemoryRequirements iq{VK_STRUCTURE_TYPE_DEVICE_IMAGE_MEMORY_REQUIREMENTS, nullptr, &s.image_info,
                                             VkImageAspectFlagBits{}};
    device.fn().vkGetDeviceImageMemoryRequirements(device.vk(), &iq, &im);
    const auto& props = device.physical_device().memory_properties();
    s.request.requirements = b.memoryRequirements;
    s.buffer_type = vkrc::choose_memory_type(props, b.memoryRequirements.memoryTypeBits, {}, "contention");
    s.image_type = vkrc::choose_memory_type(props, im.memoryRequirements.memoryTypeBits, {}, "contention");
    return s;
}

// --instructions: each case's operations on one thread, collected alone.
void count_instructions(const std::vector<Case>& cases, const Shared& s, std::size_t operations) {
    for (const Case& c : cases) {
        Step step = c.make(s, 0);
        step();  // first use (a pool's first block) is not the per-object cost
        std::size_t done = 0;
        CALLGRIND_ZERO_STATS;
        CALLGRIND_TOGGLE_COLLECT;
        while (done < operations) done += step();
        CALLGRIND_TOGGLE_COLLECT;
        const std::string label = std::string("case=") + c.name + " operations=" + std::to_string(done);
        CALLGRIND_DUMP_STATS_AT(label.c_str());
        std::printf("%s: %zu operations counted\n", c.name, done);
    }
}

struct Row {
    std::string name;
    unsigned threads = 0;
    int repeat = 1;  // 2: the block's A/A control of the first thread count
    unsigned block = 0;
    Measurement m;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

// The block's rate of r's case at repeat `repeat` of thread count n, or 0.
double rate_of(const std::vector<Row>& rows, const Row& r, unsigned n, int repeat) {
    for (const Row& x : rows) {
        if (x.name == r.name && x.block == r.block && x.threads == n && x.repeat == repeat) return x.m.rate();
    }
    return 0;
}

// One line per case: the first count's median rate, its A/A ratio (repeat 2
// over repeat 1), then per count the speed-up over the first count, each the
// median [min, max] over the blocks.
void print_summary(const std::vector<Row>& rows, const std::vector<Case>& cases, const std::vector<unsigned>& threads) {
    std::printf("%-17s %14s %26s   speed-up vs %u thread(s) per block: median [min, max]\n", "case", "ops/s median",
                "A/A", threads[0]);
    for (const Case& c : cases) {
        std::vector<double> rates, control;
        std::vector<std::vector<double>> ratios(threads.size());
        for (const Row& r : rows) {
            if (r.name != c.name || r.threads != threads[0] || r.repeat != 1) continue;
            rates.push_back(r.m.rate());
            control.push_back(rate_of(rows, r, threads[0], 2) / r.m.rate());
            for (std::size_t i = 0; i < threads.size(); ++i)
                ratios[i].push_back(rate_of(rows, r, threads[i], 1) / r.m.rate());
        }
        auto interval = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            char text[64];
            std::snprintf(text, sizeof text, "%.2f [%.2f, %.2f]", median(v), v.front(), v.back());
            return std::string(text);
        };
        std::printf("%-17s %14.0f %26s  ", c.name, median(rates), interval(control).c_str());
        for (std::size_t i = 1; i < threads.size(); ++i)
            std::printf(" %u: %s", threads[i], interval(ratios[i]).c_str());
        std::printf("\n");
    }
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
    std::ofstream out(path);
    out << "case,threads,repeat,block,operations,seconds,ops_per_second\n";
    for (const Row& r : rows) {
        out << r.name << ',' << r.threads << ',' << r.repeat << ',' << r.block << ',' << r.m.operations << ','
            << r.m.seconds << ',' << std::llround(r.m.rate()) << '\n';
    }
    if (!out) throw std::runtime_error("cannot write " + path);
}

[[noreturn]] void usage() {
    std::fprintf(stderr,
                 "usage: contention [--threads 1,2,4,8,16] [--blocks N] [--ms N] [--cases a,b,...] [--csv PATH]"
                 " [--instructions N]\n");
    std::exit(2);
}

unsigned parse_count(const std::string& text) {
    char* end = nullptr;
    const unsigned long v = std::strtoul(text.c_str(), &end, 10);
    if (text.empty() || *end || v == 0 || v > 1024) usage();
    return static_cast<unsigned>(v);
}

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> parts;
    std::stringstream in(text);
    for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
    return parts;
}

}  // namespace

int main(int argc, char** argv) try {
    std::vector<unsigned> threads{1, 2, 4, 8, 16};
    unsigned blocks = 5, block_ms = 50, instructions = 0;
    std::vector<std::string> names;
    std::string csv;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (i + 1 >= argc) usage();
        const std::string v = argv[++i];
        if (a == "--threads") {
            threads.clear();
            for (const auto& t : split(v)) threads.push_back(parse_count(t));
        } else if (a == "--blocks") blocks = parse_count(v);
        else if (a == "--ms") block_ms = parse_count(v);
        else if (a == "--cases") names = split(v);
        else if (a == "--csv") csv = v;
        else if (a == "--instructions") instructions = parse_count(v);
        else usage();
    }
    if (threads.empty()) usage();
    std::vector<Case> cases = all_cases();
    if (!names.empty()) {
        std::vector<Case> chosen;
        for (const auto& n : names) {
            auto it = std::find_if(cases.begin(), cases.end(), [&](const Case& c) { return n == c.name; });
            if (it == cases.end()) {
                std::fprintf(stderr, "contention: no case '%s'\n", n.c_str());
                return 2;
            }
            chosen.push_back(*it);
        }
        cases = chosen;
    }

    auto instance = vkrc::Instance::create({.application_name = "vkrc contention bench"});
    auto physical = vkrc::PhysicalDevice::select(instance);
    const Shared shared =
        make_shared_state(vkrc::Device::create(physical), *std::max_element(threads.begin(), threads.end()));
    if (instructions) {
        std::printf("device: %s; %u operations per case counted on one thread\n", physical.name(), instructions);
        count_instructions(cases, shared, instructions);
        return 0;
    }
    std::printf("device: %s; %u hardware threads; %u blocks of %u ms per case and thread count\n", physical.name(),
                std::thread::hardware_concurrency(), blocks, block_ms);

    // One untimed block first: the process's first measurements pay for
    // first-use work (page faults, the driver's caches) that is no contention.
    for (const Case& c : cases) measure(c, shared, threads[0], block_ms);
    std::vector<Row> rows;
    for (unsigned b = 1; b <= blocks; ++b) {
        for (const Case& c : cases) {
            for (unsigned n : threads) rows.push_back({c.name, n, 1, b, measure(c, shared, n, block_ms)});
            rows.push_back({c.name, threads[0], 2, b, measure(c, shared, threads[0], block_ms)});
        }
    }
    print_summary(rows, cases, threads);
    if (!csv.empty()) write_csv(csv, rows);
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "contention: %s\n", e.what());
    return 1;
}
