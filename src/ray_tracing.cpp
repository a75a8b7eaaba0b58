#include "vkrc/ray_tracing.hpp"

#include "caller.hpp"
#include "memory_internal.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

VKRC_BEGIN_NAMESPACE

VkPhysicalDeviceRayTracingPipelinePropertiesKHR ray_tracing_pipeline_properties(const PhysicalDevice& physical) {
    detail::Caller("vkrc::ray_tracing_pipeline_properties").require_handle(physical, "the PhysicalDevice");
    VkPhysicalDeviceRayTracingPipelinePropertiesKHR props{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &props};
    physical.fn().vkGetPhysicalDeviceProperties2(physical.vk(), &p2);
    props.pNext = nullptr;
    return props;
}

namespace {

constexpr VkShaderStageFlags ray_tracing_stages =
    VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR |
    VK_SHADER_STAGE_ANY_HIT_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;

// What a ray tracing pipeline needs of the device: the extension (its
// commands are loaded only then) and its rayTracingPipeline feature.
void require_support(const detail::Caller& caller, const Device& device) {
    caller.require(device.extension_enabled(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) &&
                       device.fn().vkCreateRayTracingPipelinesKHR != nullptr,
                   "ray tracing pipelines need VK_KHR_ray_tracing_pipeline enabled on the device (set "
                   "DeviceCreateInfo::ray_tracing_pipeline_features.rayTracingPipeline)");
    caller.require(device.state()->enabled_features.ray_tracing_pipeline.rayTracingPipeline,
                   "ray tracing pipelines need the rayTracingPipeline feature enabled");
}

void check_stages(const detail::Caller& caller, const PipelineLayout& layout,
                  const RayTracingPipelineCreateInfo& info) {
    caller.require(!info.stages.empty(), "stages is empty");
    for (std::size_t i = 0; i < info.stages.size(); ++i) {
        const RayTracingShaderStage& s = info.stages[i];
        caller.require(std::has_single_bit(static_cast<std::uint32_t>(s.stage)) && (s.stage & ray_tracing_stages),
                       "stages[", i, "].stage ", detail::Hex{s.stage},
                       " is not one ray tracing stage (RAYGEN, MISS, CLOSEST_HIT, ANY_HIT, INTERSECTION or CALLABLE)");
        caller.require(static_cast<bool>(s.module), "stages[", i, "] has no module");
        caller.require(s.module.device() == layout.device(), "stages[", i,
                       "].module belongs to another device than the pipeline layout");
        for (const auto& e : s.specialization.map_entries) {
            caller.require(
                e.offset <= s.specialization.data.size() && e.size <= s.specialization.data.size() - e.offset,
                "stages[", i, "]: specialization constant ", e.constantID, " lies outside the data (",
                s.specialization.data.size(), " bytes)");
        }
    }
}

// The name of a group member, for the refusals.
struct GroupMember {
    const char* name;
    std::uint32_t index;
};

// Refuses member unless it is unused or, when allowed, a stage of kind.
void check_member(const detail::Caller& caller, const RayTracingPipelineCreateInfo& info, std::size_t group,
                  GroupMember member, VkShaderStageFlags allowed, const char* kinds) {
    if (member.index == VK_SHADER_UNUSED_KHR) return;
    caller.require(allowed != 0, "groups[", group, "] (", info.groups[group].type, ") has a ", member.name,
                   ", which its type does not take (VK_SHADER_UNUSED_KHR)");
    caller.require(member.index < info.stages.size(), "groups[", group, "].", member.name, " ", member.index,
                   " is out of range (", info.stages.size(), " stages)");
    caller.require((info.stages[member.index].stage & allowed) != 0, "groups[", group, "].", member.name, " is stages[",
                   member.index, "], a ", info.stages[member.index].stage, " shader; it must be ", kinds);
}

// Checks group i against its type; returns the region its records go in.
ShaderGroupRegion checked_group(const detail::Caller& caller, const RayTracingPipelineCreateInfo& info, std::size_t i) {
    const RayTracingShaderGroup& g = info.groups[i];
    const bool general = g.type == VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    const bool procedural = g.type == VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
    caller.require(general || procedural || g.type == VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR,
                   "groups[", i, "].type ", g.type, " is not GENERAL, TRIANGLES_HIT_GROUP or PROCEDURAL_HIT_GROUP");
    // VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03474 to -03486.
    caller.require(!general || g.general_shader != VK_SHADER_UNUSED_KHR, "groups[", i,
                   "] is GENERAL without a general_shader");
    caller.require(!procedural || g.intersection_shader != VK_SHADER_UNUSED_KHR, "groups[", i,
                   "] is PROCEDURAL_HIT_GROUP without an intersection_shader");
    constexpr VkShaderStageFlags general_stages =
        VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;
    check_member(caller, info, i, {"general_shader", g.general_shader}, general ? general_stages : 0,
                 "a RAYGEN, MISS or CALLABLE shader");
    check_member(caller, info, i, {"closest_hit_shader", g.closest_hit_shader},
                 general ? 0 : VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, "a CLOSEST_HIT shader");
    check_member(caller, info, i, {"any_hit_shader", g.any_hit_shader}, general ? 0 : VK_SHADER_STAGE_ANY_HIT_BIT_KHR,
                 "an ANY_HIT shader");
    check_member(caller, info, i, {"intersection_shader", g.intersection_shader},
                 procedural ? VK_SHADER_STAGE_INTERSECTION_BIT_KHR : 0, "an INTERSECTION shader");
    if (!general) return ShaderGroupRegion::hit;
    switch (info.stages[g.general_shader].stage) {
        case VK_SHADER_STAGE_RAYGEN_BIT_KHR: return ShaderGroupRegion::raygen;
        case VK_SHADER_STAGE_MISS_BIT_KHR: return ShaderGroupRegion::miss;
        default: return ShaderGroupRegion::callable;
    }
}

VkRayTracingShaderGroupCreateInfoKHR group_info(const RayTracingShaderGroup& g) {
    VkRayTracingShaderGroupCreateInfoKHR out{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    out.type = g.type;
    out.generalShader = g.general_shader;
    out.closestHitShader = g.closest_hit_shader;
    out.anyHitShader = g.any_hit_shader;
    out.intersectionShader = g.intersection_shader;
    return out;
}

// The stages in Vulkan's form; specializations receives what they point to.
std::vector<VkPipelineShaderStageCreateInfo> stage_infos(const RayTracingPipelineCreateInfo& info,
                                                         std::vector<VkSpecializationInfo>& specializations) {
    std::vector<VkPipelineShaderStageCreateInfo> out;
    specializations.reserve(info.stages.size());
    for (const RayTracingShaderStage& s : info.stages) {
        const Specialization& spec = s.specialization;
        specializations.push_back({static_cast<std::uint32_t>(spec.map_entries.size()), spec.map_entries.data(),
                                   spec.data.size(), spec.data.data()});
        VkPipelineShaderStageCreateInfo stage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, s.next};
        stage.flags = s.flags;
        stage.stage = s.stage;
        stage.module = s.module.vk();
        stage.pName = s.entry_point;
        stage.pSpecializationInfo = spec.map_entries.empty() ? nullptr : &specializations.back();
        out.push_back(stage);
    }
    return out;
}

}  // namespace

