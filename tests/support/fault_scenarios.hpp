// Scenarios for the fault-injection tests beyond the teapot scene: each makes
// a new instance from the given info, uses one area of vkrc, drops
// everything, and returns what it computed (the same on every run where no
// failure is injected, so that a run whose failure vkrc absorbed can be
// compared with the reference).
#pragma once

#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include <cstdint>
#include <vector>

namespace vkrc_test {

using ScenarioResult = std::vector<std::uint64_t>;

// Samplers, buffer views, Y'CbCr conversions (where the device has them),
// a compute pipeline built through a pipeline cache and again from the
// cache's data, a set written through an update template, timestamp queries,
// host events, private data and a timeline semaphore signalled and waited
// on from the host.
ScenarioResult run_compute_scenario(const vkrc::InstanceCreateInfo& info);

// A render pass and framebuffer clearing an image, read back.
ScenarioResult run_render_pass_scenario(const vkrc::InstanceCreateInfo& info);

// The Uploader (buffer and image uploads, a download) and three frames of a
// FrameRing copied out to a readback buffer.
ScenarioResult run_streaming_scenario(const vkrc::InstanceCreateInfo& info);

// Mapped writes and reads on memory the injector reports as not
// host-coherent, so that vkrc flushes and invalidates.
ScenarioResult run_non_coherent_scenario(const vkrc::InstanceCreateInfo& info);

// Acceleration structures, where the device has them and ray queries
// (empty result otherwise): a bottom level built for compaction, its
// compacted size queried and a compacted copy made, a top level of two
// instances of the copy, written into a set and traced with a ray query.
ScenarioResult run_acceleration_structure_scenario(const vkrc::InstanceCreateInfo& info);
// Whether the device the tests select has what that scenario needs.
bool device_has_ray_queries(const vkrc::InstanceCreateInfo& info);

// A ray tracing pipeline, where the device has one (empty result
// otherwise): a bottom level of a square, a top level of two instances of
// it, the pipeline of rt_scene's shaders, its shader binding table (miss,
// hit and callable records carrying the rt_ values below), and a trace_rays
// of rt_width x rt_height read back (results[y * 16 + x]).
ScenarioResult run_ray_tracing_pipeline_scenario(const vkrc::InstanceCreateInfo& info);
bool device_has_ray_tracing_pipelines(const vkrc::InstanceCreateInfo& info);
inline constexpr std::uint32_t rt_width = 16, rt_height = 4;  // rt_scene.rgen's rows are 16 wide
inline constexpr std::uint32_t rt_miss_value = 0x0FFFFFF0u, rt_hit_tag = 3, rt_callable_bits = 0x2u;

// A swapchain on window's surface: three frames acquired, cleared and
// presented, a re-creation, one more frame. info must enable GLFW's
// instance extensions.
ScenarioResult run_presentation_scenario(const vkrc::InstanceCreateInfo& info, const vkrc::glfw::Window& window);

}  // namespace vkrc_test
