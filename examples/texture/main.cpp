// Uploads a texture with all its mip levels, samples chosen levels in a
// fragment shader and checks every pixel on the CPU:
//     texture [--validation]
// Each level is a checkerboard generated on the CPU in its own colour, so the
// output shows which level was read. The three levels drawn land side by side
// in one image; each draw gets its own viewport and LOD (a push constant).
#include <vkrc/vkrc.hpp>

#include "shaders/fullscreen.vert.h"
#include "shaders/texture_lod.frag.h"

#include <array>
#include <cstdio>
#include <cstring>
#include <exception>
#include <span>
#include <vector>

namespace {

constexpr std::uint32_t size = 64, levels = 7;  // 64x64 down to 1x1
constexpr std::array<std::uint32_t, 3> drawn_levels = {0, 2, 4};
constexpr VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;

// Texel (x, y) of a level: 4x4 cells alternating between the level's colour and black.
std::array<std::uint8_t, 4> texel(std::uint32_t level, std::uint32_t x, std::uint32_t y) {
    static constexpr std::uint8_t colors[levels][3] = {{255, 0, 0},   {0, 255, 0},   {0, 0, 255},    {255, 255, 0},
                                                       {0, 255, 255}, {255, 0, 255}, {255, 255, 255}};
    if ((x / 4 + y / 4) % 2 == 1) return {0, 0, 0, 255};
    return {colors[level][0], colors[level][1], colors[level][2], 255};
}

int run(bool validation) {
    // 1. Instance, device, a graphics queue and, where the device has one,
    //    a transfer queue of its own (else transfers share the graphics queue).
    auto instance = vkrc::Instance::create({.application_name = "vkrc texture", .validation = validation});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance), {.transfer_queue = true});
    auto queue = device.queue_for(vkrc::QueueRole::graphics).queue;
    auto transfer = device.queue_for(vkrc::QueueRole::transfer).queue;
    std::printf("device: %s\n", device.physical_device().name());

    // 2. The texture, and every mip level generated on the CPU, streamed on
    //    the transfer queue: the Uploader takes the levels one after the
    //    other, tightly packed, and leaves the image in
    //    SHADER_READ_ONLY_OPTIMAL. Nothing waits here; the draw's submit
    //    waits on the ticket (step 6).
    auto texture = vkrc::Image::create(device, {.format = format,
                                                .extent = {size, size, 1},
                                                .mip_levels = levels,
                                                .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    std::vector<std::byte> texels;
    texels.reserve(vkrc::image_data_size(texture));
    for (std::uint32_t level = 0; level < levels; ++level) {
        auto extent = texture.extent(level);
        for (std::uint32_t y = 0; y < extent.height; ++y)
            for (std::uint32_t x = 0; x < extent.width; ++x)
                for (auto c : texel(level, x, y)) texels.push_back(std::byte{c});
    }
    auto uploader = vkrc::Uploader::create({.queue = transfer});
    uploader.upload_image(texture, texels);
    const vkrc::Ticket uploaded = uploader.submit();

    // 3. A view of all levels, a sampler that picks the nearest texel of one
    //    level, and a descriptor set binding the two for the fragment shader.
    auto view = vkrc::ImageView::create(texture);
    auto sampler = vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST,
                                                  .min_filter = VK_FILTER_NEAREST,
                                                  .mipmap_mode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
                                                  .address_mode_u = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                                                  .address_mode_v = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE});
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                               .stage_flags = VK_SHADER_STAGE_FRAGMENT_BIT}}});
    auto descriptor_pool = vkrc::DescriptorPool::create(
        device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}}});
    auto set = descriptor_pool.allocate(set_layout);
    set.write_image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    sampler);

    // 4. The pipeline: a full-viewport triangle (no culling: it is clockwise)
    //    and textureLod with the level from a push constant.
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(float)}}});
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::fullscreen_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::texture_lod_frag))
            .cull_mode(VK_CULL_MODE_NONE)
            .rendering(std::array{format})
            .build();

    // 5. The target: one size x size square per drawn level, side by side.
    const std::uint32_t width = size * std::uint32_t(drawn_levels.size());
    auto target =
        vkrc::Image::create(device, {.format = format,
                                     .extent = {width, size, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto target_view = vkrc::ImageView::create(target);

    // 6. Record one draw per level, each into its own square, then leave the
    //    target ready to be copied out.
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    uploaded.record_acquire(cmd);  // the ownership acquire when the families differ
    auto to_attachment = vkrc::image_barrier(target, vkrc::use::none, vkrc::use::colour_attachment_write);
    cmd.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
    vkrc::RenderingAttachment attachment{.image_view = target_view.vk()};
    cmd.begin_rendering({.render_area = {{0, 0}, {width, size}}, .color_attachments = std::span(&attachment, 1)});
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    for (std::uint32_t i = 0; i < drawn_levels.size(); ++i) {
        const float x = float(i * size), lod = float(drawn_levels[i]);
        cmd.set_viewport({x, 0.0f, float(size), float(size), 0.0f, 1.0f});
        cmd.set_scissor({{std::int32_t(i * size), 0}, {size, size}});
        cmd.push_constants(layout, VK_SHADER_STAGE_FRAGMENT_BIT, lod);
        cmd.draw(3);
    }
    cmd.end_rendering();
    auto to_copy = vkrc::image_barrier(target, vkrc::use::colour_attachment_write, vkrc::use::transfer_src);
    cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
    cmd.end();
    auto done = vkrc::Fence::create(device);
    const vkrc::SemaphoreSubmit wait = uploaded.wait(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
    vkrc::submit(queue, {.waits = std::span(&wait, 1), .command_buffers = std::span(&cmd, 1)}, done);
    if (done.wait() != VK_SUCCESS) return 1;

    // 7. Read the target back and check every pixel: pixel x of a square
    //    reads texel x >> level of that level.
    auto pixels = vkrc::download_image(queue, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    std::uint32_t mismatches = 0;
    for (std::uint32_t i = 0; i < drawn_levels.size(); ++i) {
        const std::uint32_t level = drawn_levels[i], before = mismatches;
        for (std::uint32_t y = 0; y < size; ++y)
            for (std::uint32_t x = 0; x < size; ++x) {
                const auto expected = texel(level, x >> level, y >> level);
                mismatches += std::memcmp(&pixels[(y * width + i * size + x) * 4], expected.data(), 4) != 0;
            }
        std::printf("level %u (%ux%u): %s\n", level, size >> level, size >> level,
                    mismatches == before ? "every pixel matches" : "MISMATCH");
    }
    return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    const bool validation = argc > 1 && std::strcmp(argv[1], "--validation") == 0;
    try {
        return run(validation);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "texture: %s\n", e.what());
        return 1;
    }
}
