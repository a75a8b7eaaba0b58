// examples/raytrace: the teapot scene of examples/renderer (scene.hpp) drawn by one of several render
// paths, each measured against the rasterised image of the same camera. Written only against vkrc
// (no raw Vulkan call; ctest examples.raytrace_no_raw_vulkan checks it).
//     raytrace [--path raster|mesh|raytrace] [--shadows on|off] [--compare] [--frames N] [--validation]
//     raytrace --headless [--path P] [--shadows on|off] [--compare [--csv FILE]] [--out FILE.png] [--frames N]
//              [--validation]
// Paths: raster (a vertex shader, one indexed draw per instance), mesh (a mesh shader over
// meshlets of the same meshes, meshlets.hpp) and raytrace (a ray tracing pipeline: a ray per
// pixel, with shadow rays unless --shadows off). --compare also draws the rasterised reference every
// frame, into an image of its own, and reports each path's GPU time per frame (timestamps, median
// over the frames) and the chosen path's difference from the reference (image_metrics.hpp):
// differing pixels, max channel difference, PSNR. It exits with status 1 when the difference is
// beyond the path's tolerance (PathInfo). The window or PNG shows the chosen path. With --compare,
// --csv FILE also writes those figures as CSV, a row per path (bench/raytrace_run.sh).
//
// The rasteriser has no shadows: with --compare, raytrace traces none either (--shadows off is
// its default there, and on is refused), so that the images differ only where rays and
// rasterisation sample differently.
//
// A path is a ScenePath: it draws the scene into its own image and leaves it a transfer source;
// the frame loop times it, blits its image to the presented one and compares it. Another path
// adds a RenderPath, a PathInfo, its device features in require and a case in make_path.
#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include "raytrace/image_metrics.hpp"
#include "raytrace/meshlets.hpp"
#include "raytrace/scene.hpp"
#include "shaders/raytrace_background.rmiss.h"
#include "shaders/raytrace_lit.rmiss.h"
#include "shaders/raytrace_mesh.mesh.h"
#include "shaders/raytrace_primary.rgen.h"
#include "shaders/raytrace_raster.vert.h"
#include "shaders/raytrace_scene.frag.h"
#include "shaders/raytrace_surface.rchit.h"
#include "support/device_buffer.hpp"
#include "support/window_or_headless.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace {

using raytrace::Scene;
namespace use = vkrc::use;
constexpr VkFormat colour_format = VK_FORMAT_R8G8B8A8_UNORM, depth_format = VK_FORMAT_D32_SFLOAT;
constexpr std::uint32_t frames_in_flight = 2;

enum class RenderPath { raster, mesh, raytrace };
struct PathInfo {
    RenderPath path;
    const char* name;  // on the command line
    // Against the rasterised reference. Both exact: raster is the reference drawn again (the
    // device must be deterministic); mesh transforms every vertex with the vertex shader's
    // operations (shaders/raytrace_scene.glsl) and keeps each instance's triangle order, so
    // every fragment gets the same coverage, depth and interpolated normal.
    //
    // raytrace (without shadows) samples each pixel centre as rasterisation does, but decides
    // coverage by its own intersection test and interpolates the normal from the hit's
    // barycentrics, not the rasteriser's: pixels on silhouettes and triangle edges may flip
    // between surfaces (any channel difference there), and shaded values elsewhere may be a
    // unit off. Measured on lavapipe (Mesa 25.0) at 480x270: 30 pixels of 129600 (0.023%)
    // differ, by up to 72, PSNR 65.0 dB. The tolerance leaves room (20x the pixels, 20 dB) for
    // another device's rasterisation rules, traversal and rounding: up to 0.5% of pixels, by any
    // amount (a flipped edge pixel may show the background), PSNR at least 45 dB.
    raytrace::ImageTolerance tolerance;
};
constexpr std::array<PathInfo, 3> path_infos = {
    {{RenderPath::raster, "raster", {}},
     {RenderPath::mesh, "mesh", {}},
     {RenderPath::raytrace,
      "raytrace",
      {.differing_percent = 0.5, .max_channel_difference = 255, .min_psnr_db = 45.0}}}};
const PathInfo& info_of(RenderPath path) {
    return *std::find_if(path_infos.begin(), path_infos.end(), [&](const PathInfo& p) { return p.path == path; });
}

// The raytrace example's own options, beside those of window_or_headless.hpp.
struct PathOptions {
    RenderPath path = RenderPath::raster;
    bool compare = false;
    bool shadows = true;   // raytrace only
    std::string csv_file;  // empty: none
};

