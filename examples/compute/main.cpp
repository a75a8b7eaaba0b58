// Runs a compute shader over a buffer and checks every result on the CPU:
//     compute [--validation]
// For each start value n the shader (shaders/collatz.comp) counts the steps of
// the Collatz sequence (n -> n/2 if even, 3n+1 if odd) until n reaches 1.
// Read top to bottom: device, buffers, descriptors, pipeline, commands,
// submission, check.
#include <vkrc/vkrc.hpp>

#include "shaders/collatz.comp.h"

#include <cstdio>
#include <cstring>
#include <exception>
#include <span>
#include <vector>

namespace {

constexpr std::uint32_t count = 100'000;

std::uint32_t collatz_steps(std::uint32_t n) {
    std::uint32_t steps = 0;
    for (; n != 1; ++steps) n = (n % 2 == 0) ? n / 2 : 3 * n + 1;
    return steps;
}

int run(bool validation) {
    // 1. An instance (with the validation layer when asked) and a device.
    auto instance = vkrc::Instance::create({.application_name = "vkrc compute", .validation = validation});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));
    auto queue = device.default_queue();
    std::printf("device: %s\n", device.physical_device().name());

    // 2. The input in upload memory (the CPU writes it through the mapping),
    //    the output in readback memory (the CPU reads it the same way).
    const VkDeviceSize bytes = count * sizeof(std::uint32_t);
    auto starts = vkrc::Buffer::create(
        device,
        {.size = bytes, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {.usage = vkrc::MemoryUsage::upload}});
    auto steps = vkrc::Buffer::create(
        device,
        {.size = bytes, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    std::vector<std::uint32_t> input(count);
    for (std::uint32_t i = 0; i < count; ++i) input[i] = i + 1;
    starts.allocation().write(0, input);

    // 3. A descriptor set pointing the shader's two bindings at the buffers.
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT},
                                                                {.binding = 1,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto descriptor_pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}}});
    auto set = descriptor_pool.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, starts);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, steps);

    // 4. The pipeline: its layout names the set layout and the push constant
    //    (the element count); the SPIR-V was compiled at build time.
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout},
                 .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(std::uint32_t)}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::collatz_comp));

    // 5. Record: bind, push the count, dispatch one invocation per element
    //    (64 per workgroup), then make the shader's writes visible to the host.
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, count);
    cmd.dispatch((count + 63) / 64);
    auto to_host = vkrc::memory_barrier(vkrc::use::compute_storage_write, vkrc::use::host_read);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();

    // 6. Submit and wait for the fence.
    auto done = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, done);
    if (done.wait() != VK_SUCCESS) return 1;

    // 7. Read the results and compare each with the CPU's answer.
    std::vector<std::uint32_t> output(count);
    steps.allocation().read(0, output);
    std::uint32_t mismatches = 0, longest = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
        if (output[i] != collatz_steps(input[i])) ++mismatches;
        if (output[i] > output[longest]) longest = i;
    }
    std::printf("%u values, %u mismatches; the longest: %u takes %u steps\n", count, mismatches, input[longest],
                output[longest]);
    return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    const bool validation = argc > 1 && std::strcmp(argv[1], "--validation") == 0;
    try {
        return run(validation);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "compute: %s\n", e.what());
        return 1;
    }
}
