// Acceleration structures (VK_KHR_acceleration_structure) and the helpers
// that build them: bottom level from triangles, top level from instances of
// bottom-level structures, which the top level then keeps alive.
#pragma once

#include "vkrc/resource.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

class CommandBuffer;

namespace detail {
class AccelerationStructureState;
}  // namespace detail

// Mirrors VkAccelerationStructureCreateInfoKHR. The device must have
// VK_KHR_acceleration_structure enabled (with its accelerationStructure
// feature) and the bufferDeviceAddress feature (UsageError otherwise).
struct AccelerationStructureCreateInfo {
    // Optional (default none).
    VkAccelerationStructureCreateFlagsKHR create_flags = 0;
    // Required: where the structure lives, with ACCELERATION_STRUCTURE_STORAGE
    // usage. The structure keeps it alive.
    Buffer buffer{};
    // Optional (default 0): a multiple of 256.
    VkDeviceSize offset = 0;
    // Optional (0: the rest of the buffer from offset).
    VkDeviceSize size = 0;
    // Optional (default bottom level).
    VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    // Optional pNext chain. Read during create(); need not outlive the call.
    const void* next = nullptr;
};

// A structure over a Buffer it keeps alive (and so its Device). A top-level
// structure built by build_top_level also keeps alive the bottom-level
// structures of its last build: its instances point at them by address.
class AccelerationStructure : public DeviceChild<detail::AccelerationStructureState, VkAccelerationStructureKHR> {
public:
    static AccelerationStructure create(const Device& device, const AccelerationStructureCreateInfo& info);

    VkAccelerationStructureTypeKHR type() const VKRC_UNCHECKED_NOEXCEPT;
    VkDeviceSize size() const VKRC_UNCHECKED_NOEXCEPT;
    // vkGetAccelerationStructureDeviceAddressKHR, read once at creation.
    VkDeviceAddress device_address() const VKRC_UNCHECKED_NOEXCEPT;
    const Buffer& buffer() const VKRC_UNCHECKED_NOEXCEPT;
    // The flags of the last build recorded by vkrc's helpers (0 before one).
    VkBuildAccelerationStructureFlagsKHR build_flags() const VKRC_UNCHECKED_NOEXCEPT;
    // A top level's bottom-level structures, as its last build set them (a copy).
    List<AccelerationStructure> bottom_levels() const;

private:
    using DeviceChild::DeviceChild;
};

// One triangle geometry of a bottom-level build (VkAccelerationStructureGeometryTrianglesDataKHR
// with its VkAccelerationStructureBuildRangeInfoKHR). The buffers are read
// by device address, so each needs SHADER_DEVICE_ADDRESS and
// ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY usage; they must live until
// the build has run (a drop while the recording command buffer is open
// waits for it, as every drop does).
struct TriangleGeometry {
    // Required.
    Buffer vertex_buffer{};
    VkDeviceSize vertex_offset = 0;
    // Optional (default three floats, tightly packed).
    VkFormat vertex_format = VK_FORMAT_R32G32B32_SFLOAT;
    VkDeviceSize vertex_stride = 12;
    // Required: the highest vertex index the triangles use.
    std::uint32_t max_vertex = 0;
    // Optional (empty: non-indexed, three vertices a triangle in order).
    Buffer index_buffer{};
    VkDeviceSize index_offset = 0;
    VkIndexType index_type = VK_INDEX_TYPE_UINT32;
    // Required, non-zero.
    std::uint32_t triangle_count = 0;
    // Optional: a VkTransformMatrixKHR (3x4 row-major) applied to the vertices.
    Buffer transform_buffer{};
    VkDeviceSize transform_offset = 0;
    // Optional (default opaque): OPAQUE, NO_DUPLICATE_ANY_HIT_INVOCATION.
    VkGeometryFlagsKHR flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
};

// One box geometry of a bottom-level build (VkAccelerationStructureGeometryAabbsDataKHR
// with its VkAccelerationStructureBuildRangeInfoKHR): count VkAabbPositionsKHR
// records, for procedural hit groups whose intersection shader decides what
// each box holds. The buffer is read as TriangleGeometry's are (same usage,
// same lifetime).
struct AabbGeometry {
    // Required.
    Buffer buffer{};
    // Optional (default 0): a multiple of 8.
    VkDeviceSize offset = 0;
    // Optional (default tightly packed): a multiple of 8, at least 24.
    VkDeviceSize stride = sizeof(VkAabbPositionsKHR);
    // Required, non-zero.
    std::uint32_t count = 0;
    // Optional (default opaque): OPAQUE, NO_DUPLICATE_ANY_HIT_INVOCATION.
    VkGeometryFlagsKHR flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
};