// shaders/raytrace_scene.glsl's push constants: an instance.
struct InstanceConstants {
    glm::mat4 world;
    glm::vec4 colour;
    std::uint32_t first_meshlet;  // mesh shading only
};

// A render path: draws the scene into an image of its own (colour_format, the frame's extent).
class ScenePath {
public:
    virtual ~ScenePath() = default;
    // Makes its images for extent; called before the first frame and on a resize, the GPU idle.
    virtual void resize(VkExtent2D extent) = 0;
    // Records the scene into output(), from any previous use of it, and leaves it a transfer source
    // (use::transfer_src).
    virtual void record(const vkrc::CommandBuffer& cmd) const = 0;
    virtual const vkrc::Image& output() const = 0;
};

// The rasterising paths, raster and mesh: the instances drawn one after the other into a colour
// and a depth image with raytrace_scene.frag; they differ in the stage that makes the triangles
// and in the draw call.
class GraphicsPath final : public ScenePath {
public:
    GraphicsPath(const vkrc::Queue& queue, const Scene& scene, const vkrc::Buffer& uniforms, bool mesh_shading)
        : device_(queue.device()),
          mesh_shading_(mesh_shading),
          stages_((mesh_shading ? VK_SHADER_STAGE_MESH_BIT_EXT : VK_SHADER_STAGE_VERTEX_BIT) |
                  VK_SHADER_STAGE_FRAGMENT_BIT) {
        const auto& g = scene.geometry;
        // The vertex shader reads the vertices as attributes, the mesh shader from storage buffers.
        const VkBufferUsageFlags vertex_usage =
            mesh_shading ? VK_BUFFER_USAGE_STORAGE_BUFFER_BIT : VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
        positions_ = vkrc_examples::device_buffer(queue, g.positions, vertex_usage);
        normals_ = vkrc_examples::device_buffer(queue, g.normals, vertex_usage);
        std::vector<std::uint32_t> first_meshlet(g.meshes.size()), meshlet_count(g.meshes.size());
        if (mesh_shading) load_meshlets(queue, g, first_meshlet, meshlet_count);
        else indices_ = vkrc_examples::device_buffer(queue, g.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
        for (const auto& i : scene.instances)
            draws_.push_back({{i.world, i.colour, first_meshlet[i.mesh]}, g.meshes[i.mesh], meshlet_count[i.mesh]});
        build_pipeline(uniforms);
    }

    void resize(VkExtent2D extent) override {
        extent_ = extent;
        const VkExtent3D e{extent.width, extent.height, 1};
        colour_ = vkrc::Image::create(device_,
                                      {.format = colour_format,
                                       .extent = e,
                                       .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
        depth_ = vkrc::Image::create(
            device_, {.format = depth_format, .extent = e, .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT});
        colour_view_ = vkrc::ImageView::create(colour_);
        depth_view_ = vkrc::ImageView::create(depth_);
    }

    void record(const vkrc::CommandBuffer& cmd) const override {
        // The last frame's blit from the colour image and its depth tests come first; neither image's
        // contents are kept.
        cmd.pipeline_barrier(
            {}, {},
            std::array{vkrc::image_barrier(colour_, use::discarded(use::transfer_src), use::colour_attachment_write),
                       vkrc::image_barrier(depth_, use::discarded(use::depth_attachment), use::depth_attachment)});
        vkrc::RenderingAttachment colour_target{.image_view = colour_view_.vk()};
        const auto& b = raytrace::background;
        colour_target.clear_value.color = {{b[0], b[1], b[2], b[3]}};
        vkrc::RenderingAttachment depth_target{depth_view_.vk(), use::depth_attachment.layout,
                                               VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE};
        depth_target.clear_value.depthStencil = {1.0f, 0};
        cmd.begin_rendering({.render_area = {{0, 0}, extent_},
                             .color_attachments = std::span(&colour_target, 1),
                             .depth_attachment = &depth_target});
        cmd.bind_pipeline(pipeline_);
        cmd.set_viewport_and_scissor(extent_);
        cmd.bind_descriptor_set(pipeline_, 0, set_);
        if (!mesh_shading_) {
            cmd.bind_vertex_buffers(0, std::array{positions_.vk(), normals_.vk()}, std::array<VkDeviceSize, 2>{0, 0});
            cmd.bind_index_buffer(indices_, 0, VK_INDEX_TYPE_UINT16);
        }
        for (const Draw& d : draws_) {
            cmd.push_constants(layout_, stages_, d.constants);
            if (mesh_shading_) cmd.draw_mesh_tasks(d.meshlet_count);
            else cmd.draw_indexed(d.mesh.index_count, 1, d.mesh.first_index, d.mesh.vertex_offset);
        }
        cmd.end_rendering();
        cmd.pipeline_barrier({}, {},
                             std::array{vkrc::image_barrier(colour_, use::colour_attachment_write, use::transfer_src)});
    }

    const vkrc::Image& output() const override { return colour_; }

private:
    // Every mesh's meshlets, appended to one set of arrays (a meshlet's vertices index all the
    // positions), into meshlet_buffers_; each mesh's first meshlet and count.
    void load_meshlets(const vkrc::Queue& queue, const raytrace::Geometry& g, std::vector<std::uint32_t>& first,
                       std::vector<std::uint32_t>& count) {
        raytrace::Meshlets meshlets;
        for (std::size_t m = 0; m < g.meshes.size(); ++m) {
            const auto& r = g.meshes[m];
            first[m] = std::uint32_t(meshlets.meshlets.size());
            count[m] = raytrace::append_meshlets(std::span(g.indices).subspan(r.first_index, r.index_count), meshlets,
                                                 std::uint32_t(r.vertex_offset));
        }
        std::printf("mesh path: %zu meshlets of at most %u vertices and %u triangles\n", meshlets.meshlets.size(),
                    raytrace::MeshletLimits{}.max_vertices, raytrace::MeshletLimits{}.max_triangles);
        constexpr auto storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        meshlet_buffers_ = {vkrc_examples::device_buffer(queue, meshlets.meshlets, storage),
                            vkrc_examples::device_buffer(queue, meshlets.vertices, storage),
                            vkrc_examples::device_buffer(queue, meshlets.triangles, storage)};
    }

    // The descriptor set (binding 0: the frame's uniforms; with mesh shading, the mesh shader's
    // buffers from binding 1, as shaders/raytrace_mesh.mesh declares them), layout and pipeline.
    void build_pipeline(const vkrc::Buffer& uniforms) {
        vkrc::DescriptorSetLayoutCreateInfo set_info{.bindings = {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, stages_}}};
        const std::array<const vkrc::Buffer*, 5> storage = {&positions_, &normals_, &meshlet_buffers_[0],
                                                            &meshlet_buffers_[1], &meshlet_buffers_[2]};
        for (std::uint32_t b = 0; mesh_shading_ && b < storage.size(); ++b)
            set_info.bindings.push_back({b + 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_MESH_BIT_EXT});
        const auto set_layout = vkrc::DescriptorSetLayout::create(device_, set_info);
        const auto pool = vkrc::DescriptorPool::create(
            device_, {.max_sets = 1,
                      .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 5}}});
        set_ = pool.allocate(set_layout);  // the set keeps its pool
        set_.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, uniforms);
        for (std::uint32_t b = 0; mesh_shading_ && b < storage.size(); ++b)
            set_.write_buffer(b + 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, *storage[b]);
        layout_ = vkrc::PipelineLayout::create(
            device_, {.set_layouts = {set_layout}, .push_constant_ranges = {{stages_, 0, sizeof(InstanceConstants)}}});
        vkrc::GraphicsPipelineBuilder builder(layout_);
        if (mesh_shading_)
            builder.shader(VK_SHADER_STAGE_MESH_BIT_EXT,
                           vkrc::ShaderModule::create(device_, vkrc_shaders::raytrace_mesh_mesh));
        else
            builder
                .shader(VK_SHADER_STAGE_VERTEX_BIT,
                        vkrc::ShaderModule::create(device_, vkrc_shaders::raytrace_raster_vert))
                .vertex_binding(0, sizeof(glm::vec3))  // positions
                .vertex_binding(1, sizeof(glm::vec3))  // normals
                .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0)
                .vertex_attribute(1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0);
        pipeline_ = builder
                        .shader(VK_SHADER_STAGE_FRAGMENT_BIT,
                                vkrc::ShaderModule::create(device_, vkrc_shaders::raytrace_scene_frag))
                        .cull_mode(VK_CULL_MODE_NONE)  // the spout and lid openings show inner faces
                        .depth_test(true, true, VK_COMPARE_OP_LESS)
                        .rendering(std::array{colour_format}, depth_format)
                        .build();
    }

    struct Draw {
        InstanceConstants constants;
        raytrace::MeshRange mesh;     // the vertex shader's
        std::uint32_t meshlet_count;  // the mesh shader's
    };
    vkrc::Device device_;
    bool mesh_shading_;
    VkShaderStageFlags stages_;  // of the push constants and the uniforms
    vkrc::Buffer positions_, normals_, indices_;
    std::array<vkrc::Buffer, 3> meshlet_buffers_;  // meshlets, their vertices, their triangles
    std::vector<Draw> draws_;
    vkrc::DescriptorSet set_;
    vkrc::PipelineLayout layout_;
    vkrc::GraphicsPipeline pipeline_;
    VkExtent2D extent_{};
    vkrc::Image colour_, depth_;
    vkrc::ImageView colour_view_, depth_view_;
};