RayTracingPipeline RayTracingPipeline::create(const PipelineLayout& layout, const RayTracingPipelineCreateInfo& info) {
    const detail::Caller caller{"vkrc::RayTracingPipeline::create"};
    caller.require_handle(layout, "the PipelineLayout");
    const Device& device = layout.device();
    require_support(caller, device);
    caller.require(!(info.flags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR),
                   "flags has LIBRARY_BIT_KHR: pipeline libraries are not supported");
    const std::uint32_t max_depth = ray_tracing_pipeline_properties(device.physical_device()).maxRayRecursionDepth;
    caller.require(info.max_ray_recursion_depth <= max_depth, "max_ray_recursion_depth ", info.max_ray_recursion_depth,
                   " exceeds the device's maxRayRecursionDepth ", max_depth);
    check_stages(caller, layout, info);
    caller.require(!info.groups.empty(), "groups is empty");
    List<ShaderGroupRegion> regions;
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
    for (std::size_t i = 0; i < info.groups.size(); ++i) {
        regions.push_back(checked_group(caller, info, i));
        groups.push_back(group_info(info.groups[i]));
    }
    std::vector<VkSpecializationInfo> specializations;
    const auto stages = stage_infos(info, specializations);
    VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR, info.next};
    ci.flags = info.flags;
    ci.stageCount = static_cast<std::uint32_t>(stages.size());
    ci.pStages = stages.data();
    ci.groupCount = static_cast<std::uint32_t>(groups.size());
    ci.pGroups = groups.data();
    ci.maxPipelineRayRecursionDepth = info.max_ray_recursion_depth;
    ci.layout = layout.vk();
    detail::Ref<detail::RayTracingPipelineState> s(new detail::RayTracingPipelineState);
    s->layout = layout;
    s->bind_point = VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR;
    s->group_regions = std::move(regions);
    s->max_ray_recursion_depth = info.max_ray_recursion_depth;
    check(device.fn().vkCreateRayTracingPipelinesKHR(
              device.vk(), VK_NULL_HANDLE, info.cache ? info.cache.vk() : VK_NULL_HANDLE, 1, &ci, nullptr, &s->handle),
          "vkCreateRayTracingPipelinesKHR");
    return RayTracingPipeline(std::move(s));
}

