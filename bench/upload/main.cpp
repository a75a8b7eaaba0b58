// Upload throughput and CPU cost per upload (issue 15): vkrc's streaming
// path (Uploader: staging ring, transfer queue, tickets), vkrc's blocking
// upload_* helpers, and a raw-Vulkan streaming implementation (staging ring,
// transfer queue, one timeline semaphore) on the same device and queue.
// Each case runs --blocks blocks per variant, the variants interleaved; a
// block uploads the case's data --reps times (scaled down for large cases)
// and waits once at its end. raw-stream-aa is raw-stream again (a second
// instance): the A/A control of the ratios. GB/s: bytes / wall time of the block; CPU us:
// the uploading thread's CPU time per upload (lavapipe's copies run on its
// own threads, so this is the submitting cost).
//
// Usage: upload [--blocks N] [--reps N] [--csv PATH]
#include <vkrc/vkrc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <deque>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace {

double thread_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

struct Case {
    std::string name;
    VkDeviceSize bytes = 0;  // per upload
    bool image = false;
    int reps = 0;  // uploads per block at --reps 1000
};

// The data each upload sends: a buffer, or every level of a 4096^2 RGBA8 image.
struct Target {
    vkrc::Buffer buffer;
    vkrc::Image image;
};

// Raw Vulkan streaming, as one would write it by hand: a host-coherent staging
// ring, command buffers reused once their submission's timeline value passed,
// one timeline semaphore counting submissions on the transfer queue.
class RawStream {
public:
    RawStream(const vkrc::Queue& queue, VkDeviceSize capacity) : queue_(queue), capacity_(capacity) {
        const auto& d = queue.device();
        device_ = d.vk();
        fn_ = &d.fn();
        VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bi.size = capacity;
        bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
        vkrc::check(fn_->vkCreateBuffer(device_, &bi, nullptr, &staging_), "vkCreateBuffer");
        VkMemoryRequirements req;
        fn_->vkGetBufferMemoryRequirements(device_, staging_, &req);
        const auto& props = d.physical_device().memory_properties();
        constexpr VkMemoryPropertyFlags want =
            VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        std::uint32_t type = 0;
        while (!((req.memoryTypeBits >> type) & 1) || (props.memoryTypes[type].propertyFlags & want) != want) ++type;
        VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        ai.allocationSize = req.size;
        ai.memoryTypeIndex = type;
        vkrc::check(fn_->vkAllocateMemory(device_, &ai, nullptr, &memory_), "vkAllocateMemory");
        fn_->vkBindBufferMemory(device_, staging_, memory_, 0);
        void* p = nullptr;
        vkrc::check(fn_->vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &p), "vkMapMemory");
        mapped_ = static_cast<std::byte*>(p);
        VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pi.queueFamilyIndex = queue.family_index();
        vkrc::check(fn_->vkCreateCommandPool(device_, &pi, nullptr, &pool_), "vkCreateCommandPool");
        VkSemaphoreTypeCreateInfo ti{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
        ti.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
        VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &ti};
        vkrc::check(fn_->vkCreateSemaphore(device_, &si, nullptr, &timeline_), "vkCreateSemaphore");
    }
    ~RawStream() {
        fn_->vkQueueWaitIdle(queue_.vk());
        fn_->vkDestroySemaphore(device_, timeline_, nullptr);
        fn_->vkDestroyCommandPool(device_, pool_, nullptr);
        fn_->vkDestroyBuffer(device_, staging_, nullptr);
        fn_->vkFreeMemory(device_, memory_, nullptr);
    }

    void upload(const Target& t, const std::byte* data, VkDeviceSize size) {
        const VkDeviceSize at = reserve(size);
        std::memcpy(mapped_ + at, data, size);
        VkCommandBuffer cmd = next_command_buffer();
        VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        fn_->vkBeginCommandBuffer(cmd, &bi);
        // Earlier copies into the same target finish first (write after
        // write), as in the Uploader's batches: the same synchronisation, by hand.
        VkMemoryBarrier2 before{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        before.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        before.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
        before.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        before.dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.memoryBarrierCount = 1;
        dep.pMemoryBarriers = &before;
        fn_->vkCmdPipelineBarrier2(cmd, &dep);
        if (t.buffer) {
            const VkBufferCopy region{at, 0, size};
            fn_->vkCmdCopyBuffer(cmd, staging_, t.buffer.vk(), 1, &region);
        } else {
            copy_image(cmd, t.image, at);
        }
        fn_->vkEndCommandBuffer(cmd);
        submit(cmd);
    }
    void wait_all() { wait(value_); }

private:
    void copy_image(VkCommandBuffer cmd, const vkrc::Image& image, VkDeviceSize at) {
        const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, image.mip_levels(), 0, 1};
        VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
        b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
        b.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        b.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = image.vk();
        b.subresourceRange = all;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.imageMemoryBarrierCount = 1;
        dep.pImageMemoryBarriers = &b;
        fn_->vkCmdPipelineBarrier2(cmd, &dep);
        VkBufferImageCopy regions[16];
        for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
            regions[level] = VkBufferImageCopy{};
            regions[level].bufferOffset = at;
            regions[level].imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, 1};
            regions[level].imageExtent = image.extent(level);
            at += VkDeviceSize(regions[level].imageExtent.width) * regions[level].imageExtent.height * 4;
        }
        fn_->vkCmdCopyBufferToImage(cmd, staging_, image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, image.mip_levels(),
                                    regions);
        b.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT;
        b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
        fn_->vkCmdPipelineBarrier2(cmd, &dep);
    }

    // Ring space: regions in flight are (begin, end, value), oldest first;
    // completed ones are dropped first, so an idle ring starts again at 0
    // (its pages stay warm).
    VkDeviceSize reserve(VkDeviceSize size) {
        retire();
        for (;;) {
            VkDeviceSize at = 0;
            if (!regions_.empty()) {
                const VkDeviceSize head = (regions_.back().end + 15) & ~VkDeviceSize(15);
                const VkDeviceSize tail = regions_.front().begin;
                if (head > tail ? head + size <= capacity_ || size <= tail : head + size <= tail) {
                    at = head > tail && head + size > capacity_ ? 0 : head;
                } else {
                    wait(regions_.front().value);
                    retire();
                    continue;
                }
            }
            regions_.push_back({at, at + size, value_ + 1});
            return at;
        }
    }
    void retire() {
        std::uint64_t done = 0;
        fn_->vkGetSemaphoreCounterValue(device_, timeline_, &done);
        while (!regions_.empty() && regions_.front().value <= done) regions_.pop_front();
    }
    void wait(std::uint64_t value) {
        VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
        wi.semaphoreCount = 1;
        wi.pSemaphores = &timeline_;
        wi.pValues = &value;
        vkrc::check(fn_->vkWaitSemaphores(device_, &wi, UINT64_MAX), "vkWaitSemaphores");
    }
    VkCommandBuffer next_command_buffer() {
        std::uint64_t done = 0;
        fn_->vkGetSemaphoreCounterValue(device_, timeline_, &done);
        for (auto& c : cmds_) {
            if (c.value <= done) {
                c.value = value_ + 1;
                return c.cmd;
            }
        }
        VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        ai.commandPool = pool_;
        ai.commandBufferCount = 1;
        VkCommandBuffer cmd;
        vkrc::check(fn_->vkAllocateCommandBuffers(device_, &ai, &cmd), "vkAllocateCommandBuffers");
        cmds_.push_back({cmd, value_ + 1});
        return cmd;
    }
    void submit(VkCommandBuffer cmd) {
        VkCommandBufferSubmitInfo ci{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
        ci.commandBuffer = cmd;
        VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        signal.semaphore = timeline_;
        signal.value = ++value_;
        signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        si.commandBufferInfoCount = 1;
        si.pCommandBufferInfos = &ci;
        si.signalSemaphoreInfoCount = 1;
        si.pSignalSemaphoreInfos = &signal;
        vkrc::check(fn_->vkQueueSubmit2(queue_.vk(), 1, &si, VK_NULL_HANDLE), "vkQueueSubmit2");
    }

    struct Region {
        VkDeviceSize begin, end;
        std::uint64_t value;
    };
    struct Cmd {
        VkCommandBuffer cmd;
        std::uint64_t value;
    };
    vkrc::Queue queue_;
    VkDevice device_ = VK_NULL_HANDLE;
    const vkrc::DeviceFunctions* fn_ = nullptr;
    VkDeviceSize capacity_;
    VkBuffer staging_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    std::byte* mapped_ = nullptr;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkSemaphore timeline_ = VK_NULL_HANDLE;
    std::uint64_t value_ = 0;
    std::deque<Region> regions_;
    std::vector<Cmd> cmds_;
};