// The ray-traced path: a bottom-level structure per mesh, a top level of one instance per scene
// instance (its custom index the instance's index), and a ray tracing pipeline whose raygen shader
// (shaders/raytrace_primary.rgen) writes a storage image. The closest-hit shader reads the
// instance's world matrix and colour, and its mesh's indices and normals, from storage buffers.
class RayTracedPath final : public ScenePath {
public:
    RayTracedPath(const vkrc::Queue& queue, const Scene& scene, bool shadows)
        : device_(queue.device()), shadows_(shadows) {
        const auto& g = scene.geometry;
        constexpr VkBufferUsageFlags build_input =
            VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
            VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
        constexpr auto storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        positions_ = vkrc_examples::device_buffer(queue, g.positions, build_input);
        // 32-bit: the closest-hit shader reads whole words.
        indices_ = vkrc_examples::device_buffer(queue, std::vector<std::uint32_t>(g.indices.begin(), g.indices.end()),
                                                build_input | storage);
        normals_ = vkrc_examples::device_buffer(queue, g.normals, storage);
        std::vector<InstanceRecord> records;
        for (const auto& i : scene.instances)
            records.push_back({i.world, i.colour, g.meshes[i.mesh].first_index, g.meshes[i.mesh].vertex_offset, {}});
        instances_ = vkrc_examples::device_buffer(queue, records, storage);
        build_structures(queue, scene);
        build_pipeline();
    }

