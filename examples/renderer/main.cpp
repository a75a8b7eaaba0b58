// A small forward renderer written only against vkrc (no raw Vulkan call), to be read top to bottom:
// teapots (scene.hpp) on a textured ground under a directional light, a shadow map, bindless textures
// in a vkrc::BindlessTable (mip chains blitted on the GPU; one texture streamed out and a new one in
// every few frames on the transfer queue), a multisampled HDR main pass recorded on several threads,
// a compute tone-map, GPU timestamps per pass.
//     renderer [--threads N] [--frames N] [--resize-every N] [--report N] [--validation]   a window
//     renderer --headless [--out FILE.png] [--frames N] [--threads N] [--validation]  (1 frame by default)
#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include <GLFW/glfw3.h>

#include "renderer/scene.hpp"
#include "shaders/renderer_scene.frag.h"
#include "shaders/renderer_scene.vert.h"
#include "shaders/renderer_shadow.vert.h"
#include "shaders/renderer_tonemap.comp.h"
#include "support/window_or_headless.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <span>
#include <thread>
#include <vector>

namespace {

constexpr bool multi_thread = VKRC_IS_MULTI_THREAD != 0;  // which vkrc policy this build links
constexpr VkFormat hdr_format = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat depth_format = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat ldr_format = VK_FORMAT_R8G8B8A8_UNORM;  // what the tone-map shader stores (rgba8)
constexpr std::uint32_t shadow_size = 1024, texture_size = 256, frames_in_flight = 2;
// The table's size, within the device's limits: a few textures are live at a time, and a larger
// table would be pool memory held for nothing.
constexpr std::uint32_t max_textures = 256;
constexpr int fixed_level = 16;  // the tessellation a renderer without LOD would draw everywhere

// The uniforms every draw reads (set 0, binding 0; in the frame ring), and one draw's push constants
// (texture_index: the draw's material's slot in the bindless table, set 1).
struct FrameUniforms {
    glm::mat4 view_proj, light_view_proj;
    glm::vec4 light_direction, camera_position;
};
struct DrawConstants {
    glm::mat4 world;
    std::uint32_t texture_index;
    float uv_scale;
};
// Every mesh's vertices and indices, appended to one set of arrays; a mesh is a range of them.
struct MeshRange {
    std::uint32_t first_index, index_count;
    std::int32_t vertex_offset;
};
struct Geometry {
    std::vector<glm::vec3> positions, normals;
    std::vector<std::uint16_t> indices;
    MeshRange add(const teapot::Mesh& m) {
        const MeshRange r{std::uint32_t(indices.size()), std::uint32_t(m.indices.size()),
                          std::int32_t(positions.size())};
        positions.insert(positions.end(), m.positions.begin(), m.positions.end());
        normals.insert(normals.end(), m.normals.begin(), m.normals.end());
        indices.insert(indices.end(), m.indices.begin(), m.indices.end());
        return r;
    }
};
struct Draw {
    glm::mat4 world;
    std::uint32_t material;  // 0: the ground's; then scene.hpp's Teapot::texture
    float uv_scale;
    MeshRange mesh;
};
// One tessellation level of the teapot, with its largest distance from the exact surface (model units).
struct Lod {
    int level;
    double error;
    MeshRange mesh;
};

// Texel (x, y) of procedural texture index: ground tiles, red stripes, blue dots.
std::array<std::uint8_t, 4> texel(std::uint32_t index, std::uint32_t x, std::uint32_t y) {
    using Rgba = std::array<std::uint8_t, 4>;
    const std::uint8_t v = x % 64 < 3 || y % 64 < 3 ? 150 : (x / 64 + y / 64) % 2 ? 190 : 215;
    const int dx = int(x % 32) - 16, dy = int(y % 32) - 16;
    if (index == 0) return {v, std::uint8_t(v - 12), std::uint8_t(v - 30), 255};
    if (index == 1) return (x + y) % 64 < 24 ? Rgba{200, 40, 30, 255} : Rgba{235, 220, 190, 255};
    return dx * dx + dy * dy < 64 ? Rgba{240, 240, 245, 255} : Rgba{40, 80, 190, 255};
}

// The texture streamed in at step (scene.hpp): every mip level, box-filtered on the CPU (a transfer
// queue cannot blit), packed level after level as the Uploader takes them.
std::vector<std::uint8_t> streamed_texels(std::uint32_t step) {
    const auto colour = renderer::streamed_colour(step);
    std::vector<std::uint8_t> texels;
    for (std::uint32_t y = 0; y < texture_size; ++y)
        for (std::uint32_t x = 0; x < texture_size; ++x) {
            for (const std::uint8_t c : colour) texels.push_back((x + y) % 32 < 16 ? c : std::uint8_t(c * 3 / 4));
            texels.push_back(255);
        }
    std::size_t level = 0;  // where the level being halved starts
    for (std::uint32_t size = texture_size; size > 1; size /= 2) {
        const std::size_t next = texels.size();
        for (std::uint32_t y = 0; y < size; y += 2)
            for (std::uint32_t x = 0; x < size; x += 2)
                for (std::uint32_t c = 0; c < 4; ++c) {
                    auto at = [&](std::uint32_t u, std::uint32_t v) {
                        return unsigned(texels[level + (v * size + u) * 4 + c]);
                    };
                    texels.push_back(std::uint8_t((at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1) + 2) / 4));
                }
        level = next;
    }
    return texels;
}

