#include "fault_scenarios.hpp"

#include "support/fault_injection.hpp"
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"
#include "shaders/ray_query.comp.h"
#include "shaders/rt_scene.rcall.h"
#include "shaders/rt_scene.rchit.h"
#include "shaders/rt_scene.rgen.h"
#include "shaders/rt_scene.rmiss.h"
#include "shaders/rt_shadow.rmiss.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <span>
#include <stdexcept>

namespace vkrc_test {
namespace {

struct Context {
    vkrc::Instance instance;
    vkrc::PhysicalDevice physical;
    vkrc::Device device;
    vkrc::Queue queue;
};

Context make_context(const vkrc::InstanceCreateInfo& info) {
    Context c;
    c.instance = vkrc::Instance::create(info);
    c.physical = vkrc::PhysicalDevice::select(c.instance, test_device_requirements());
    c.device = vkrc::Device::create(c.physical);
    c.queue = c.device.default_queue();
    faults::end_of_setup();
    return c;
}

vkrc::Buffer readback_buffer(const vkrc::Device& device, VkDeviceSize size, VkBufferUsageFlags usage) {
    return vkrc::Buffer::create(device,
                                {.size = size, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::readback}});
}

// Submits cmd (ended) and waits for it through a fence.
void run_and_wait(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd) {
    auto fence = vkrc::Fence::create(queue.device());
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    fence.wait();
    // Signalled now: the status query is one more failable call.
    if (fence.status() != VK_SUCCESS) throw std::logic_error("the fence waited for is not signalled");
}

VkMemoryBarrier2 copy_to_host() {
    return vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

constexpr VkFormat nv12 = VK_FORMAT_G8_B8R8_2PLANE_420_UNORM;

// A Y'CbCr conversion and the sampler and view made with it, where the
// device samples NV12; returns whether it could.
bool use_ycbcr(const vkrc::PhysicalDevice& physical, const vkrc::Device& device) {
    VkFormatProperties props{};
    physical.fn().vkGetPhysicalDeviceFormatProperties(physical.vk(), nv12, &props);
    const VkFormatFeatureFlags f = props.optimalTilingFeatures;
    const VkFormatFeatureFlags locations =
        VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT | VK_FORMAT_FEATURE_COSITED_CHROMA_SAMPLES_BIT;
    if (!(f & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) || !(f & locations)) return false;
    const VkChromaLocation location = (f & VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT)
                                          ? VK_CHROMA_LOCATION_MIDPOINT
                                          : VK_CHROMA_LOCATION_COSITED_EVEN;
    auto conversion = vkrc::SamplerYcbcrConversion::create(
        device, {.format = nv12, .x_chroma_offset = location, .y_chroma_offset = location});
    auto sampler = vkrc_test::ycbcr_sampler(device, conversion);
    auto image =
        vkrc::Image::create(device, {.format = nv12, .extent = {4, 4, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto view = vkrc::ImageView::create(image, {.ycbcr_conversion = conversion});
    return true;
}

struct FillParams {
    std::uint32_t count;
    std::uint32_t seed;
};

}  // namespace

ScenarioResult run_compute_scenario(const vkrc::InstanceCreateInfo& info) {
    Context c;
    c.instance = vkrc::Instance::create(info);
    c.physical = vkrc::PhysicalDevice::select(c.instance, test_device_requirements());
    const bool ycbcr = supported_features(c.physical).v11.samplerYcbcrConversion;
    vkrc::DeviceCreateInfo device_info;
    device_info.vulkan13_features.privateData = VK_TRUE;
    device_info.vulkan11_features.samplerYcbcrConversion = ycbcr;
    c.device = vkrc::Device::create(c.physical, device_info);
    c.queue = c.device.default_queue();
    faults::end_of_setup();
    const auto& device = c.device;
    ScenarioResult result;
    result.push_back(!vkrc::Instance::available_layers(info.get_instance_proc_addr).empty());
    result.push_back(ycbcr && use_ycbcr(c.physical, device));

    auto sampler = vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST, .min_filter = VK_FILTER_NEAREST});
    auto texels = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT});
    auto texel_view = vkrc::BufferView::create(texels, {.format = VK_FORMAT_R32_UINT});