    void resize(VkExtent2D extent) override {
        extent_ = extent;
        image_ = vkrc::Image::create(device_, {.format = colour_format,
                                               .extent = {extent.width, extent.height, 1},
                                               .usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
        view_ = vkrc::ImageView::create(image_);
        set_.write_image(1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, view_, storage_write.layout);
        // The inverse in double: the rays' ends are then as close as float allows to where the
        // rasteriser's view_proj puts each pixel centre.
        const auto frame = raytrace::frame_uniforms(extent.width, extent.height);
        constants_ = {glm::mat4(glm::inverse(glm::dmat4(frame.view_proj))), frame.light_direction, shadows_ ? 1u : 0u};
    }

    void record(const vkrc::CommandBuffer& cmd) const override {
        // After the last frame's blit from the image, whose contents are not kept.
        cmd.pipeline_barrier({}, {},
                             std::array{vkrc::image_barrier(image_, use::discarded(use::transfer_src), storage_write)});
        cmd.bind_pipeline(pipeline_);
        cmd.bind_descriptor_set(pipeline_, 0, set_);
        cmd.push_constants(layout_, trace_stages, constants_);
        cmd.trace_rays(table_, extent_.width, extent_.height);
        cmd.pipeline_barrier({}, {}, std::array{vkrc::image_barrier(image_, storage_write, use::transfer_src)});
    }

    const vkrc::Image& output() const override { return image_; }

private:
    // shaders/raytrace_trace.glsl's push constants.
    struct TraceConstants {
        glm::mat4 inverse_view_proj;
        glm::vec4 light_direction;
        std::uint32_t shadows;
    };
    // shaders/raytrace_surface.rchit's Instance (std430: 96 bytes).
    struct InstanceRecord {
        glm::mat4 world;
        glm::vec4 colour;
        std::uint32_t first_index;
        std::int32_t vertex_offset;
        std::array<std::uint32_t, 2> padding;
    };
    static constexpr VkShaderStageFlags trace_stages =
        VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
    static constexpr vkrc::Use storage_write{VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR,
                                             VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL};

    // The bottom levels (one per mesh) and the top level, built in one submission and waited for;
    // its last barrier makes the top level visible to the frames' rays.
    void build_structures(const vkrc::Queue& queue, const Scene& scene) {
        const auto& g = scene.geometry;
        auto pool = vkrc::CommandPool::create(device_, {.queue_family_index = queue.family_index()});
        const auto cmd = pool.allocate();
        cmd.begin();
        std::vector<vkrc::AccelerationStructure> meshes;
        for (const auto& m : g.meshes) {
            vkrc::BottomLevelBuildInfo info;
            info.geometries = {{.vertex_buffer = positions_,
                                .vertex_offset = VkDeviceSize(m.vertex_offset) * sizeof(glm::vec3),
                                .max_vertex = m.vertex_count - 1,
                                .index_buffer = indices_,
                                .index_offset = VkDeviceSize(m.first_index) * sizeof(std::uint32_t),
                                .triangle_count = m.index_count / 3}};
            meshes.push_back(vkrc::build_bottom_level(cmd, info));
        }
        const auto built = vkrc::memory_barrier(
            VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
            VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        cmd.pipeline_barrier(std::span(&built, 1), {}, {});
        vkrc::TopLevelBuildInfo top;
        for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
            const auto& w = scene.instances[i].world;  // column-major; the transform is 3x4 row-major
            VkTransformMatrixKHR transform;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 4; ++c) transform.matrix[r][c] = w[c][r];
            top.instances.push_back(
                {.bottom_level = meshes[scene.instances[i].mesh], .transform = transform, .custom_index = i});
        }
        top_level_ = vkrc::build_top_level(cmd, top);  // keeps the bottom levels
        const auto traced = vkrc::memory_barrier(
            VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
            VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        cmd.pipeline_barrier(std::span(&traced, 1), {}, {});
        cmd.end();
        auto done = vkrc::Fence::create(device_, false);
        vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, done);
        done.wait();
    }

    // The set (binding 0: the top level; 1: the output image, written by resize; 2 to 4: the
    // instances, indices and normals), the layout, the pipeline and its table: raygen; the
    // background's and the lit shadow ray's misses; the one hit group every instance uses.
    void build_pipeline() {
        constexpr auto hit = VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
        const auto set_layout = vkrc::DescriptorSetLayout::create(
            device_, {.bindings = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, trace_stages},
                                   {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR},
                                   {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, hit},
                                   {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, hit},
                                   {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, hit}}});
        const auto pool =
            vkrc::DescriptorPool::create(device_, {.max_sets = 1,
                                                   .pool_sizes = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                                                  {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1},
                                                                  {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3}}});
        set_ = pool.allocate(set_layout);
        set_.write_acceleration_structure(0, top_level_);
        set_.write_buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, instances_);
        set_.write_buffer(3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, indices_);
        set_.write_buffer(4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, normals_);
        layout_ = vkrc::PipelineLayout::create(
            device_,
            {.set_layouts = {set_layout}, .push_constant_ranges = {{trace_stages, 0, sizeof(TraceConstants)}}});
        auto module = [&](std::span<const std::uint32_t> code) { return vkrc::ShaderModule::create(device_, code); };
        vkrc::RayTracingPipelineCreateInfo info;
        info.stages = {
            {.stage = VK_SHADER_STAGE_RAYGEN_BIT_KHR, .module = module(vkrc_shaders::raytrace_primary_rgen)},
            {.stage = VK_SHADER_STAGE_MISS_BIT_KHR, .module = module(vkrc_shaders::raytrace_background_rmiss)},
            {.stage = VK_SHADER_STAGE_MISS_BIT_KHR, .module = module(vkrc_shaders::raytrace_lit_rmiss)},
            {.stage = hit, .module = module(vkrc_shaders::raytrace_surface_rchit)}};
        info.groups = {{.general_shader = 0},
                       {.general_shader = 1},
                       {.general_shader = 2},
                       {.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, .closest_hit_shader = 3}};
        info.max_ray_recursion_depth = 2;  // primary rays, and the shadow rays of their hits
        pipeline_ = vkrc::RayTracingPipeline::create(layout_, info);
        table_ = vkrc::ShaderBindingTable::create(
            pipeline_,
            {.raygen = {0}, .miss = {{1, std::as_bytes(std::span(raytrace::background))}, {2}}, .hit = {{3}}});
    }

    vkrc::Device device_;
    bool shadows_;
    vkrc::Buffer positions_, indices_, normals_, instances_;
    vkrc::AccelerationStructure top_level_;
    vkrc::DescriptorSet set_;
    vkrc::PipelineLayout layout_;
    vkrc::RayTracingPipeline pipeline_;
    vkrc::ShaderBindingTable table_;
    TraceConstants constants_{};
    VkExtent2D extent_{};
    vkrc::Image image_;
    vkrc::ImageView view_;
};

