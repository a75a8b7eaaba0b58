// Creates a device through an installed or embedded vkrc, squares numbers
// with a compute shader (compiled by vkrc_add_shaders), checks them and names
// the device, with the thread policy this program was compiled for.
#include <vkrc/vkrc.hpp>

#include "shaders/square.comp.h"

#include <cstdio>
#include <exception>
#include <span>
#include <vector>

int main() try {
    constexpr std::uint32_t count = 1000;
    vkrc::Instance instance = vkrc::Instance::create({.application_name = "vkrc consumer"});
    vkrc::PhysicalDevice gpu = vkrc::PhysicalDevice::select(instance);
    vkrc::Device device = vkrc::Device::create(gpu);
    vkrc::Queue queue = device.default_queue();

    auto out = vkrc::Buffer::create(device, {.size = count * sizeof(std::uint32_t),
                                             .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                             .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto descriptor_pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptor_pool.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout},
                 .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(std::uint32_t)}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::square_comp));

    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, count);
    cmd.dispatch((count + 63) / 64);
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    auto done = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, done);
    if (done.wait() != VK_SUCCESS) return 1;

    std::vector<std::uint32_t> squares(count);
    out.allocation().read(0, std::span(squares));
    for (std::uint32_t i = 0; i < count; ++i) {
        if (squares[i] != i * i) {
            std::fprintf(stderr, "vkrc consumer: element %u is %u, not %u\n", i, squares[i], i * i);
            return 1;
        }
    }
    std::printf("vkrc consumer (policy %s): %s\n", VKRC_IS_MULTI_THREAD ? "mt" : "st", device.physical_device().name());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "vkrc consumer: %s\n", e.what());
    return 1;
}