// A bottom-level build of triangles or of boxes: exactly one of geometries
// and aabbs is set (Vulkan builds one kind per bottom level). Every other
// member is optional.
struct BottomLevelBuildInfo {
    // Triangles (default none); gl_GeometryIndexEXT is the index in this list.
    List<TriangleGeometry> geometries{};
    // Boxes (default none); gl_GeometryIndexEXT is the index in this list.
    List<AabbGeometry> aabbs{};
    // PREFER_FAST_TRACE by default; ALLOW_UPDATE to refit later with update_bottom_level.
    VkBuildAccelerationStructureFlagsKHR flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    // Where the structure's buffer and the scratch come from (null: the device's
    // default). Must outlive the build call; the Device keeps it from then on.
    AllocatorView allocator{};
};

// One instance of a top-level build (VkAccelerationStructureInstanceKHR).
struct AccelerationStructureInstance {
    // Required: a bottom-level structure of the same device, which the top level keeps alive.
    AccelerationStructure bottom_level{};
    // Optional (default identity): 3x4 row-major, object to world.
    VkTransformMatrixKHR transform{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    // 24 bits: gl_InstanceCustomIndexEXT / rayQueryGetIntersectionInstanceCustomIndexEXT.
    std::uint32_t custom_index = 0;
    // Optional (default every ray).
    std::uint8_t mask = 0xFF;
    // 24 bits: the instance's shader binding table record offset.
    std::uint32_t sbt_offset = 0;
    // VkGeometryInstanceFlagsKHR (8 bits).
    VkGeometryInstanceFlagsKHR flags = 0;
};

// A top-level build. Every member but instances is optional.
struct TopLevelBuildInfo {
    // Required, not empty.
    List<AccelerationStructureInstance> instances{};
    VkBuildAccelerationStructureFlagsKHR flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    // Where the structure's buffer, the scratch and the instance buffer come from
    // (null: the device's default). Must outlive the build call.
    AllocatorView allocator{};
};

// The build helpers query the build sizes, make the structure (over a
// buffer of its own) and a scratch buffer from the allocator (at the device's
// minAccelerationStructureScratchOffsetAlignment), and record
// vkCmdBuildAccelerationStructuresKHR into cmd, a primary or secondary
// recording on the structure's device. What they make for the build
// (scratch, instance buffer) is dropped at once: a drop while cmd is open
// waits for it to close and for the GPU. A build that later commands read
// needs a barrier from ACCELERATION_STRUCTURE_BUILD / ACCELERATION_STRUCTURE_WRITE,
// which the caller records (as for any other write). Throws UsageError on
// bad geometry or when the device lacks what acceleration structures need.
AccelerationStructure build_bottom_level(const CommandBuffer& cmd, const BottomLevelBuildInfo& info);
// vkrc writes the instances into a host-visible buffer of its own.
AccelerationStructure build_top_level(const CommandBuffer& cmd, const TopLevelBuildInfo& info);
// Builds again into top_level (made by build_top_level, large enough for the
// new instances: UsageError otherwise) and replaces the bottom-level
// structures it keeps with the new ones; the old ones are released as drops
// are, so work in flight that traces the old build keeps them.
void rebuild_top_level(const CommandBuffer& cmd, const AccelerationStructure& top_level, const TopLevelBuildInfo& info);
// Refits bottom_level in place (mode UPDATE) from geometries of the same
// shape (kind, count, triangle or box counts, formats) with moved vertices or boxes; bottom_level
// must have been built with ALLOW_UPDATE (UsageError otherwise).
void update_bottom_level(const CommandBuffer& cmd, const AccelerationStructure& bottom_level,
                         const BottomLevelBuildInfo& info);

// Compaction, after source's build (with ALLOW_COMPACTION) has run and its
// compacted size was read: cmd.write_acceleration_structures_properties with
// ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR into a QueryPool, then
// QueryPool::results. Makes a structure of compacted_size (a buffer of its
// own from allocator) and records the COMPACT copy into cmd; a top level's
// copy keeps the same bottom levels. The caller records the barrier from
// source's build before, as for any read of it.
AccelerationStructure compact(const CommandBuffer& cmd, const AccelerationStructure& source,
                              VkDeviceSize compacted_size, AllocatorView allocator = {});

namespace detail {

class AccelerationStructureState final : public DeviceChildState<VkAccelerationStructureKHR> {
public:
    static constexpr const char* type_name = "vkrc::AccelerationStructure";
    ~AccelerationStructureState() override;
    Buffer buffer;  // released after the structure's destruction is queued
    VkDeviceSize size = 0;
    VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    VkDeviceAddress device_address = 0;
    VkBuildAccelerationStructureFlagsKHR build_flags = 0;
    // Under mutex: a top level's bottom levels, released after its own
    // destruction is queued (so destroyed after it).
    mutable Mutex mutex;
    List<AccelerationStructure> bottom_levels;
};

}  // namespace detail

VKRC_END_NAMESPACE