// The images the main pass and the tone-map use, re-created when the presented extent changes.
struct Targets {
    VkExtent2D extent{};
    vkrc::Image msaa, hdr, depth, ldr;  // msaa: empty without MSAA; ldr: only where the output is blitted
    vkrc::ImageView msaa_view, hdr_view, depth_view, ldr_view;
};

// A single-level 2D image and its view.
vkrc::Image image(const vkrc::Device& device, VkFormat format, VkExtent2D extent, VkSampleCountFlagBits samples,
                  VkImageUsageFlags usage, vkrc::ImageView& view) {
    auto i = vkrc::Image::create(
        device, {.format = format, .extent = {extent.width, extent.height, 1}, .samples = samples, .usage = usage});
    view = vkrc::ImageView::create(i);
    return i;
}

Targets make_targets(const vkrc::Device& device, VkExtent2D e, VkSampleCountFlagBits samples, bool blit) {
    constexpr auto colour = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    constexpr auto one = VK_SAMPLE_COUNT_1_BIT;
    Targets t;
    t.extent = e;
    if (samples != one) t.msaa = image(device, hdr_format, e, samples, colour, t.msaa_view);
    t.hdr = image(device, hdr_format, e, one, colour | VK_IMAGE_USAGE_SAMPLED_BIT, t.hdr_view);
    t.depth = image(device, depth_format, e, samples, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, t.depth_view);
    if (blit)
        t.ldr =
            image(device, ldr_format, e, one, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, t.ldr_view);
    return t;
}

