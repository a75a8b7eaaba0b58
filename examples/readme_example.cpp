#include <vkrc/vkrc.hpp>
#include <cstdio>
int main() {
    auto instance = vkrc::Instance::create({.validation = true});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));
    auto queue = device.default_queue();
    instance.reset();  // fine: the device keeps its instance alive
    auto buffer = vkrc::Buffer::create(
        device,
        {.size = 1024, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto cmd = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()}).allocate();
    cmd.begin();
    cmd.fill_buffer(buffer, 0, buffer.size(), 42);
    auto to_host = vkrc::memory_barrier(vkrc::use::transfer_dst, vkrc::use::host_read);  // fill, then read
    cmd.pipeline_barrier(vkrc::Span(&to_host, 1), {}, {});
    cmd.end();
    auto done = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = vkrc::Span(&cmd, 1)}, done);
    done.wait();
    std::printf("%s filled the buffer with %u\n", device.physical_device().name(),
                buffer.allocation().read_value<std::uint32_t>(512));
}  // handles go in any order; vkrc destroys children before parents