std::unique_ptr<ScenePath> make_path(RenderPath path, const vkrc::Queue& queue, const Scene& scene,
                                     const vkrc::Buffer& uniforms, const PathOptions& options) {
    switch (path) {
        case RenderPath::raster: return std::make_unique<GraphicsPath>(queue, scene, uniforms, false);
        case RenderPath::mesh: return std::make_unique<GraphicsPath>(queue, scene, uniforms, true);
        case RenderPath::raytrace: return std::make_unique<RayTracedPath>(queue, scene, options.shadows);
    }
    throw std::logic_error("unknown render path");
}

// The device features each path needs, asked of the device chosen and enabled on it.
void require(RenderPath path, vkrc::DeviceRequirements& requirements, vkrc::DeviceCreateInfo& device_info) {
    auto& wanted = requirements.required_features;
    if (path == RenderPath::mesh) wanted.mesh_shader.meshShader = device_info.mesh_shader_features.meshShader = VK_TRUE;
    if (path == RenderPath::raytrace) {  // a ray tracing pipeline, no ray queries
        wanted.ray_tracing_pipeline.rayTracingPipeline = device_info.ray_tracing_pipeline_features.rayTracingPipeline =
            VK_TRUE;
        wanted.acceleration_structure.accelerationStructure =
            device_info.acceleration_structure_features.accelerationStructure = VK_TRUE;
        wanted.vulkan12.bufferDeviceAddress = device_info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
    }
}

