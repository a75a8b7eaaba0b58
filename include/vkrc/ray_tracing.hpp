// Ray tracing pipelines (VK_KHR_ray_tracing_pipeline) with their shader
// groups, and shader binding tables: the groups' handles and per-record data
// laid out in one buffer, whose four regions CommandBuffer::trace_rays passes.
#pragma once

#include "vkrc/pipeline.hpp"
#include "vkrc/resource.hpp"

#include "vkrc/detail/list.hpp"
#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class RayTracingPipelineState;
class ShaderBindingTableState;
}  // namespace detail

// One stage of a ray tracing pipeline (VkPipelineShaderStageCreateInfo).
struct RayTracingShaderStage {
    // Optional (default RAYGEN): RAYGEN, MISS, CLOSEST_HIT, ANY_HIT, INTERSECTION or CALLABLE (_KHR bits).
    VkShaderStageFlagBits stage = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    // Required, of the layout's device. Kept alive by nothing after create.
    ShaderModule module{};
    // Optional (default "main"). Read during create only.
    const char* entry_point = "main";
    // Optional (default none). Both spans are read during create only.
    Specialization specialization{};
    // Optional (default none).
    VkPipelineShaderStageCreateFlags flags = 0;
    // Optional pNext of the stage. Read during create only.
    const void* next = nullptr;
};

// One shader group (VkRayTracingShaderGroupCreateInfoKHR): indices into
// RayTracingPipelineCreateInfo::stages, VK_SHADER_UNUSED_KHR where a group
// has no shader of that kind. A GENERAL group has general_shader alone (a
// RAYGEN, MISS or CALLABLE stage); a TRIANGLES_HIT group an optional
// closest_hit_shader and any_hit_shader; a PROCEDURAL_HIT group also a
// required intersection_shader.
struct RayTracingShaderGroup {
    // Optional (default GENERAL).
    VkRayTracingShaderGroupTypeKHR type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    // Optional each (default VK_SHADER_UNUSED_KHR), as the type above requires.
    std::uint32_t general_shader = VK_SHADER_UNUSED_KHR;
    std::uint32_t closest_hit_shader = VK_SHADER_UNUSED_KHR;
    std::uint32_t any_hit_shader = VK_SHADER_UNUSED_KHR;
    std::uint32_t intersection_shader = VK_SHADER_UNUSED_KHR;
};

// Mirrors VkRayTracingPipelineCreateInfoKHR (without pipeline libraries or
// dynamic state: the LIBRARY flag is refused). The device must have
// VK_KHR_ray_tracing_pipeline with its rayTracingPipeline feature
// (DeviceCreateInfo::ray_tracing_pipeline_features) and, to trace anything,
// acceleration structures (vkrc/acceleration_structure.hpp).
struct RayTracingPipelineCreateInfo {
    // Optional (default none).
    VkPipelineCreateFlags flags = 0;
    // Required, not empty. Read during create only.
    List<RayTracingShaderStage> stages{};
    // Required, not empty; the group indices of a ShaderBindingTable index
    // this list. Read during create only.
    List<RayTracingShaderGroup> groups{};
    // Optional (default 1: rays from raygen only): how deep traceRayEXT
    // calls may nest, at most the device's maxRayRecursionDepth.
    std::uint32_t max_ray_recursion_depth = 1;
    // Optional (default none).
    PipelineCache cache{};
    // Optional pNext chain. Read during create only.
    const void* next = nullptr;
};

// The region of a shader binding table a group's records belong in: raygen,
// miss and callable for GENERAL groups (by their shader's stage), hit for
// TRIANGLES_HIT and PROCEDURAL_HIT groups.
enum class ShaderGroupRegion : std::uint8_t { raygen, miss, hit, callable };

// The device's VkPhysicalDeviceRayTracingPipelinePropertiesKHR (pNext null):
// handle size and alignments, maxRayRecursionDepth, maxShaderGroupStride.
VkPhysicalDeviceRayTracingPipelinePropertiesKHR ray_tracing_pipeline_properties(const PhysicalDevice& physical_device);

