// Ray tracing commands of CommandBuffer (vkrc/command.hpp): acceleration
// structure builds, copies and property queries, and trace_rays through a
// ShaderBindingTable (vkrc/ray_tracing.hpp). A base of vkrc::CommandRecorder
// (so of CommandBuffer), included by vkrc/command.hpp; call them on a
// CommandBuffer, as cmd.trace_rays(table, width, height). Building whole
// structures: vkrc/acceleration_structure.hpp.
//
// Inline, each one call through the device function table, as every
// recording method.
#pragma once

#include "vkrc/handle.hpp"
#include "vkrc/ray_tracing.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {

// Self is the CommandRecorder: each method records through the table and the
// raw handle of Self::recording(*this, who), which checks it holds one.
template <class Self>
class RayTracingCommands {
public:
    // Acceleration structures (VK_KHR_acceleration_structure, enabled on the
    // device: the functions are called as loaded). The builds as given,
    // ranges[i] holding infos[i]'s geometryCount ranges; build_bottom_level
    // and build_top_level (vkrc/acceleration_structure.hpp) fill them in.
    void build_acceleration_structures(Span<const VkAccelerationStructureBuildGeometryInfoKHR> infos,
                                       const VkAccelerationStructureBuildRangeInfoKHR* const* ranges) const
        VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::build_acceleration_structures");
        self.fn_->vkCmdBuildAccelerationStructuresKHR(self.cmd_, static_cast<std::uint32_t>(infos.size()), infos.data(),
                                                      ranges);
    }
    // mode CLONE or COMPACT (dst made with the size the compacted-size query gave).
    void copy_acceleration_structure(Raw<VkAccelerationStructureKHR> src, Raw<VkAccelerationStructureKHR> dst,
                                     VkCopyAccelerationStructureModeKHR mode) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::copy_acceleration_structure");
        const VkCopyAccelerationStructureInfoKHR info{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR, nullptr,
                                                      src, dst, mode};
        self.fn_->vkCmdCopyAccelerationStructureKHR(self.cmd_, &info);
    }
    // Writes a property of each structure (e.g. ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR)
    // into consecutive queries of pool from first_query (reset them first).
    void write_acceleration_structures_properties(Span<const VkAccelerationStructureKHR> structures,
                                                  VkQueryType query_type, Raw<VkQueryPool> pool,
                                                  std::uint32_t first_query) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::write_acceleration_structures_properties");
        self.fn_->vkCmdWriteAccelerationStructuresPropertiesKHR(
            self.cmd_, static_cast<std::uint32_t>(structures.size()), structures.data(), query_type, pool, first_query);
    }

    // Ray tracing (VK_KHR_ray_tracing_pipeline: DeviceCreateInfo::ray_tracing_pipeline_features)
    // with a bound RayTracingPipeline: width * height * depth raygen
    // invocations through the table's four regions, which the table holds
    // (a drop of it while this recording is open waits, as every drop does).
    void trace_rays(const ShaderBindingTable& table, std::uint32_t width, std::uint32_t height,
                    std::uint32_t depth = 1) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::trace_rays");
        const VkStridedDeviceAddressRegionKHR* r = table.regions();
        self.fn_->vkCmdTraceRaysKHR(self.cmd_, &r[0], &r[1], &r[2], &r[3], width, height, depth);
    }
    // The dimensions from a VkTraceRaysIndirectCommandKHR at indirect, a
    // device address in a buffer with INDIRECT_BUFFER usage, read at
    // execution. Needs the rayTracingPipelineTraceRaysIndirect feature.
    void trace_rays_indirect(const ShaderBindingTable& table, VkDeviceAddress indirect) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::trace_rays_indirect");
        const VkStridedDeviceAddressRegionKHR* r = table.regions();
        self.fn_->vkCmdTraceRaysIndirectKHR(self.cmd_, &r[0], &r[1], &r[2], &r[3], indirect);
    }
};

}  // namespace detail

VKRC_END_NAMESPACE