// The median of values (not empty).
double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

int run(const vkrc_examples::WindowOrHeadless& options, const PathOptions& chosen) {
    // 1. Instance, device and presenter, as in examples/teapot, with the features of the paths
    //    drawn. Each path draws into an image of its own, blitted into the presented image.
    std::vector<RenderPath> drawn;  // the reference first, when comparing
    if (chosen.compare) drawn.push_back(RenderPath::raster);
    drawn.push_back(chosen.path);
    vkrc::InstanceCreateInfo instance_info{.application_name = "vkrc raytrace", .validation = options.validation};
    vkrc::DeviceRequirements requirements;
    vkrc::DeviceCreateInfo device_info;
    for (RenderPath p : drawn) require(p, requirements, device_info);
    vkrc::glfw::WindowSurface window;
    if (!options.headless) {
        window =
            vkrc::glfw::create_window_surface({.width = 480, .height = 270, .title = "vkrc raytrace"}, instance_info);
        requirements.present_surface = window.surface.vk();
        requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    auto instance = options.headless ? vkrc::Instance::create(instance_info) : window.instance;
    const auto physical = vkrc::PhysicalDevice::select(instance, requirements);
    device_info.enabled_extension_names = requirements.required_extensions;
    auto device = vkrc::Device::create(physical, device_info);
    auto queue = device.default_queue();
    vkrc::Swapchain swapchain;
    vkrc::HeadlessPresenter headless;
    // Blitted into; colour attachment too, as the presenters make a view of each image.
    constexpr VkImageUsageFlags presented_usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    if (options.headless)
        headless = vkrc::HeadlessPresenter::create(
            queue, {.extent = {480, 270}, .format = colour_format, .image_usage = presented_usage});
    else
        swapchain = vkrc::Swapchain::create(  // unorm, as the paths' images: the blit copies the values
            queue, window.surface,
            {.preferred_formats = {{VK_FORMAT_B8G8R8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
                                   {VK_FORMAT_R8G8B8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR}},
             .image_usage = presented_usage});
    vkrc::Presenter& presenter = options.headless ? static_cast<vkrc::Presenter&>(headless) : swapchain;
    std::printf("device: %s; path %s%s%s\n", physical.name(), info_of(chosen.path).name,
                chosen.path != RenderPath::raytrace ? ""
                : chosen.shadows                    ? " with shadows"
                                                    : " without shadows",
                chosen.compare ? ", compared with raster" : "");

    // 2. The scene and the paths. The frame's uniforms change only with the extent: they are
    //    written while the GPU is idle (step 4).
    const Scene scene = raytrace::make_scene();
    std::printf("scene: %zu instances of %zu meshes (levels", scene.instances.size(), scene.geometry.meshes.size());
    for (int level : scene.mesh_levels) std::printf(" %d", level);
    std::printf("), %zu triangles drawn\n", [&] {
        std::size_t triangles = 0;
        for (const auto& i : scene.instances) triangles += scene.geometry.meshes[i.mesh].index_count / 3;
        return triangles;
    }());
    auto uniforms = vkrc::Buffer::create(device, {.size = sizeof(raytrace::FrameUniforms),
                                                  .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                                  .memory = {.usage = vkrc::MemoryUsage::upload}});
    std::vector<std::unique_ptr<ScenePath>> paths;
    for (RenderPath p : drawn) paths.push_back(make_path(p, queue, scene, uniforms, chosen));

    // 3. Frames in flight, each with its command buffer, fence and two timestamps per path drawn
    //    (before and after its commands), read once the frame is done.
    struct FrameResources {
        vkrc::CommandBuffer cmd;
        vkrc::Fence done;
        bool timed = false;
    };
    auto command_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    std::array<FrameResources, frames_in_flight> in_flight;
    for (auto& f : in_flight) f = {command_pool.allocate(), vkrc::Fence::create(device, true), false};
    const bool timing = physical.queue_families()[queue.family_index()].timestampValidBits != 0;
    const auto per_frame = std::uint32_t(2 * paths.size());
    auto timestamps = vkrc::QueryPool::create(device, {.query_count = per_frame * frames_in_flight});
    std::vector<std::vector<double>> path_ms(paths.size());  // per frame, GPU
    auto read_timestamps = [&](FrameResources& f, std::uint32_t first) {
        std::vector<std::uint64_t> t(per_frame);
        if (f.timed && timestamps.results(first, t) == VK_SUCCESS)
            for (std::size_t p = 0; p < paths.size(); ++p)
                path_ms[p].push_back(double(t[2 * p + 1] - t[2 * p]) * timestamps.timestamp_period_ns() / 1e6);
        f.timed = false;
    };

    // 4. The frame loop: acquire; draw each path, timed; blit the chosen path's image into the
    //    presented one; submit and present.
    VkExtent2D extent{};
    vkrc::Frame frame;
    for (long n = 0, frames = options.frame_limit(); frames < 0 || n < frames;) {
        if (!options.headless) vkrc::glfw::Window::poll_events();
        if (window.window && window.window.should_close()) break;
        FrameResources& f = in_flight[std::size_t(n) % frames_in_flight];
        const std::uint32_t q = std::uint32_t(n % frames_in_flight) * per_frame;
        f.done.wait();
        read_timestamps(f, q);
        presenter.acquire(frame);
        if (!frame) {  // minimised (wait for the window to come back) or being re-created
            if (frame.status == vkrc::PresentStatus::zero_extent) vkrc::glfw::Window::wait_events();
            continue;
        }
        f.done.unsignal();
        if (frame.extent.width != extent.width || frame.extent.height != extent.height) {
            device.wait_idle();
            extent = frame.extent;
            uniforms.allocation().write_value(0, raytrace::frame_uniforms(extent.width, extent.height));
            for (auto& p : paths) p->resize(extent);
        }
        const auto& cmd = f.cmd;
        cmd.begin();
        if (timing) cmd.reset_query_pool(timestamps, q, per_frame);
        for (std::uint32_t p = 0; p < paths.size(); ++p) {
            if (timing) cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps, q + 2 * p);
            paths[p]->record(cmd);
            if (timing) cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps, q + 2 * p + 1);
        }
        cmd.pipeline_barrier({}, {}, std::array{vkrc::image_barrier(frame.image(), use::acquired, use::transfer_dst)});
        const VkOffset3D end{std::int32_t(extent.width), std::int32_t(extent.height), 1};
        const VkImageBlit region{
            {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {{}, end}, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {{}, end}};
        cmd.blit_image(paths.back()->output(), use::transfer_src.layout, frame.image(), use::transfer_dst.layout,
                       std::span(&region, 1), VK_FILTER_NEAREST);
        cmd.pipeline_barrier(
            {}, {},
            std::array{vkrc::image_barrier(frame.image(), use::transfer_dst, use::presented(frame.present_layout))});
        cmd.end();
        vkrc::submit(queue, {.waits = frame.waits(), .command_buffers = std::span(&cmd, 1), .signals = frame.signals()},
                     f.done);
        presenter.present(frame);
        f.timed = timing;
        ++n;
    }
    device.wait_idle();
    for (std::uint32_t i = 0; i < frames_in_flight; ++i) read_timestamps(in_flight[i], i * per_frame);

    // 5. The report: time per frame of each path and, comparing, the chosen path's difference
    //    from the reference, read back from the two paths' images.
    for (std::size_t p = 0; p < paths.size(); ++p) {
        const char* name = info_of(drawn[p]).name;
        if (path_ms[p].empty()) std::printf("%s: no GPU timestamps on this queue\n", name);
        else
            std::printf("%s%s: %.3f ms per frame (GPU, median of %zu frames)\n", name,
                        chosen.compare && p == 0 ? " (reference)" : "", median(path_ms[p]), path_ms[p].size());
    }
    if (options.headless) vkrc_examples::save_last_frame(headless, options.out_file);
    if (!chosen.compare) return 0;
    if (extent.width == 0) throw std::runtime_error("--compare: no frame was drawn, nothing to compare");
    auto pixels = [&](const ScenePath& p) {
        const auto bytes = vkrc::download_image(queue, p.output(), use::transfer_src.layout);
        return std::vector<std::uint8_t>(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                         reinterpret_cast<const std::uint8_t*>(bytes.data()) + bytes.size());
    };
    const auto d = raytrace::compare_images(pixels(*paths[0]), pixels(*paths[1]));
    const auto& tolerance = info_of(chosen.path).tolerance;
    const bool matches = raytrace::within(d, tolerance);
    std::printf(
        "%s against raster: %zu of %zu pixels (%.3f%%) differ, max channel difference %d, PSNR %.2f dB: %s "
        "(tolerance: %.3g%% of pixels, %d per channel, PSNR %.3g dB)\n",
        info_of(chosen.path).name, d.differing_pixels, d.pixels, 100.0 * double(d.differing_pixels) / double(d.pixels),
        d.max_channel_difference, d.psnr_db, matches ? "matches" : "DOES NOT MATCH", tolerance.differing_percent,
        tolerance.max_channel_difference, tolerance.min_psnr_db);
    if (!chosen.csv_file.empty()) {
        // The reference's row: its difference from itself.
        const std::array<raytrace::ImageDifference, 2> differences{raytrace::ImageDifference{.pixels = d.pixels}, d};
        std::ofstream csv(chosen.csv_file);
        csv << "path,width,height,frames,median_ms,differing_pixels,max_channel_difference,psnr_db\n";
        for (std::size_t p = 0; p < paths.size(); ++p) {
            csv << info_of(drawn[p]).name << ',' << extent.width << ',' << extent.height << ',' << path_ms[p].size()
                << ',';
            if (!path_ms[p].empty()) csv << median(path_ms[p]);  // empty without timestamps
            csv << ',' << differences[p].differing_pixels << ',' << differences[p].max_channel_difference << ','
                << differences[p].psnr_db << '\n';
        }
        if (!csv) throw std::runtime_error("cannot write " + chosen.csv_file);
        std::printf("wrote %s\n", chosen.csv_file.c_str());
    }
    return matches ? 0 : 1;
}

}  // namespace