// A ray tracing pipeline (bind point RAY_TRACING_KHR); keeps its layout
// alive, and knows the region each of its groups belongs in.
class RayTracingPipeline : public Pipeline {
public:
    // vkCreateRayTracingPipelinesKHR (no deferred operation). UsageError for
    // a device without the extension or feature, a stage that is not a ray
    // tracing stage, a group index out of range or of a kind its group type
    // forbids, or a recursion depth over the device's limit.
    static RayTracingPipeline create(const PipelineLayout& layout, const RayTracingPipelineCreateInfo& info);

    std::uint32_t group_count() const VKRC_UNCHECKED_NOEXCEPT;
    // The region group's records go in (UsageError for group >= group_count()).
    ShaderGroupRegion group_region(std::uint32_t group) const;
    std::uint32_t max_ray_recursion_depth() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using Pipeline::Pipeline;
};

// One record of a shader binding table: a group's handle followed by data
// the group's shaders read as shaderRecordEXT.
struct ShaderRecord {
    // Required: an index into the pipeline's groups, of the region's kind.
    std::uint32_t group = 0;
    // Optional (default none). Copied during create.
    Span<const std::byte> data{};
};

// What ShaderBindingTable::create lays out. Each region's stride is its
// largest record (handle and data) rounded up to shaderGroupHandleAlignment,
// at most maxShaderGroupStride; each region starts at a multiple of
// shaderGroupBaseAlignment. The hit records are indexed as traceRayEXT
// computes: instance sbt_offset + sbt record offset + geometry index *
// sbt record stride.
struct ShaderBindingTableCreateInfo {
    // Required: the one raygen record (its region's size is its stride, as
    // vkCmdTraceRaysKHR requires).
    ShaderRecord raygen{};
    // Optional each (default none): MISS, hit-group and CALLABLE records, in
    // the order the shaders index them. Read during create only.
    List<ShaderRecord> miss{};
    List<ShaderRecord> hit{};
    List<ShaderRecord> callable{};
    // Optional (null: the device's default): where the table's buffer comes from.
    // Must outlive create().
    AllocatorView allocator{};
};

// A shader binding table: one host-visible buffer (SHADER_BINDING_TABLE and
// SHADER_DEVICE_ADDRESS usage) of the pipeline's group handles and record
// data. Keeps the buffer and the pipeline alive; dropped while a recording
// or the GPU may use it, both wait as every drop does.
class ShaderBindingTable : public Handle<detail::ShaderBindingTableState> {
public:
    ShaderBindingTable() noexcept = default;
    // Reads the handles with vkGetRayTracingShaderGroupHandlesKHR and writes
    // the records. UsageError for a group out of range or of another region's
    // kind, a stride over maxShaderGroupStride, or a device without
    // bufferDeviceAddress.
    static ShaderBindingTable create(const RayTracingPipeline& pipeline, const ShaderBindingTableCreateInfo& info);

    // Raygen, miss, hit and callable, in that order (an empty region is all zero).
    const VkStridedDeviceAddressRegionKHR* regions() const VKRC_UNCHECKED_NOEXCEPT;
    const VkStridedDeviceAddressRegionKHR& raygen_region() const VKRC_UNCHECKED_NOEXCEPT { return regions()[0]; }
    const VkStridedDeviceAddressRegionKHR& miss_region() const VKRC_UNCHECKED_NOEXCEPT { return regions()[1]; }
    const VkStridedDeviceAddressRegionKHR& hit_region() const VKRC_UNCHECKED_NOEXCEPT { return regions()[2]; }
    const VkStridedDeviceAddressRegionKHR& callable_region() const VKRC_UNCHECKED_NOEXCEPT { return regions()[3]; }
    const Buffer& buffer() const VKRC_UNCHECKED_NOEXCEPT;
    const RayTracingPipeline& pipeline() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using Handle::Handle;
};

namespace detail {

class RayTracingPipelineState final : public PipelineState {
public:
    List<ShaderGroupRegion> group_regions;  // one per group
    std::uint32_t max_ray_recursion_depth = 1;
};

class ShaderBindingTableState final : public RefCounted {
public:
    static constexpr const char* type_name = "vkrc::ShaderBindingTable";
    // First: trace_rays reads them.
    VkStridedDeviceAddressRegionKHR regions[4]{};
    Buffer buffer;
    RayTracingPipeline pipeline;
};

}  // namespace detail

// Inline: trace_rays reads them.
inline const VkStridedDeviceAddressRegionKHR* ShaderBindingTable::regions() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::ShaderBindingTable::regions").regions;
}

VKRC_END_NAMESPACE