// The images' uses through a frame are named (vkrc/access.hpp); a barrier goes from one to the next,
// with the aspect taken from the image's format. A discarded previous use keeps the order but lets
// the layout transition drop the old contents.
namespace use = vkrc::use;
constexpr vkrc::Use fragment_read = use::sampled(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
constexpr vkrc::Use compute_read = use::sampled(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);

int run(const vkrc_examples::WindowOrHeadless& options) {
    // 1. Instance, device and presenter, as in examples/teapot. Headless, the tone-map writes the
    //    presented image itself (storage usage); a window's swapchain formats seldom allow storage,
    //    so there it writes an intermediate that is blitted into the swapchain image.
    const auto threads = std::uint32_t(options.threads > 0 ? options.threads : multi_thread ? 2 : 1);
    if (!multi_thread && threads > 1) throw std::runtime_error("the st build records on one thread: --threads 1");
    vkrc::InstanceCreateInfo instance_info{.application_name = "vkrc renderer", .validation = options.validation};
    vkrc::DeviceRequirements requirements;
    // The textures are bindless (a vkrc::BindlessTable, indexed by a push constant): a device
    // without descriptor indexing is rejected, with the missing features named.
    auto& indexing = requirements.required_features.vulkan12;
    indexing.runtimeDescriptorArray = indexing.descriptorBindingPartiallyBound = VK_TRUE;
    indexing.descriptorBindingSampledImageUpdateAfterBind = indexing.descriptorBindingUpdateUnusedWhilePending =
        VK_TRUE;
    vkrc::glfw::WindowSurface window;
    if (!options.headless) {
        window =
            vkrc::glfw::create_window_surface({.width = 480, .height = 270, .title = "vkrc renderer"}, instance_info);
        requirements.present_surface = window.surface.vk();
        requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    auto instance = options.headless ? vkrc::Instance::create(instance_info) : window.instance;
    const auto physical = vkrc::PhysicalDevice::select(instance, requirements);
    // A transfer queue of its own where the device has one: textures stream in on it while frames render.
    auto device = vkrc::Device::create(physical, {.transfer_queue = true,
                                                  .enabled_extension_names = requirements.required_extensions,
                                                  .vulkan12_features = indexing});
    auto queue = device.default_queue();
    const auto transfer = device.queue_for(vkrc::QueueRole::transfer);
    const bool blit_output = !options.headless;
    vkrc::Swapchain swapchain;
    vkrc::HeadlessPresenter headless;
    if (options.headless)
        headless = vkrc::HeadlessPresenter::create(
            queue, {.extent = {480, 270}, .format = ldr_format, .image_usage = VK_IMAGE_USAGE_STORAGE_BIT});
    else
        swapchain = vkrc::Swapchain::create(
            queue, window.surface,
            {.preferred_formats = {{VK_FORMAT_B8G8R8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
                                   {VK_FORMAT_R8G8B8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR}},
             .image_usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    vkrc::Presenter& presenter = options.headless ? static_cast<vkrc::Presenter&>(headless) : swapchain;
    const auto& limits = physical.properties().limits;
    const auto samples = VkSampleCountFlagBits(
        limits.framebufferColorSampleCounts & limits.framebufferDepthSampleCounts & VK_SAMPLE_COUNT_4_BIT ? 4 : 1);
    std::printf("device: %s; transfers on %s; %ux MSAA; %u recording thread(s)\n", physical.name(),
                transfer.shares_graphics_queue ? "the graphics queue" : "a queue of their own", unsigned(samples),
                threads);

    // 2. Geometry: the ground and the teapot at several tessellation levels, each with its error
    //    against the exact surface, so that each teapot is drawn as coarse as its size allows.
    Geometry geometry;
    const float g = renderer::ground_half_size;
    const MeshRange ground = geometry.add(
        {{{-g, -g, 0}, {g, -g, 0}, {g, g, 0}, {-g, g, 0}}, std::vector(4, glm::vec3(0, 0, 1)), {0, 1, 2, 0, 2, 3}, {}});
    std::vector<Lod> lods;
    for (int level : {2, 3, 4, 5, 6, 7, 8, 10, 12, fixed_level}) {
        const auto mesh = teapot::tessellate(teapot::newell_teapot(), level);
        lods.push_back({level, teapot::geometric_error(teapot::newell_teapot(), mesh, 3).max, geometry.add(mesh)});
    }

    // 3. Loading: the buffers and each texture's level 0 (generated here) go through an Uploader
    //    in one batch; the mip chains are then blitted on the GPU, every level read back and checked.
    //    The textures go into the bindless table, which holds them from then on (step 4).
    auto uploader = vkrc::Uploader::create({.queue = queue, .staging_size = 8 << 20});
    constexpr auto transfer_dst = VK_BUFFER_USAGE_TRANSFER_DST_BIT;  // the same bit for images
    auto gpu_buffer = [&](const auto& data, VkBufferUsageFlags usage) {
        const auto bytes = std::as_bytes(std::span(data));
        auto buffer = vkrc::Buffer::create(device, {.size = bytes.size(), .usage = usage | transfer_dst});
        uploader.upload_buffer(buffer, 0, bytes);
        return buffer;
    };
    auto positions = gpu_buffer(geometry.positions, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    auto normals = gpu_buffer(geometry.normals, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    auto indices = gpu_buffer(geometry.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    const std::uint32_t mip_levels = std::uint32_t(std::log2(texture_size)) + 1;
    std::vector<vkrc::Image> textures;
    for (std::uint32_t index = 0; index < 3; ++index) {
        constexpr auto usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | transfer_dst;
        const VkExtent3D extent{texture_size, texture_size, 1};
        textures.push_back(vkrc::Image::create(
            device, {.format = ldr_format, .extent = extent, .mip_levels = mip_levels, .usage = usage}));
        std::vector<std::uint8_t> texels;
        for (std::uint32_t y = 0; y < texture_size; ++y)
            for (std::uint32_t x = 0; x < texture_size; ++x)
                for (auto c : texel(index, x, y)) texels.push_back(c);
        uploader.upload_image(textures.back(), std::as_bytes(std::span(texels)),
                              {.new_layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, .level_count = 1});
    }
    const vkrc::Ticket uploaded = uploader.submit();
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto setup = pool.allocate();
    setup.begin();
    for (const auto& texture : textures) vkrc::generate_mipmaps(setup, texture);  // ends in SHADER_READ_ONLY
    setup.end();
    const auto after_upload = uploaded.wait(VK_PIPELINE_STAGE_2_BLIT_BIT);
    vkrc::submit(queue, {.waits = std::span(&after_upload, 1), .command_buffers = std::span(&setup, 1)});
    std::vector<vkrc::Download> levels;
    for (const auto& texture : textures)
        for (std::uint32_t level = 0; level < mip_levels; ++level)
            levels.push_back(uploader.download_image(texture, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, level));
    uploader.submit();
    // A blit halves the size and keeps the mean colour: every level must
    // have its level 0's (within rounding), which an unwritten one has not.
    std::array<double, 3> base{};
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const auto bytes = levels[i].read();
        std::array<double, 3> mean{};
        for (std::size_t b = 0; b < bytes.size(); ++b)
            if (b % 4 < 3) mean[b % 4] += double(bytes[b]) * 4.0 / double(bytes.size());
        if (i % mip_levels == 0) base = mean;
        for (int c = 0; c < 3; ++c)
            if (!(std::abs(mean[c] - base[c]) < 12.0)) throw std::runtime_error("a mip level was not written");
    }
    std::printf("textures: %zu x %u mip levels generated by blits, every level read back and checked\n",
                textures.size(), mip_levels);

    // 4. Descriptors. Set 0: the per-frame uniforms (a dynamic uniform buffer over the frame ring)
    //    and the shadow map, sampled with comparison. Set 1: the textures in a BindlessTable; a push
    //    constant holds a draw's index. The table keeps what it holds: a removed texture lives until
    //    the frames that may sample it are done, and its slot is reused after that.
    auto texture_sampler = vkrc::Sampler::create(device);  // trilinear, repeating
    auto table = vkrc::BindlessTable::create(
        device,
        {.image_capacity = std::min(max_textures, vkrc::BindlessTable::max_capacity(device, vkrc::BindlessKind::image)),
         .buffer_capacity = 0,
         .stage_flags = VK_SHADER_STAGE_FRAGMENT_BIT});
    std::vector<vkrc::BindlessIndex> materials;  // each material's texture: ground, stripes, dots
    for (const auto& texture : textures)
        materials.push_back(table.add(vkrc::ImageView::create(texture), texture_sampler));
    textures.clear();  // the table holds them now
    auto ring = vkrc::FrameRing::create({.queue = queue, .frame_size = 64 << 10, .frames_in_flight = frames_in_flight});
    vkrc::ImageView shadow_view;
    const auto shadow_map =
        image(device, depth_format, {shadow_size, shadow_size}, VK_SAMPLE_COUNT_1_BIT,
              VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, shadow_view);
    auto shadow_sampler = vkrc::Sampler::create(device, {.address_mode_u = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
                                                         .address_mode_v = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
                                                         .compare_enable = true,
                                                         .compare_op = VK_COMPARE_OP_LESS_OR_EQUAL,
                                                         .border_color = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE});
    constexpr VkShaderStageFlags graphics = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    auto frame_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1, graphics},
                              {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT}}});
    auto post_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT},
                              {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT}}});
    // One pool for set 0 and the tone-map's sets (one per frame in flight).
    auto descriptor_pool = vkrc::DescriptorPool::create(
        device, {.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT,
                 .max_sets = 1 + frames_in_flight,
                 .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, 1},
                                {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1 + frames_in_flight},
                                {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, frames_in_flight}}});
    auto frame_set = descriptor_pool.allocate(frame_layout);
    vkrc::write_dynamic_buffer(frame_set, 0, ring, sizeof(FrameUniforms));
    frame_set.write_image(1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, shadow_view,
                          VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, shadow_sampler);
    const std::array<VkDescriptorSet, 2> scene_sets{frame_set.vk(), table.set().vk()};

    // 5. Pipelines: the depth-only shadow pass (depth bias against acne),
    //    the multisampled HDR main pass, the tone-map compute shader.
    auto scene_layout =
        vkrc::PipelineLayout::create(device, {.set_layouts = {frame_layout, table.layout()},
                                              .push_constant_ranges = {{graphics, 0, sizeof(DrawConstants)}}});
    auto shadow_pipeline =
        vkrc::GraphicsPipelineBuilder(scene_layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::renderer_shadow_vert))
            .vertex_binding(0, sizeof(glm::vec3))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0)
            .rasterization({.cull_mode = VK_CULL_MODE_NONE,
                            .depth_bias_enable = true,
                            .depth_bias_constant_factor = 2.0f,
                            .depth_bias_slope_factor = 2.5f})
            .rendering({}, depth_format)
            .build();
    auto scene_pipeline =
        vkrc::GraphicsPipelineBuilder(scene_layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::renderer_scene_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::renderer_scene_frag))
            .vertex_binding(0, sizeof(glm::vec3))
            .vertex_binding(1, sizeof(glm::vec3))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0)
            .vertex_attribute(1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0)
            .cull_mode(VK_CULL_MODE_NONE)  // the spout and lid openings show inner faces
            .depth_test(true, true, VK_COMPARE_OP_LESS)
            .samples(samples)
            .rendering(std::array{hdr_format}, depth_format)
            .build();
    auto post_pipeline =
        vkrc::ComputePipeline::create(vkrc::PipelineLayout::create(device, {.set_layouts = {post_layout}}),
                                      vkrc::ShaderModule::create(device, vkrc_shaders::renderer_tonemap_comp));
    auto hdr_sampler =
        vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST, .min_filter = VK_FILTER_NEAREST});

    // Both passes bind the same sets and buffers, then draw; the main pass
    // does it in secondaries, which inherit no state from the primary. The
    // recorder by value keeps the table and the raw handle in registers
    // across the draws (docs/guide.md, "Command recording").
    auto record_draws = [&](vkrc::CommandRecorder cmd, const vkrc::GraphicsPipeline& pipeline, VkExtent2D extent,
                            std::uint32_t uniforms, std::span<const Draw> list) {
        cmd.bind_pipeline(pipeline);
        cmd.set_viewport_and_scissor(extent);
        cmd.bind_descriptor_sets(pipeline, 0, scene_sets, std::span(&uniforms, 1));
        cmd.bind_vertex_buffers(0, std::array{positions.vk(), normals.vk()}, std::array<VkDeviceSize, 2>{0, 0});
        cmd.bind_index_buffer(indices, 0, VK_INDEX_TYPE_UINT16);
        for (const Draw& d : list) {
            cmd.push_constants(scene_layout, graphics, DrawConstants{d.world, materials[d.material].index, d.uv_scale});
            cmd.draw_indexed(d.mesh.index_count, 1, d.mesh.first_index, d.mesh.vertex_offset);
        }
    };

    // 6. Per frame in flight: a primary command buffer, a fence, the tone-map's descriptor set and
    //    four timestamps (start, after shadow, main, post); and a command pool per recording thread.
    struct FrameResources {
        vkrc::CommandBuffer cmd;
        vkrc::Fence done;
        vkrc::DescriptorSet post_set;
        bool timed = false;
    };
    std::array<FrameResources, frames_in_flight> in_flight;
    for (auto& f : in_flight)
        f = {pool.allocate(), vkrc::Fence::create(device, true), descriptor_pool.allocate(post_layout), false};
    std::vector<vkrc::CommandPool> thread_pools;  // a secondary returns to its pool once its frame is done
    for (std::uint32_t t = 0; t < threads; ++t)
        thread_pools.push_back(vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()}));
    auto timestamps = vkrc::QueryPool::create(device, {.query_count = 4 * frames_in_flight});
    std::array<double, 4> totals{};  // ms since the start: shadow, main, post (GPU), frame (CPU)
    double gpu_frames = 0, cpu_frames = 0;
    auto add_timestamps = [&](FrameResources& f, std::uint32_t first) {  // once its frame is done
        std::array<std::uint64_t, 4> t{};
        if (f.timed && timestamps.results(first, t) == VK_SUCCESS) {
            for (int i = 0; i < 3; ++i) totals[i] += double(t[i + 1] - t[i]) * timestamps.timestamp_period_ns() / 1e6;
            ++gpu_frames;
        }
        f.timed = false;
    };
    auto report = [&](const char* when) {  // averages since the start
        const double g = std::max(gpu_frames, 1.0);
        std::printf("%s: shadow %.3f ms, main %.3f ms, post %.3f ms (GPU, %.0f frames); frame %.3f ms (CPU)\n", when,
                    totals[0] / g, totals[1] / g, totals[2] / g, gpu_frames, totals[3] / std::max(cpu_frames, 1.0));
    };

    // 7. The scene's draws: the ground, then each teapot at its level.
    std::vector<Draw> draws;
    auto build_draws = [&](VkExtent2D extent) {
        draws = {{glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -8.0f)) * renderer::z_up_to_y_up(), 0, 0.25f,
                  ground}};
        std::size_t drawn = 0, fixed = 0;
        std::printf("tessellation for %ux%u: levels", extent.width, extent.height);
        for (const auto& teapot : renderer::teapots) {
            // The coarsest level whose error, seen at the teapot's distance, stays under a pixel.
            const double distance =
                glm::distance(renderer::camera_position, teapot.position + glm::vec3(0.0f, 1.5f * teapot.scale, 0.0f));
            const double pixels_per_unit =
                std::min(extent.width, extent.height) / (2.0 * std::tan(renderer::camera_fov / 2.0) * distance);
            std::size_t l = 0;
            while (l + 1 < lods.size() && lods[l].error * teapot.scale * pixels_per_unit >= 1.0) ++l;
            draws.push_back({renderer::teapot_world(teapot), teapot.texture, 0.4f, lods[l].mesh});
            drawn += lods[l].mesh.index_count / 3;
            fixed += lods.back().mesh.index_count / 3;
            std::printf(" %d", lods[l].level);
        }
        std::printf("; %zu triangles instead of %zu at level %d everywhere (%zu saved)\n", drawn, fixed, fixed_level,
                    fixed - drawn);
    };

    // 8. Streaming while rendering: every stream_every frames (scene.hpp) the streamed material's
    //    texture is replaced. The new one, every level made on the CPU, goes through an Uploader on
    //    the transfer queue; the frame that first samples it waits on the batch's Ticket and records
    //    its ownership acquire (where the transfer queue's family is another). The old index is
    //    removed from the table, which releases the texture once the frames that sample it are done.
    auto streamer = vkrc::Uploader::create({.queue = transfer.queue, .staging_size = 2 << 20});
    // Slots used: the highest index + 1; removed slots come back once the GPU is done with them.
    std::uint32_t streamed_in = 0, slots_used = std::uint32_t(materials.size());
    auto stream_texture = [&](std::uint32_t step) {
        auto texture =
            vkrc::Image::create(device, {.format = ldr_format,
                                         .extent = {texture_size, texture_size, 1},
                                         .mip_levels = mip_levels,
                                         .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
        const auto texels = streamed_texels(step);
        streamer.upload_image(texture, std::as_bytes(std::span(texels)));
        auto& slot = materials[renderer::streamed_material];
        table.remove(slot);
        slot = table.add(vkrc::ImageView::create(texture), texture_sampler);
        ++streamed_in, slots_used = std::max(slots_used, slot.index + 1);
        return streamer.submit();
    };

    // 9. The frame loop: wait for the frame's last use and read its timestamps, acquire, write the
    //    uniforms, record the main pass's draws on the threads, then record and submit every pass.
    Targets targets;
    vkrc::Frame frame;
    auto last = std::chrono::steady_clock::now();
    for (long n = 0, frames = options.frame_limit(); frames < 0 || n < frames;) {
        if (!options.headless) vkrc::glfw::Window::poll_events();
        if (window.window && window.window.should_close()) break;
        if (!options.headless && options.resize_every > 0 && n > 0 && n % options.resize_every == 0) {
            const int k = int(n / options.resize_every) % 3;  // 320x180, 400x225, 240x135, 320x180, ...
            glfwSetWindowSize(window.window.get(), 240 + 80 * k, 135 + 45 * k);
        }
        FrameResources& f = in_flight[std::size_t(n) % frames_in_flight];
        const std::uint32_t q = std::uint32_t(n % frames_in_flight) * 4;
        f.done.wait();
        add_timestamps(f, q);
        presenter.acquire(frame);
        if (!frame) {  // minimised (wait for the window to come back) or being re-created
            if (frame.status == vkrc::PresentStatus::zero_extent) vkrc::glfw::Window::wait_events();
            continue;
        }
        f.done.unsignal();
        vkrc::Ticket streamed;  // the new texture's upload, when this frame streams one in
        if (n > 0 && n % renderer::stream_every == 0)
            streamed = stream_texture(renderer::streamed_step(std::uint32_t(n)));
        if (frame.extent.width != targets.extent.width || frame.extent.height != targets.extent.height) {
            targets = make_targets(device, frame.extent, samples, blit_output);
            build_draws(frame.extent);
        }
        ring.begin_frame();
        const auto uniforms = ring.allocate(sizeof(FrameUniforms));
        uniforms.view.write_value(
            0, FrameUniforms{renderer::view_projection(frame.extent.width, frame.extent.height),
                             renderer::light_view_projection(), glm::vec4(renderer::light_direction, 0.0f),
                             glm::vec4(renderer::camera_position, 1.0f)});
        const vkrc::Image& ldr = blit_output ? targets.ldr : frame.image();
        f.post_set.write_image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, targets.hdr_view,
                               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, hdr_sampler);
        f.post_set.write_image(1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, blit_output ? targets.ldr_view : frame.view(),
                               VK_IMAGE_LAYOUT_GENERAL);
        // The main pass's draws, split over the threads: each records a secondary from its own pool
        // (vkrc::mt: allocation takes the pool's lock, recording takes none).
        std::vector<vkrc::CommandBuffer> secondaries(threads);
        auto record_share = [&](std::uint32_t t) {
            auto cmd = thread_pools[t].allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
            cmd.begin_secondary({.color_formats = std::span(&hdr_format, 1),
                                 .depth_format = depth_format,
                                 .rasterization_samples = samples});
            const std::size_t begin = draws.size() * t / threads, end = draws.size() * (t + 1) / threads;
            record_draws(cmd, scene_pipeline, frame.extent, uniforms.dynamic_offset(),
                         std::span(draws).subspan(begin, end - begin));
            cmd.end();
            secondaries[t] = std::move(cmd);
        };
        std::vector<std::thread> workers;
        for (std::uint32_t t = 1; t < threads; ++t) workers.emplace_back(record_share, t);
        record_share(0);
        for (auto& w : workers) w.join();

        const auto& cmd = f.cmd;
        cmd.begin();
        streamed.record_acquire(cmd);  // nothing when the families are the same or nothing was streamed
        cmd.reset_query_pool(timestamps, q, 4);
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps, q);
        // Shadow pass: the teapots' depth from the light, once the last frame is done sampling the map.
        cmd.pipeline_barrier(
            {}, {}, std::array{vkrc::image_barrier(shadow_map, use::discarded(fragment_read), use::depth_attachment)});
        vkrc::RenderingAttachment shadow_target{shadow_view.vk(), use::depth_attachment.layout};
        shadow_target.clear_value.depthStencil = {1.0f, 0};
        cmd.begin_rendering({.render_area = {{0, 0}, {shadow_size, shadow_size}}, .depth_attachment = &shadow_target});
        record_draws(cmd, shadow_pipeline, {shadow_size, shadow_size}, uniforms.dynamic_offset(),
                     std::span(draws).subspan(1));  // the ground casts no shadow
        cmd.end_rendering();
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps, q + 1);

        // Main pass: the secondaries' draws into the multisampled HDR image, resolved into targets.hdr
        // once the last frame's tone-map has read it.
        cmd.pipeline_barrier(
            {}, {},
            std::array{
                vkrc::image_barrier(shadow_map, use::depth_attachment, fragment_read),
                vkrc::image_barrier(targets.hdr, use::discarded(compute_read), use::colour_attachment_write),
                vkrc::image_barrier(targets.depth, use::discarded(use::depth_attachment), use::depth_attachment)});
        if (targets.msaa)
            cmd.pipeline_barrier(
                {}, {},
                std::array{vkrc::image_barrier(targets.msaa, use::discarded(use::colour_attachment_write),
                                               use::colour_attachment_write)});
        vkrc::RenderingAttachment colour_target{.image_view = targets.hdr_view.vk()};
        if (targets.msaa) {
            colour_target = {targets.msaa_view.vk(), use::colour_attachment_write.layout, VK_ATTACHMENT_LOAD_OP_CLEAR,
                             VK_ATTACHMENT_STORE_OP_DONT_CARE};
            colour_target.resolve_mode = VK_RESOLVE_MODE_AVERAGE_BIT;
            colour_target.resolve_image_view = targets.hdr_view.vk();
        }
        colour_target.clear_value.color = {{0.45f, 0.6f, 0.9f, 1.0f}};  // the sky, in HDR
        vkrc::RenderingAttachment depth_target{targets.depth_view.vk(), use::depth_attachment.layout,
                                               VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE};
        depth_target.clear_value.depthStencil = {1.0f, 0};
        cmd.begin_rendering({.render_area = {{0, 0}, frame.extent},
                             .color_attachments = std::span(&colour_target, 1),
                             .depth_attachment = &depth_target,
                             .flags = VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT});
        cmd.execute_commands(secondaries);
        cmd.end_rendering();
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps, q + 2);

        // Post: tone-map targets.hdr into the 8-bit image: the presented one or an intermediate blitted into it.
        cmd.pipeline_barrier(
            {}, {},
            std::array{vkrc::image_barrier(targets.hdr, use::colour_attachment_write, compute_read),
                       vkrc::image_barrier(ldr, use::discarded(blit_output ? use::transfer_src : use::acquired),
                                           use::compute_storage_write)});
        cmd.bind_pipeline(post_pipeline);
        cmd.bind_descriptor_set(post_pipeline, 0, f.post_set);
        cmd.dispatch((frame.extent.width + 7) / 8, (frame.extent.height + 7) / 8);
        if (blit_output) {
            cmd.pipeline_barrier({}, {},
                                 std::array{vkrc::image_barrier(ldr, use::compute_storage_write, use::transfer_src),
                                            vkrc::image_barrier(frame.image(), use::acquired, use::transfer_dst)});
            const VkOffset3D end{std::int32_t(frame.extent.width), std::int32_t(frame.extent.height), 1};
            const VkImageBlit region{
                {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {{}, end}, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {{}, end}};
            cmd.blit_image(ldr, use::transfer_src.layout, frame.image(), use::transfer_dst.layout,
                           std::span(&region, 1), VK_FILTER_NEAREST);
        }
        cmd.pipeline_barrier(
            {}, {},
            std::array{vkrc::image_barrier(frame.image(), blit_output ? use::transfer_dst : use::compute_storage_write,
                                           use::presented(frame.present_layout))});
        cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps, q + 3);
        cmd.end();
        std::vector<vkrc::SemaphoreSubmit> waits(frame.waits().begin(), frame.waits().end());
        if (streamed) waits.push_back(streamed.wait(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT));
        vkrc::submit(queue, {.waits = waits, .command_buffers = std::span(&cmd, 1), .signals = frame.signals()},
                     f.done);
        ring.end_frame();
        presenter.present(frame);
        f.timed = true;

        totals[3] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - last).count();
        last = std::chrono::steady_clock::now(), ++cpu_frames;
        ++n;
        if (options.report_every > 0 && n % options.report_every == 0) report("every --report frames");
    }
    device.wait_idle();
    std::printf("streamed %u textures in; %u slots used; the table holds %u, %zu removed ones waiting for the GPU\n",
                streamed_in, slots_used, table.live_count(vkrc::BindlessKind::image),
                table.pending_count(vkrc::BindlessKind::image));
    for (std::uint32_t i = 0; i < frames_in_flight; ++i) add_timestamps(in_flight[i], i * 4);
    report("at exit");
    if (options.headless) vkrc_examples::save_last_frame(headless, options.out_file);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return vkrc_examples::run_example(argc, argv, "renderer", run); }