// A RayTracingPipeline is only made by create(), so its state is always a ray tracing pipeline's.
std::uint32_t RayTracingPipeline::group_count() const VKRC_UNCHECKED_NOEXCEPT {
    const auto& s = static_cast<const detail::RayTracingPipelineState&>(live("vkrc::RayTracingPipeline::group_count"));
    return static_cast<std::uint32_t>(s.group_regions.size());
}
ShaderGroupRegion RayTracingPipeline::group_region(std::uint32_t group) const {
    const auto& s = static_cast<const detail::RayTracingPipelineState&>(live("vkrc::RayTracingPipeline::group_region"));
    detail::Caller("vkrc::RayTracingPipeline::group_region")
        .require(group < s.group_regions.size(), "group ", group, " is out of range (", s.group_regions.size(),
                 " groups)");
    return s.group_regions[group];
}
std::uint32_t RayTracingPipeline::max_ray_recursion_depth() const VKRC_UNCHECKED_NOEXCEPT {
    return static_cast<const detail::RayTracingPipelineState&>(
               live("vkrc::RayTracingPipeline::max_ray_recursion_depth"))
        .max_ray_recursion_depth;
}

// Shader binding tables

namespace {

constexpr const char* region_names[] = {"raygen", "miss", "hit", "callable"};

// One region's records, with where they go.
struct RegionLayout {
    Span<const ShaderRecord> records;
    VkDeviceSize offset = 0;  // from the table's aligned start
    VkDeviceSize stride = 0;
};

// Checks region's records against the pipeline and the limits; returns the stride.
VkDeviceSize checked_stride(const detail::Caller& caller, const detail::RayTracingPipelineState& pipeline,
                            const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& props, ShaderGroupRegion region,
                            Span<const ShaderRecord> records) {
    const char* name = region_names[static_cast<int>(region)];
    VkDeviceSize largest = 0;
    for (std::size_t i = 0; i < records.size(); ++i) {
        const std::uint32_t group = records[i].group;
        caller.require(group < pipeline.group_regions.size(), name, "[", i, "]: group ", group, " is out of range (",
                       pipeline.group_regions.size(), " groups)");
        caller.require(pipeline.group_regions[group] == region, name, "[", i, "]: group ", group, " is a ",
                       region_names[static_cast<int>(pipeline.group_regions[group])], " group, not a ", name, " group");
        largest = std::max<VkDeviceSize>(largest, props.shaderGroupHandleSize + records[i].data.size());
    }
    const VkDeviceSize stride = detail::align_up(largest, props.shaderGroupHandleAlignment);
    caller.require(stride <= props.maxShaderGroupStride, name, ": a record of ", largest, " bytes (stride ", stride,
                   ") exceeds the device's maxShaderGroupStride ", props.maxShaderGroupStride);
    return stride;
}

// Checks the records and places the regions one after the other; returns the bytes they take.
VkDeviceSize lay_out(const detail::Caller& caller, const detail::RayTracingPipelineState& pipeline,
                     const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& props, RegionLayout (&regions)[4]) {
    VkDeviceSize size = 0;
    for (int r = 0; r < 4; ++r) {
        regions[r].stride = checked_stride(caller, pipeline, props, ShaderGroupRegion(r), regions[r].records);
        regions[r].offset = detail::align_up(size, props.shaderGroupBaseAlignment);
        size = regions[r].offset + regions[r].stride * regions[r].records.size();
    }
    return size;
}

// The table's size bytes: each record its group's handle (read once for
// every group) and its data.
std::vector<std::byte> table_bytes(const RayTracingPipeline& pipeline, std::uint32_t handle_size,
                                   const RegionLayout (&regions)[4], VkDeviceSize size) {
    const Device& device = pipeline.layout().device();
    const std::uint32_t group_count = pipeline.group_count();
    std::vector<std::byte> handles(std::size_t(handle_size) * group_count);
    check(device.fn().vkGetRayTracingShaderGroupHandlesKHR(device.vk(), pipeline.vk(), 0, group_count, handles.size(),
                                                           handles.data()),
          "vkGetRayTracingShaderGroupHandlesKHR");
    std::vector<std::byte> bytes(size);
    for (const RegionLayout& region : regions) {
        for (std::size_t i = 0; i < region.records.size(); ++i) {
            std::byte* record = bytes.data() + region.offset + i * region.stride;
            std::memcpy(record, handles.data() + std::size_t(handle_size) * region.records[i].group, handle_size);
            const auto& data = region.records[i].data;
            if (!data.empty()) std::memcpy(record + handle_size, data.data(), data.size());
        }
    }
    return bytes;
}

}  // namespace

