// The wrapper of the C++ blocks of README.md and docs/guide.md (see
// extract.py): vkrc's headers, and the names the blocks use without
// declaring them, declared here at namespace scope so that a block may also
// declare its own (a local name hides these). Only compiled, never linked.
#pragma once

#include <vkrc/extension_functions.hpp>
#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace vkrc_snippets {

// The examples' own types and helpers.
struct Options {  // examples/support: the command line
    bool validation = false;
    bool headless = false;
    long frame_limit() const;
};
struct Vertex {  // examples/triangle
    float position[2];
    float color[3];
};
struct Uniforms {
    float view_projection[16];
};
void write_png(const std::string& file, std::uint32_t width, std::uint32_t height, std::span<const std::uint8_t> rgba);
std::array<std::uint8_t, 4> texel(std::uint32_t level, std::uint32_t x, std::uint32_t y);
vkrc::Sampler ycbcr_sampler(const vkrc::Device& device, const vkrc::SamplerYcbcrConversion& conversion);
void report(const char* message);
struct MessageLog {
    void add(const vkrc::DebugMessage& message);
};
// examples/allocator's allocator (its members are in the example).
class ArenaAllocator final : public vkrc::DeviceAllocator {
public:
    explicit ArenaAllocator(VkDeviceSize capacity);
    vkrc::AllocationInfo allocate(vkrc::DeviceView device, const vkrc::AllocationRequest& request) override;
    void free(vkrc::DeviceView device, const vkrc::AllocationInfo& allocation) override;
    vkrc::AllocatorStatistics statistics(vkrc::DeviceView device) const override;
};

// Common handles.
extern vkrc::Instance instance;
extern vkrc::InstanceCreateInfo instance_info;
extern vkrc::PhysicalDevice physical;
extern vkrc::Device device;
extern vkrc::Queue queue, graphics;
extern vkrc::CommandBuffer cmd, primary;
extern std::vector<vkrc::CommandBuffer> secondaries;
extern std::array<vkrc::Fence, 2> fences;
extern vkrc::Fence done;
extern vkrc::Buffer buffer, vertex_buffer, vertices, starts, steps, src, dst, pixels, args, counts;
extern vkrc::Image image, texture, depth, shadow_map;
extern vkrc::ImageView view, depth_view;
extern vkrc::Sampler sampler;
extern vkrc::ShaderModule module;
extern vkrc::DescriptorSetLayout push_layout;
extern vkrc::DescriptorPool descriptor_pool;
extern vkrc::DescriptorSet set;
extern vkrc::PipelineLayout layout, pipeline_layout;
extern vkrc::ComputePipeline pipeline;
extern vkrc::GraphicsPipelineBuilder builder;
extern vkrc::SamplerYcbcrConversion conversion;
extern vkrc::RenderPass render_pass;
extern vkrc::Frame frame;
extern vkrc::RenderingAttachment attachment;
extern VkPipeline raw_pipeline_made_elsewhere, their_pipeline;
extern VkPipelineLayout their_layout;
extern VkWriteDescriptorSet write;
extern VkFormat depth_format;
extern std::array<VkFormat, 1> formats;
extern std::vector<VkDescriptorImageInfo> infos;
extern std::vector<std::thread> workers;
extern std::vector<std::uint32_t> input, output;
extern std::vector<std::byte> texels;
extern std::vector<Vertex> vertex_data;
extern Uniforms uniforms;
extern Options options;
extern MessageLog* log;
extern std::string file;
extern bool validation;
extern std::uint32_t count, threads, levels, size, n;
extern VkDeviceSize bytes;

}  // namespace vkrc_snippets

// Opens every function block: the names blocks capture in lambdas, as local
// references (a lambda does not capture a namespace-scope variable).
#define VKRC_SNIPPET_LOCALS                                        \
  [[maybe_unused]] auto& pipeline = vkrc_snippets::pipeline;       \
  [[maybe_unused]] auto& layout = vkrc_snippets::layout;           \
  [[maybe_unused]] auto& formats = vkrc_snippets::formats;         \
  [[maybe_unused]] auto& secondaries = vkrc_snippets::secondaries; \
  [[maybe_unused]] auto& log = vkrc_snippets::log;

namespace vkrc_shaders {  // vkrc_add_shaders' headers
extern const std::span<const std::uint32_t> triangle_vert, triangle_frag, collatz_comp, cull_task, meshlets_mesh,
    scene_rgen, scene_rmiss, scene_rchit;
}