// Takes --path, --shadows, --compare and --csv out of the arguments; window_or_headless.hpp
// parses the rest.
int main(int argc, char** argv) {
    PathOptions chosen;
    std::vector<char*> rest{argv[0]};
    const char* shadows = nullptr;  // as given
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--shadows") == 0) {
            shadows = i + 1 < argc ? argv[++i] : "";
        } else if (std::strcmp(argv[i], "--compare") == 0) {
            chosen.compare = true;
        } else if (std::strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
            chosen.csv_file = argv[++i];
        } else if (std::strcmp(argv[i], "--path") == 0) {
            const auto known = std::find_if(path_infos.begin(), path_infos.end(), [&](const PathInfo& p) {
                return i + 1 < argc && std::string_view(argv[i + 1]) == p.name;
            });
            if (known == path_infos.end()) {
                std::fprintf(stderr, "%s: --path takes one of:", argv[0]);
                for (const auto& p : path_infos) std::fprintf(stderr, " %s", p.name);
                std::fprintf(stderr, "\n");
                return 2;
            }
            chosen.path = known->path;
            ++i;
        } else {
            rest.push_back(argv[i]);
        }
    }
    if (!chosen.csv_file.empty() && !chosen.compare) {
        std::fprintf(stderr, "%s: --csv writes what --compare measures: add --compare\n", argv[0]);
        return 2;
    }
    if (shadows) {
        const char* refused = nullptr;
        if (std::strcmp(shadows, "on") != 0 && std::strcmp(shadows, "off") != 0) refused = "--shadows takes on or off";
        else if (chosen.path != RenderPath::raytrace) refused = "--shadows is for --path raytrace (raster has none)";
        else if (chosen.compare && std::strcmp(shadows, "on") == 0)
            refused = "--compare measures raytrace against raster, which has no shadows: use --shadows off";
        if (refused) {
            std::fprintf(stderr, "%s: %s\n", argv[0], refused);
            return 2;
        }
    }
    chosen.shadows = shadows ? std::strcmp(shadows, "on") == 0 : !chosen.compare;
    return vkrc_examples::run_example(
        int(rest.size()), rest.data(), "raytrace",
        [&](const vkrc_examples::WindowOrHeadless& o) { return run(o, chosen); },
        " [--path raster|mesh|raytrace] [--shadows on|off] [--compare [--csv FILE]]");
}