ShaderBindingTable ShaderBindingTable::create(const RayTracingPipeline& pipeline,
                                              const ShaderBindingTableCreateInfo& info) {
    const detail::Caller caller{"vkrc::ShaderBindingTable::create"};
    caller.require_handle(pipeline, "the RayTracingPipeline");
    const Device& device = pipeline.layout().device();
    caller.require(device.state()->enabled_features.vulkan12.bufferDeviceAddress,
                   "shader binding tables need the bufferDeviceAddress feature enabled");
    const auto props = ray_tracing_pipeline_properties(device.physical_device());
    RegionLayout regions[4] = {{Span(&info.raygen, 1)}, {info.miss}, {info.hit}, {info.callable}};
    const VkDeviceSize size =
        lay_out(caller, static_cast<const detail::RayTracingPipelineState&>(*pipeline.state()), props, regions);
    const auto bytes = table_bytes(pipeline, props.shaderGroupHandleSize, regions, size);
    // The buffer's address aligned to shaderGroupBaseAlignment (it is made that much larger).
    Buffer buffer = Buffer::create(
        device, {.size = size + props.shaderGroupBaseAlignment - 1,
                 .usage = VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                 .memory = {.usage = MemoryUsage::upload},
                 .allocator = info.allocator});
    const VkDeviceAddress start = detail::align_up(buffer.device_address(), props.shaderGroupBaseAlignment);
    buffer.allocation().write(start - buffer.device_address(), bytes.data(), bytes.size());
    detail::Ref<detail::ShaderBindingTableState> s(new detail::ShaderBindingTableState);
    for (int r = 0; r < 4; ++r) {
        if (regions[r].records.empty()) continue;  // all zero, as Vulkan takes an unused region
        s->regions[r] = {start + regions[r].offset, regions[r].stride, regions[r].stride * regions[r].records.size()};
    }
    s->buffer = std::move(buffer);
    s->pipeline = pipeline;
    return ShaderBindingTable(std::move(s));
}

const Buffer& ShaderBindingTable::buffer() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::ShaderBindingTable::buffer").buffer;
}
const RayTracingPipeline& ShaderBindingTable::pipeline() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::ShaderBindingTable::pipeline").pipeline;
}

VKRC_END_NAMESPACE