    // The pipeline built once to fill a cache, then again from its data.
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(FillParams)}}});
    auto module = vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp);
    auto cache = vkrc::PipelineCache::create(device);
    vkrc::ComputePipeline::create(layout, {.module = module, .cache = cache});
    const auto blob = cache.data();
    auto warm_cache = vkrc::PipelineCache::create(device, blob);
    auto pipeline = vkrc::ComputePipeline::create(layout, {.module = module, .cache = warm_cache});

    // The output written into the set through an update template.
    constexpr std::uint32_t count = 64;
    auto out = readback_buffer(device, count * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vkrc::set_name(device, out, "compute output");
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 2, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}}});
    // A set dropped at once with its layout, which nothing else holds: the
    // next allocate, finding no set of its own layout to reuse, frees it.
    pool.allocate(vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}}));
    auto set = pool.allocate(set_layout);
    auto update = vkrc::DescriptorUpdateTemplate::create(
        device, {.entries = {{0, 0, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 0, sizeof(VkDescriptorBufferInfo)}},
                 .descriptor_set_layout = set_layout});
    const VkDescriptorBufferInfo target{out.vk(), 0, VK_WHOLE_SIZE};
    set.update_with_template(update, &target);

    auto queries = vkrc::QueryPool::create(device, {.query_count = 2});
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = c.queue.family_index()});
    auto cmd = commands.allocate();
    cmd.begin();
    cmd.reset_query_pool(queries, 0, 2);
    cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 0);
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, FillParams{count, 0x5eed});
    cmd.dispatch(1);
    cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 1);
    const auto to_host = compute_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();

    // The submission waits for a timeline value the host signals first (a
    // gate left closed would hold the GPU when an injected failure stops the
    // scenario), and signals another the host waits for.
    auto gate = vkrc::Semaphore::create_timeline(device);
    auto done = vkrc::Semaphore::create_timeline(device);
    gate.signal(1);
    const vkrc::SemaphoreSubmit wait{gate, 1, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
    const vkrc::SemaphoreSubmit signal{done, 2, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
    vkrc::submit(
        c.queue,
        {.waits = std::span(&wait, 1), .command_buffers = std::span(&cmd, 1), .signals = std::span(&signal, 1)});
    result.push_back(done.wait(2) == VK_SUCCESS);
    result.push_back(done.value());
    pool.allocate(set_layout);
    commands.reset_commands();

    std::array<std::uint32_t, count> values{};
    out.allocation().read(0, std::span(values));
    result.insert(result.end(), values.begin(), values.end());
    std::array<std::uint64_t, 2> ticks{};
    result.push_back(queries.results(0, std::span(ticks)) == VK_SUCCESS && ticks[1] >= ticks[0]);

    auto event = vkrc::Event::create(device);
    event.set();
    result.push_back(event.status() == VK_EVENT_SET);
    event.unset();
    result.push_back(event.status() == VK_EVENT_RESET);

    auto slot = vkrc::PrivateDataSlot::create(device);
    slot.set(VK_OBJECT_TYPE_BUFFER_VIEW, texel_view.vk(), 42);
    slot.set(VK_OBJECT_TYPE_SAMPLER, sampler.vk(), 43);
    result.push_back(slot.get(VK_OBJECT_TYPE_BUFFER_VIEW, texel_view.vk()));
    result.push_back(slot.get(VK_OBJECT_TYPE_SAMPLER, sampler.vk()));
    return result;
}

ScenarioResult run_render_pass_scenario(const vkrc::InstanceCreateInfo& info) {
    auto c = make_context(info);
    const auto& device = c.device;
    constexpr std::uint32_t side = 4;
    auto render_pass = vkrc_test::clear_to_copy_render_pass(device, VK_FORMAT_R8G8B8A8_UNORM);
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                     .extent = {side, side, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto framebuffer = vkrc::Framebuffer::create(
        device,
        {.render_pass = render_pass, .attachments = {vkrc::ImageView::create(image)}, .width = side, .height = side});
    auto readback = readback_buffer(device, side * side * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);

    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = c.queue.family_index()});
    auto cmd = commands.allocate();
    cmd.begin();
    VkClearValue clear{};
    clear.color = {{0.25f, 0.5f, 0.75f, 1.0f}};
    cmd.begin_render_pass(render_pass, framebuffer, {{0, 0}, {side, side}}, std::span(&clear, 1));
    cmd.end_render_pass();
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {side, side, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, std::span(&region, 1));
    const auto to_host = copy_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    run_and_wait(c.queue, cmd);

    std::array<std::uint32_t, side * side> pixels{};
    readback.allocation().read(0, std::span(pixels));
    return ScenarioResult(pixels.begin(), pixels.end());
}