struct Row {
    std::string variant, upload;
    int block = 0, uploads = 0;
    VkDeviceSize bytes = 0;
    double wall = 0, cpu = 0;
};

int parse(const char* text) {
    const int v = std::atoi(text);
    if (v <= 0) throw std::runtime_error(std::string("upload: a positive integer is needed, got ") + text);
    return v;
}

}  // namespace

int main(int argc, char** argv) try {
    int blocks = 3, reps = 1000;
    std::string csv, only;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--blocks") blocks = parse(argv[i + 1]);
        else if (a == "--reps") reps = parse(argv[i + 1]);
        else if (a == "--csv") csv = argv[i + 1];
        else if (a == "--case") only = argv[i + 1];
        else throw std::runtime_error("usage: upload [--blocks N] [--reps N] [--csv PATH] [--case NAME-PREFIX]");
    }
    auto instance = vkrc::Instance::create({.application_name = "vkrc upload bench"});
    auto physical = vkrc::PhysicalDevice::select(instance, {});
    auto device = vkrc::Device::create(physical, {.transfer_queue = true});
    const auto transfer = device.queue_for(vkrc::QueueRole::transfer);
    std::printf("device: %s; transfer queue family %u%s\n", physical.name(), transfer.queue.family_index(),
                transfer.dedicated_family        ? " (dedicated)"
                : transfer.shares_graphics_queue ? " (the graphics queue)"
                                                 : "");
    // Upload counts per block at --reps 1000: fewer for the large cases.
    const std::vector<Case> cases = {{"buffer 4 KiB", 4 << 10, false, 1000},
                                     {"buffer 1 MiB", 1 << 20, false, 100},
                                     {"buffer 64 MiB", 64 << 20, false, 4},
                                     {"image 4096^2 RGBA8 mips", 0, true, 2}};
    std::vector<Row> rows;
    for (const auto& c : cases) {
        if (!c.name.starts_with(only)) continue;  // --case "buffer 4": that case only
        Target target;
        VkDeviceSize bytes = c.bytes;
        if (c.image) {
            target.image =
                vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                             .extent = {4096, 4096, 1},
                                             .mip_levels = 13,
                                             .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
            bytes = vkrc::image_data_size(target.image);
        } else {
            target.buffer = vkrc::Buffer::create(device, {.size = bytes, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        }
        std::vector<std::byte> data(bytes, std::byte{0x5a});
        const int uploads = std::max(1, c.reps * reps / 1000);
        const VkDeviceSize ring = std::max<VkDeviceSize>(2 * bytes, 16 << 20);
        auto uploader = vkrc::Uploader::create(
            {.queue = transfer.queue, .consumer_family = transfer.queue.family_index(), .staging_size = ring});
        RawStream raw(transfer.queue, ring), raw_aa(transfer.queue, ring);
        const std::vector<std::pair<std::string, std::function<void()>>> variants = {
            {"vkrc-stream",
             [&] {
                 if (c.image) uploader.upload_image(target.image, data);
                 else uploader.upload_buffer(target.buffer, 0, data);
                 uploader.submit();
             }},
            {"vkrc-blocking",
             [&] {
                 if (c.image) vkrc::upload_image(transfer.queue, target.image, data);
                 else vkrc::upload_buffer(transfer.queue, target.buffer, 0, data);
             }},
            {"raw-stream", [&] { raw.upload(target, data.data(), bytes); }},
            // The A/A control: the reference again, so its ratio shows the noise floor.
            {"raw-stream-aa", [&] { raw_aa.upload(target, data.data(), bytes); }}};
        const std::vector<std::function<void()>> finish = {[&] { uploader.submit().wait_on_host(); }, [] {},
                                                           [&] { raw.wait_all(); }, [&] { raw_aa.wait_all(); }};
        for (int block = 0; block <= blocks; ++block) {  // block 0 warms up
            for (std::size_t v = 0; v < variants.size(); ++v) {
                const auto start = std::chrono::steady_clock::now();
                double cpu = 0;
                for (int u = 0; u < uploads; ++u) {
                    const double t0 = thread_cpu_seconds();
                    variants[v].second();
                    cpu += thread_cpu_seconds() - t0;
                }
                finish[v]();
                const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                if (block == 0) continue;
                rows.push_back({variants[v].first, c.name, block, uploads, bytes, wall, cpu});
                const Row& r = rows.back();
                std::printf("%-24s %-14s block %d: %8.3f GB/s %10.1f us CPU per upload\n", c.name.c_str(),
                            r.variant.c_str(), block, double(bytes) * uploads / wall * 1e-9, cpu / uploads * 1e6);
            }
        }
    }
    if (!csv.empty()) {
        std::ofstream out(csv);
        out << "upload,variant,block,uploads,bytes_per_upload,wall_seconds,cpu_seconds,gb_per_s,cpu_us_per_upload\n";
        for (const auto& r : rows) {
            out << r.upload << ',' << r.variant << ',' << r.block << ',' << r.uploads << ',' << r.bytes << ',' << r.wall
                << ',' << r.cpu << ',' << double(r.bytes) * r.uploads / r.wall * 1e-9 << ',' << r.cpu / r.uploads * 1e6
                << '\n';
        }
        if (!out) throw std::runtime_error("upload: cannot write " + csv);
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "upload: %s\n", e.what());
    return 1;
}