ScenarioResult run_streaming_scenario(const vkrc::InstanceCreateInfo& info) {
    auto c = make_context(info);
    const auto& device = c.device;
    ScenarioResult result;

    // Two uploads in one batch, then a download of each in the next.
    auto uploader = vkrc::Uploader::create({.queue = c.queue, .staging_size = 64 << 10});
    std::array<std::uint32_t, 16> words{};
    for (std::uint32_t i = 0; i < words.size(); ++i) words[i] = 0x1000 + i;
    auto buffer = vkrc::Buffer::create(
        device, {.size = sizeof words, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    uploader.upload_buffer(buffer, 0, std::as_bytes(std::span(words)));
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                     .extent = {4, 4, 1},
                                     .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    uploader.upload_image(image, std::as_bytes(std::span(words)), {.new_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL});
    uploader.submit().wait_on_host();
    auto buffer_download = uploader.download_buffer(buffer, 0, sizeof words);
    auto image_download = uploader.download_image(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    uploader.submit();
    for (const auto& download : {buffer_download, image_download}) {
        const auto bytes = download.read();
        std::array<std::uint32_t, 16> got{};
        std::memcpy(got.data(), bytes.data(), std::min(bytes.size(), sizeof got));
        result.insert(result.end(), got.begin(), got.end());
    }

    // Three frames through a two-block ring, each copied out.
    constexpr VkDeviceSize slice = 16;
    auto ring = vkrc::FrameRing::create(
        {.queue = c.queue, .frame_size = 256, .frames_in_flight = 2, .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    auto out = readback_buffer(device, 3 * slice, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = c.queue.family_index()});
    for (std::uint32_t frame = 0; frame < 3; ++frame) {
        ring.begin_frame();
        auto a = ring.allocate(slice);
        const std::array<std::uint32_t, 4> value{frame + 1, frame + 2, frame + 3, frame + 4};
        a.view.write(0, std::span<const std::uint32_t>(value));
        auto cmd = commands.allocate();
        cmd.begin();
        const VkBufferCopy region{a.offset, frame * slice, slice};
        cmd.copy_buffer(a.buffer, out.vk(), {&region, 1});
        if (frame == 2) {
            const auto to_host = copy_to_host();
            cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
        }
        cmd.end();
        vkrc::submit(c.queue, {.command_buffers = {&cmd, 1}});
        ring.end_frame();
    }
    c.queue.wait_idle();
    std::array<std::uint32_t, 12> copied{};
    out.allocation().read(0, std::span(copied));
    result.insert(result.end(), copied.begin(), copied.end());
    return result;
}

ScenarioResult run_non_coherent_scenario(const vkrc::InstanceCreateInfo& info) {
    struct Hidden {
        Hidden() { faults::hide_host_coherence(true); }
        ~Hidden() { faults::hide_host_coherence(false); }
    } hidden;
    auto c = make_context(info);
    const auto& device = c.device;
    auto upload = vkrc::Buffer::create(
        device,
        {.size = 64, .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT, .memory = {.usage = vkrc::MemoryUsage::upload}});
    const std::array<std::uint32_t, 4> value{7, 11, 13, 17};
    upload.allocation().write(0, value.data(), value.size());  // flushes
    auto readback = readback_buffer(device, 64, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = c.queue.family_index()});
    auto cmd = commands.allocate();
    cmd.begin();
    const VkBufferCopy region{0, 16, sizeof value};
    cmd.copy_buffer(upload, readback, {&region, 1});
    const auto to_host = copy_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    run_and_wait(c.queue, cmd);
    std::array<std::uint32_t, 4> got{};
    readback.allocation().read(16, got.data(), got.size());  // invalidates
    return {readback.allocation().host_coherent(), got[0], got[1], got[2], got[3]};
}

namespace {

// What acceleration structures and the ray query shader need of a device.
vkrc::DeviceCreateInfo ray_query_device_info() {
    vkrc::DeviceCreateInfo info;
    info.acceleration_structure_features.accelerationStructure = VK_TRUE;
    info.ray_query_features.rayQuery = VK_TRUE;
    info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
    return info;
}

bool has_ray_queries(const vkrc::PhysicalDevice& physical) {
    auto wanted = test_device_requirements();
    wanted.required_features.acceleration_structure.accelerationStructure = VK_TRUE;
    wanted.required_features.ray_query.rayQuery = VK_TRUE;
    wanted.required_features.vulkan12.bufferDeviceAddress = VK_TRUE;
    return physical.unmet_requirements(wanted).empty();
}

// A host-written buffer of values a structure build reads by address.
template <class T, std::size_t N>
vkrc::Buffer build_input(const vkrc::Device& device, const std::array<T, N>& values) {
    constexpr VkBufferUsageFlags usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                         VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
    auto buffer = vkrc::Buffer::create(
        device, {.size = sizeof values, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::upload}});
    buffer.allocation().write(0, values.data(), values.size());
    return buffer;
}

// A barrier from builds and copies of structures to what reads them next (stage).
void after_builds(const vkrc::CommandBuffer& cmd, VkPipelineStageFlags2 stage) {
    const auto b = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                                        VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, stage,
                                        VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    cmd.pipeline_barrier(std::span(&b, 1), {}, {});
}

}  // namespace

bool device_has_ray_queries(const vkrc::InstanceCreateInfo& info) {
    auto instance = vkrc::Instance::create(info);
    return has_ray_queries(vkrc::PhysicalDevice::select(instance, test_device_requirements()));
}

ScenarioResult run_acceleration_structure_scenario(const vkrc::InstanceCreateInfo& info) {
    Context c;
    c.instance = vkrc::Instance::create(info);
    c.physical = vkrc::PhysicalDevice::select(c.instance, test_device_requirements());
    if (!has_ray_queries(c.physical)) return {};
    c.device = vkrc::Device::create(c.physical, ray_query_device_info());
    c.queue = c.device.default_queue();
    faults::end_of_setup();
    const auto& device = c.device;
    auto commands = vkrc::CommandPool::create(device, {.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                                                       .queue_family_index = c.queue.family_index()});
    auto cmd = commands.allocate();

    // The square [0,4]x[0,4] at z 0, two indexed triangles, built for compaction.
    const std::array<float, 12> square{0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 4, 0};
    const std::array<std::uint32_t, 6> indices{0, 1, 2, 0, 2, 3};
    auto vertices = build_input(device, square);
    auto index_buffer = build_input(device, indices);
    vkrc::BottomLevelBuildInfo bottom;
    bottom.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                   VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
    bottom.geometries = {
        {.vertex_buffer = vertices, .max_vertex = 3, .index_buffer = index_buffer, .triangle_count = 2}};
    auto sizes = vkrc::QueryPool::create(
        device, {.query_type = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, .query_count = 1});
    cmd.begin();
    auto square_level = vkrc::build_bottom_level(cmd, bottom);
    after_builds(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    cmd.reset_query_pool(sizes, 0, 1);
    const VkAccelerationStructureKHR raw = square_level.vk();
    cmd.write_acceleration_structures_properties(std::span(&raw, 1),
                                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, sizes, 0);
    cmd.end();
    run_and_wait(c.queue, cmd);
    std::array<std::uint64_t, 1> compacted{};
    if (sizes.results(0, std::span(compacted)) != VK_SUCCESS) throw std::logic_error("no compacted size");

    // The compacted copy, the original dropped once the copy is recorded;
    // the scene: the copy at the origin (custom 5) and moved right by 4 (custom 7).
    cmd.reset_commands();
    cmd.begin();
    after_builds(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);  // the compaction copy reads it
    auto small = vkrc::compact(cmd, square_level, compacted[0]);
    square_level.reset();
    after_builds(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    vkrc::TopLevelBuildInfo top;
    top.instances = {
        {.bottom_level = small, .custom_index = 5},
        {.bottom_level = small, .transform = {{{1, 0, 0, 4}, {0, 1, 0, 0}, {0, 0, 1, 0}}}, .custom_index = 7}};
    auto scene = vkrc::build_top_level(cmd, top);
    small.reset();  // the scene keeps it

    // Traced: one ray per pixel of 8x8, each reporting custom index << 8 | geometry (0xFFFFFFFF: a miss).
    constexpr std::uint32_t side = 8;
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR},
                              {.binding = 1, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    const std::array<std::uint32_t, 3> params{side, side, 0xFF};  // width, height, cull mask
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof params}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::ray_query_comp));
    auto pool = vkrc::DescriptorPool::create(device, {.max_sets = 1,
                                                      .pool_sizes = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto hits = readback_buffer(device, side * side * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    auto set = pool.allocate(set_layout);
    set.write_acceleration_structure(0, scene);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, hits);
    scene.reset();  // the set keeps it
    after_builds(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, params);
    cmd.dispatch(1, 1);
    const auto to_host = compute_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    run_and_wait(c.queue, cmd);
    std::array<std::uint32_t, side * side> traced{};
    hits.allocation().read(0, std::span(traced));
    ScenarioResult result(traced.begin(), traced.end());
    result.push_back(compacted[0]);
    return result;
}

namespace {

// What the ray tracing pipeline scenario needs of a device.
vkrc::DeviceCreateInfo ray_tracing_device_info() {
    vkrc::DeviceCreateInfo info;
    info.ray_tracing_pipeline_features.rayTracingPipeline = VK_TRUE;  // enables the extensions
    info.acceleration_structure_features.accelerationStructure = VK_TRUE;
    info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
    return info;
}

bool has_ray_tracing_pipelines(const vkrc::PhysicalDevice& physical) {
    auto wanted = test_device_requirements();
    wanted.required_features.ray_tracing_pipeline.rayTracingPipeline = VK_TRUE;
    wanted.required_features.acceleration_structure.accelerationStructure = VK_TRUE;
    wanted.required_features.vulkan12.bufferDeviceAddress = VK_TRUE;
    return physical.unmet_requirements(wanted).empty();
}

// The shaders of tests/ray_tracing_test.cpp without the any-hit and
// intersection stages: raygen, the scene's and the shadows' misses, the
// closest hit (which traces the shadow ray, hence depth 2) and the callable.
vkrc::RayTracingPipeline rt_scene_pipeline(const vkrc::PipelineLayout& layout) {
    const auto& device = layout.device();
    auto stage = [&](VkShaderStageFlagBits bits, std::span<const std::uint32_t> code) {
        return vkrc::RayTracingShaderStage{.stage = bits, .module = vkrc::ShaderModule::create(device, code)};
    };
    vkrc::RayTracingPipelineCreateInfo info;
    info.stages = {stage(VK_SHADER_STAGE_RAYGEN_BIT_KHR, vkrc_shaders::rt_scene_rgen),
                   stage(VK_SHADER_STAGE_MISS_BIT_KHR, vkrc_shaders::rt_scene_rmiss),
                   stage(VK_SHADER_STAGE_MISS_BIT_KHR, vkrc_shaders::rt_shadow_rmiss),
                   stage(VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, vkrc_shaders::rt_scene_rchit),
                   stage(VK_SHADER_STAGE_CALLABLE_BIT_KHR, vkrc_shaders::rt_scene_rcall)};
    info.groups = {{.general_shader = 0},
                   {.general_shader = 1},
                   {.general_shader = 2},
                   {.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, .closest_hit_shader = 3},
                   {.general_shader = 4}};
    info.max_ray_recursion_depth = 2;
    return vkrc::RayTracingPipeline::create(layout, info);
}

}  // namespace

bool device_has_ray_tracing_pipelines(const vkrc::InstanceCreateInfo& info) {
    auto instance = vkrc::Instance::create(info);
    return has_ray_tracing_pipelines(vkrc::PhysicalDevice::select(instance, test_device_requirements()));
}

ScenarioResult run_ray_tracing_pipeline_scenario(const vkrc::InstanceCreateInfo& info) {
    Context c;
    c.instance = vkrc::Instance::create(info);
    c.physical = vkrc::PhysicalDevice::select(c.instance, test_device_requirements());
    if (!has_ray_tracing_pipelines(c.physical)) return {};
    c.device = vkrc::Device::create(c.physical, ray_tracing_device_info());
    c.queue = c.device.default_queue();
    faults::end_of_setup();
    const auto& device = c.device;

    // The square [0,4]x[0,4], two triangles (the first below its diagonal):
    // seen at x + 0.25 (no pixel centre on an edge; custom 5, mask 0x01) and,
    // doubled at z 5 over y [2,10], as the occluder only shadow rays see (mask 0x02).
    const std::array<float, 18> square{0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 0, 0, 4, 4, 0, 0, 4, 0};
    auto vertices = build_input(device, square);
    vkrc::BottomLevelBuildInfo bottom;
    bottom.geometries = {{.vertex_buffer = vertices, .max_vertex = 5, .triangle_count = 2}};
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = c.queue.family_index()});
    auto cmd = commands.allocate();
    cmd.begin();
    auto square_level = vkrc::build_bottom_level(cmd, bottom);
    after_builds(cmd, VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    vkrc::TopLevelBuildInfo top;
    top.instances = {{.bottom_level = square_level,
                      .transform = {{{1, 0, 0, 0.25f}, {0, 1, 0, 0}, {0, 0, 1, 0}}},
                      .custom_index = 5,
                      .mask = 0x01},
                     {.bottom_level = square_level,
                      .transform = {{{2, 0, 0, 0.25f}, {0, 2, 0, 2}, {0, 0, 2, 5}}},
                      .custom_index = 13,
                      .mask = 0x02}};
    auto scene = vkrc::build_top_level(cmd, top);
    square_level.reset();  // the scene keeps it

    // The set rt_scene.rgen writes results[y * 16 + x] through.
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR},
                              {.binding = 1, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    auto pool = vkrc::DescriptorPool::create(device, {.max_sets = 1,
                                                      .pool_sizes = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto results = readback_buffer(device, rt_width * rt_height * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    auto set = pool.allocate(set_layout);
    set.write_acceleration_structure(0, scene);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, results);
    scene.reset();  // the set keeps it

    // The pipeline, made last (compiling it is the slow part of a run, which
    // a failure before it skips), and its table: the miss record's value, the
    // hit record's tag, the callable record's bits (shaderRecordEXT of rt_scene.r*).
    auto layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
    auto pipeline = rt_scene_pipeline(layout);
    const std::array<std::uint32_t, 3> record_data{rt_miss_value, rt_hit_tag, rt_callable_bits};
    vkrc::ShaderBindingTableCreateInfo table_info;
    table_info.raygen = {0};
    table_info.miss = {{1, std::as_bytes(std::span(&record_data[0], 1))}, {2}};
    table_info.hit = {{3, std::as_bytes(std::span(&record_data[1], 1))}};
    table_info.callable = {{4, std::as_bytes(std::span(&record_data[2], 1))}};
    auto table = vkrc::ShaderBindingTable::create(pipeline, table_info);
    pipeline.reset();  // the table keeps it

    // Traced: rt_scene.rgen's rays over 16x4.
    after_builds(cmd, VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR);
    cmd.bind_pipeline(table.pipeline());
    cmd.bind_descriptor_set(table.pipeline(), 0, set);
    cmd.trace_rays(table, rt_width, rt_height);
    const auto to_host =
        vkrc::memory_barrier(VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    run_and_wait(c.queue, cmd);
    std::array<std::uint32_t, rt_width * rt_height> traced{};
    results.allocation().read(0, std::span(traced));
    return ScenarioResult(traced.begin(), traced.end());
}

ScenarioResult run_presentation_scenario(const vkrc::InstanceCreateInfo& info, const vkrc::glfw::Window& window) {
    auto instance = vkrc::Instance::create(info);
    auto surface = vkrc::glfw::create_surface(instance, window.get());
    faults::end_of_setup();
    auto requirements = test_device_requirements();
    requirements.present_surface = surface.vk();
    requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    auto physical = vkrc::PhysicalDevice::select(instance, requirements);
    auto device = vkrc::Device::create(physical, {.enabled_extension_names = {VK_KHR_SWAPCHAIN_EXTENSION_NAME}});
    auto queue = device.default_queue();
    auto swapchain = vkrc::Swapchain::create(
        queue, surface, {.image_usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    auto commands = vkrc::CommandPool::create(
        device, {.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, .queue_family_index = queue.family_index()});
    std::array<vkrc::CommandBuffer, 2> cmds{commands.allocate(), commands.allocate()};
    std::array<vkrc::Fence, 2> fences{vkrc::Fence::create(device, true), vkrc::Fence::create(device, true)};

    ScenarioResult result;
    vkrc::Frame frame;
    auto render = [&](int i) {
        const auto& cmd = cmds[i % 2];
        fences[i % 2].wait();
        result.push_back(static_cast<std::uint64_t>(swapchain.acquire(frame)));
        if (!frame) return;
        fences[i % 2].unsignal();
        cmd.reset_commands();
        cmd.begin();
        const auto to_clear = vkrc::image_barrier(frame.image().vk(), VK_IMAGE_LAYOUT_UNDEFINED,
                                                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, vkrc::Frame::acquire_stage, 0,
                                                  VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        cmd.pipeline_barrier({}, {}, std::span(&to_clear, 1));
        const VkClearColorValue colour{{0.1f, 0.2f, 0.3f, 1.0f}};
        const VkImageSubresourceRange whole{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        cmd.clear_color_image(frame.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, colour, std::span(&whole, 1));
        const auto to_present = vkrc::image_barrier(frame.image().vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                                    frame.present_layout, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                                                    VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_NONE, 0);
        cmd.pipeline_barrier({}, {}, std::span(&to_present, 1));
        cmd.end();
        vkrc::submit(queue, {.waits = frame.waits(), .command_buffers = std::span(&cmd, 1), .signals = frame.signals()},
                     fences[i % 2]);
        result.push_back(static_cast<std::uint64_t>(swapchain.present(frame)));
    };
    for (int i = 0; i < 3; ++i) render(i);
    result.push_back(static_cast<std::uint64_t>(swapchain.recreate()));
    render(3);
    for (const auto& f : fences) f.wait();
    result.push_back(swapchain.extent().width);
    result.push_back(swapchain.extent().height);
    return result;
}

}  // namespace vkrc_test
