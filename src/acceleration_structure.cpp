#include "vkrc/acceleration_structure.hpp"

#include "vkrc/command.hpp"

#include "caller.hpp"
#include "memory_internal.hpp"
#include "object_state.hpp"

#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {

// The structure's destruction is queued first; then its members go: the
// bottom levels (destroyed after it, FIFO) and its buffer.
AccelerationStructureState::~AccelerationStructureState() {
    if (device) device.state()->objects.remove(DescribedKind::acceleration_structure, handle_bits(handle), this);
    destroy_owned<&DeviceFunctions::vkDestroyAccelerationStructureKHR>(*this, device);
}

}  // namespace detail

namespace {

constexpr VkBufferUsageFlags input_usage =
    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

// What every acceleration structure call needs of the device: the extension
// (its commands are loaded only then) and buffer device addresses.
void require_support(const detail::Caller& caller, const Device& device) {
    caller.require(device.extension_enabled(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) &&
                       device.fn().vkCreateAccelerationStructureKHR != nullptr,
                   "acceleration structures need VK_KHR_acceleration_structure enabled on the device (set "
                   "DeviceCreateInfo::acceleration_structure_features.accelerationStructure)");
    caller.require(device.state()->enabled_features.acceleration_structure.accelerationStructure,
                   "acceleration structures need the accelerationStructure feature enabled");
    caller.require(device.state()->enabled_features.vulkan12.bufferDeviceAddress,
                   "acceleration structures need the bufferDeviceAddress feature enabled");
}

// The device's VkPhysicalDeviceAccelerationStructurePropertiesKHR.
VkPhysicalDeviceAccelerationStructurePropertiesKHR structure_properties(const Device& device) {
    VkPhysicalDeviceAccelerationStructurePropertiesKHR props{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &props};
    const PhysicalDevice& physical = device.physical_device();
    physical.fn().vkGetPhysicalDeviceProperties2(physical.vk(), &p2);
    props.pNext = nullptr;
    return props;
}

// A buffer for the build's own use, its address aligned to alignment (the
// buffer is made that much larger); address receives the aligned address.
Buffer build_buffer(const Device& device, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUsage memory,
                    AllocatorView allocator, VkDeviceSize alignment, VkDeviceAddress& address) {
    const VkDeviceSize slack = alignment > 1 ? alignment - 1 : 0;
    Buffer buffer = Buffer::create(device, {.size = size + slack,
                                            .usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                            .memory = {.usage = memory},
                                            .allocator = allocator});
    address = detail::align_up(buffer.device_address(), alignment);
    return buffer;
}

}  // namespace

AccelerationStructure AccelerationStructure::create(const Device& device, const AccelerationStructureCreateInfo& info) {
    const detail::Caller caller{"vkrc::AccelerationStructure::create"};
    caller.require_handle(device, "the Device");
    require_support(caller, device);
    caller.require_handle(info.buffer, "the Buffer");
    caller.require(info.buffer.device() == device, "the buffer belongs to another device");
    caller.require(info.buffer.usage() & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR,
                   "the buffer lacks ACCELERATION_STRUCTURE_STORAGE usage (VUID-VkAccelerationStructureCreateInfoKHR-"
                   "buffer-03614)");
    caller.require(info.offset % 256 == 0, "offset ", info.offset,
                   " is not a multiple of 256 (VUID-VkAccelerationStructureCreateInfoKHR-offset-03734)");
    caller.require(info.offset < info.buffer.size(), "offset ", info.offset, " is past the buffer's ",
                   info.buffer.size(), " bytes");
    const VkDeviceSize size = info.size != 0 ? info.size : info.buffer.size() - info.offset;
    caller.require(size <= info.buffer.size() - info.offset, "size ", size, " at offset ", info.offset,
                   " does not fit the buffer's ", info.buffer.size(), " bytes");
    VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR, info.next};
    ci.createFlags = info.create_flags;
    ci.buffer = info.buffer.vk();
    ci.offset = info.offset;
    ci.size = size;
    ci.type = info.type;
    auto state =
        detail::created_state<detail::AccelerationStructureState, &DeviceFunctions::vkCreateAccelerationStructureKHR>(
            device, ci, "vkCreateAccelerationStructureKHR");
    state->buffer = info.buffer;
    state->size = size;
    state->type = info.type;
    const VkAccelerationStructureDeviceAddressInfoKHR address{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR, nullptr, state->handle};
    state->device_address = device.fn().vkGetAccelerationStructureDeviceAddressKHR(device.vk(), &address);
    device.state()->objects.add(detail::DescribedKind::acceleration_structure, detail::handle_bits(state->handle),
                                state.get());
    return AccelerationStructure(std::move(state));
}

List<AccelerationStructure> AccelerationStructure::bottom_levels() const {
    const auto& s = live("vkrc::AccelerationStructure::bottom_levels");
    LockGuard lock(s.mutex);
    return s.bottom_levels;
}

namespace {

// A structure of type and size over a buffer of its own.
AccelerationStructure structure_of(const Device& device, VkAccelerationStructureTypeKHR type, VkDeviceSize size,
                                   AllocatorView allocator) {
    Buffer storage = Buffer::create(device, {.size = size,
                                             .usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                                      VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                             .allocator = allocator});
    return AccelerationStructure::create(device, {.buffer = storage, .type = type});
}

// The geometries of a bottom-level build, checked, in Vulkan's form.
struct BuildInputs {
    std::vector<VkAccelerationStructureGeometryKHR> geometries;
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
    std::vector<std::uint32_t> counts;
};

// An input buffer of list[i] (what names it, e.g. "vertex_buffer"):
// this device's, with the usage a build reads it through.
void check_input(const detail::Caller& caller, const Device& device, const Buffer& buffer, const char* list,
                 std::size_t i, const char* what) {
    caller.require(buffer.device() == device, list, "[", i, "].", what, " belongs to another device");
    caller.require((buffer.usage() & input_usage) == input_usage, list, "[", i, "].", what,
                   " lacks SHADER_DEVICE_ADDRESS or ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY usage");
}

// One geometry's checks: buffers, counts, and that what it reads lies in its buffers.
void check_triangles(const detail::Caller& caller, const Device& device, const TriangleGeometry& g, std::size_t i) {
    caller.require(static_cast<bool>(g.vertex_buffer), "geometries[", i, "] has no vertex_buffer");
    check_input(caller, device, g.vertex_buffer, "geometries", i, "vertex_buffer");
    caller.require(g.triangle_count != 0, "geometries[", i, "] has triangle_count 0");
    caller.require(g.vertex_stride != 0 && g.vertex_stride % 2 == 0 && g.vertex_stride <= UINT32_MAX, "geometries[", i,
                   "] has vertex_stride ", g.vertex_stride, "; it must be a non-zero multiple of its component size");
    const VkDeviceSize vertex_end = g.vertex_offset + (VkDeviceSize(g.max_vertex) + 1) * g.vertex_stride;
    caller.require(vertex_end <= g.vertex_buffer.size(), "geometries[", i, "]: vertices 0 to ", g.max_vertex,
                   " at stride ", g.vertex_stride, " from offset ", g.vertex_offset, " need ", vertex_end,
                   " bytes, the vertex_buffer has ", g.vertex_buffer.size());
    if (g.index_buffer) {
        check_input(caller, device, g.index_buffer, "geometries", i, "index_buffer");
        caller.require(g.index_type == VK_INDEX_TYPE_UINT16 || g.index_type == VK_INDEX_TYPE_UINT32, "geometries[", i,
                       "] has index_type ", g.index_type, "; UINT16 or UINT32 with an index_buffer");
        const VkDeviceSize index_size = g.index_type == VK_INDEX_TYPE_UINT16 ? 2 : 4;
        const VkDeviceSize index_end = g.index_offset + VkDeviceSize(g.triangle_count) * 3 * index_size;
        caller.require(g.index_offset % index_size == 0 && index_end <= g.index_buffer.size(), "geometries[", i,
                       "]: ", g.triangle_count, " triangles of indices from offset ", g.index_offset,
                       " do not fit (aligned) in the index_buffer's ", g.index_buffer.size(), " bytes");
    } else {
        caller.require(VkDeviceSize(g.triangle_count) * 3 <= VkDeviceSize(g.max_vertex) + 1, "geometries[", i,
                       "] is not indexed: ", g.triangle_count, " triangles need ", VkDeviceSize(g.triangle_count) * 3,
                       " vertices, max_vertex is ", g.max_vertex);
    }
    if (g.transform_buffer) {
        check_input(caller, device, g.transform_buffer, "geometries", i, "transform_buffer");
        caller.require(g.transform_offset % 16 == 0 &&
                           g.transform_offset + sizeof(VkTransformMatrixKHR) <= g.transform_buffer.size(),
                       "geometries[", i, "]: transform_offset ", g.transform_offset,
                       " is not a multiple of 16 or the matrix does not fit the transform_buffer");
    }
}

// A geometry of type with flags, its data for the caller to fill in.
VkAccelerationStructureGeometryKHR geometry_of(VkGeometryTypeKHR type, VkGeometryFlagsKHR flags) {
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = type;
    geometry.flags = flags;
    return geometry;
}

VkAccelerationStructureGeometryKHR triangles_of(const TriangleGeometry& g) {
    auto geometry = geometry_of(VK_GEOMETRY_TYPE_TRIANGLES_KHR, g.flags);
    auto& t = geometry.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = g.vertex_format;
    t.vertexData.deviceAddress = g.vertex_buffer.device_address() + g.vertex_offset;
    t.vertexStride = g.vertex_stride;
    t.maxVertex = g.max_vertex;
    t.indexType = g.index_buffer ? g.index_type : VK_INDEX_TYPE_NONE_KHR;
    if (g.index_buffer) t.indexData.deviceAddress = g.index_buffer.device_address() + g.index_offset;
    if (g.transform_buffer) t.transformData.deviceAddress = g.transform_buffer.device_address() + g.transform_offset;
    return geometry;
}

// One box geometry's checks: its buffer, count, stride and that the boxes lie in it.
void check_aabbs(const detail::Caller& caller, const Device& device, const AabbGeometry& g, std::size_t i) {
    caller.require(static_cast<bool>(g.buffer), "aabbs[", i, "] has no buffer");
    check_input(caller, device, g.buffer, "aabbs", i, "buffer");
    caller.require(g.count != 0, "aabbs[", i, "] has count 0");
    // VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545 and the address's 8-byte alignment (-03714).
    caller.require(g.stride % 8 == 0 && g.stride >= sizeof(VkAabbPositionsKHR) && g.stride <= UINT32_MAX, "aabbs[", i,
                   "] has stride ", g.stride, "; it must be a multiple of 8, at least 24");
    caller.require(g.offset % 8 == 0, "aabbs[", i, "] has offset ", g.offset, "; it must be a multiple of 8");
    const VkDeviceSize end = g.offset + VkDeviceSize(g.count - 1) * g.stride + sizeof(VkAabbPositionsKHR);
    caller.require(end <= g.buffer.size(), "aabbs[", i, "]: ", g.count, " boxes at stride ", g.stride, " from offset ",
                   g.offset, " need ", end, " bytes, the buffer has ", g.buffer.size());
}

VkAccelerationStructureGeometryKHR aabbs_of(const AabbGeometry& g) {
    auto geometry = geometry_of(VK_GEOMETRY_TYPE_AABBS_KHR, g.flags);
    auto& a = geometry.geometry.aabbs;
    a.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
    a.data.deviceAddress = g.buffer.device_address() + g.offset;
    a.stride = g.stride;
    return geometry;
}

// The triangles or the boxes of info (a bottom level holds one kind:
// VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03792), checked.
BuildInputs geometry_inputs(const detail::Caller& caller, const Device& device, const BottomLevelBuildInfo& info) {
    caller.require(!info.geometries.empty() || !info.aabbs.empty(), "geometries and aabbs are both empty");
    caller.require(info.geometries.empty() || info.aabbs.empty(),
                   "geometries and aabbs are both set; a bottom level holds triangles or boxes, not both");
    BuildInputs in;
    for (std::size_t i = 0; i < info.geometries.size(); ++i) {
        const TriangleGeometry& g = info.geometries[i];
        check_triangles(caller, device, g, i);
        in.geometries.push_back(triangles_of(g));
        in.ranges.push_back({g.triangle_count, 0, 0, 0});
        in.counts.push_back(g.triangle_count);
    }
    for (std::size_t i = 0; i < info.aabbs.size(); ++i) {
        const AabbGeometry& g = info.aabbs[i];
        check_aabbs(caller, device, g, i);
        in.geometries.push_back(aabbs_of(g));
        in.ranges.push_back({g.count, 0, 0, 0});
        in.counts.push_back(g.count);
    }
    return in;
}

// The command buffer's device, after the checks every build makes.
const Device& build_device(const detail::Caller& caller, const CommandBuffer& cmd) {
    caller.require_handle(cmd, "the CommandBuffer");
    const Device& device = cmd.pool().device();
    require_support(caller, device);
    return device;
}

// The command buffer's device, after build_device's checks and those of the
// structure a call works on: not empty, of that device and, unless type is
// VK_ACCELERATION_STRUCTURE_TYPE_MAX_ENUM_KHR, of that level.
const Device& structure_device(const detail::Caller& caller, const CommandBuffer& cmd,
                               const AccelerationStructure& structure, VkAccelerationStructureTypeKHR type) {
    const Device& device = build_device(caller, cmd);
    caller.require_handle(structure, "the AccelerationStructure");
    caller.require(structure.device() == device, "the structure belongs to another device");
    caller.require(type == VK_ACCELERATION_STRUCTURE_TYPE_MAX_ENUM_KHR || structure.type() == type,
                   "the structure is not a ",
                   type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR ? "top level" : "bottom level");
    return device;
}

// One build of geometries into dst (from src when updating): sizes, scratch,
// the recorded call. dst null: makes the structure of type with a buffer of
// its own. Returns dst (or what it made).
AccelerationStructure record_build(const detail::Caller& caller, const CommandBuffer& cmd,
                                   VkAccelerationStructureBuildGeometryInfoKHR build, const std::uint32_t* counts,
                                   const VkAccelerationStructureBuildRangeInfoKHR* ranges, AccelerationStructure dst,
                                   AllocatorView allocator) {
    const Device& device = cmd.pool().device();
    const auto& fn = device.fn();
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    fn.vkGetAccelerationStructureBuildSizesKHR(device.vk(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &build,
                                               counts, &sizes);
    if (!dst) dst = structure_of(device, build.type, sizes.accelerationStructureSize, allocator);
    caller.require(sizes.accelerationStructureSize <= dst.size(), "the build needs ", sizes.accelerationStructureSize,
                   " bytes, the structure has ", dst.size());
    const bool update = build.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    const VkDeviceSize scratch_size = update ? sizes.updateScratchSize : sizes.buildScratchSize;
    VkDeviceAddress scratch_address = 0;
    // Dropped on return: held until cmd closes, then until the GPU is done.
    const Buffer scratch =
        build_buffer(device, scratch_size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::gpu_only, allocator,
                     structure_properties(device).minAccelerationStructureScratchOffsetAlignment, scratch_address);
    build.dstAccelerationStructure = dst.vk();
    if (update) build.srcAccelerationStructure = dst.vk();
    build.scratchData.deviceAddress = scratch_address;
    cmd.build_acceleration_structures(Span(&build, 1), &ranges);
    dst.state()->build_flags = build.flags;
    return dst;
}

VkAccelerationStructureBuildGeometryInfoKHR build_info(VkAccelerationStructureTypeKHR type,
                                                       VkBuildAccelerationStructureFlagsKHR flags,
                                                       const VkAccelerationStructureGeometryKHR* geometries,
                                                       std::size_t count) {
    VkAccelerationStructureBuildGeometryInfoKHR build{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    build.type = type;
    build.flags = flags;
    build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    build.geometryCount = static_cast<std::uint32_t>(count);
    build.pGeometries = geometries;
    return build;
}

}  // namespace

AccelerationStructure build_bottom_level(const CommandBuffer& cmd, const BottomLevelBuildInfo& info) {
    const detail::Caller caller{"vkrc::build_bottom_level"};
    const Device& device = build_device(caller, cmd);
    const BuildInputs in = geometry_inputs(caller, device, info);
    const auto build = build_info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, info.flags, in.geometries.data(),
                                  in.geometries.size());
    return record_build(caller, cmd, build, in.counts.data(), in.ranges.data(), {}, info.allocator);
}

void update_bottom_level(const CommandBuffer& cmd, const AccelerationStructure& bottom_level,
                         const BottomLevelBuildInfo& info) {
    const detail::Caller caller{"vkrc::update_bottom_level"};
    const Device& device = structure_device(caller, cmd, bottom_level, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
    caller.require(bottom_level.build_flags() & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR,
                   "the structure was not built with ALLOW_UPDATE (VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-"
                   "03667)");
    caller.require(info.flags == bottom_level.build_flags(), "flags ", detail::Hex{info.flags},
                   " differ from the build's ", detail::Hex{bottom_level.build_flags()});
    const BuildInputs in = geometry_inputs(caller, device, info);
    auto build = build_info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, info.flags, in.geometries.data(),
                            in.geometries.size());
    build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    record_build(caller, cmd, build, in.counts.data(), in.ranges.data(), bottom_level, info.allocator);
}

namespace {

// The instances in Vulkan's form, checked; bottom receives the bottom levels to keep.
std::vector<VkAccelerationStructureInstanceKHR> instance_records(const detail::Caller& caller, const Device& device,
                                                                 const TopLevelBuildInfo& info,
                                                                 List<AccelerationStructure>& bottom) {
    caller.require(!info.instances.empty(), "instances is empty");
    std::vector<VkAccelerationStructureInstanceKHR> records;
    records.reserve(info.instances.size());
    bottom.reserve(info.instances.size());
    for (std::size_t i = 0; i < info.instances.size(); ++i) {
        const AccelerationStructureInstance& in = info.instances[i];
        caller.require(static_cast<bool>(in.bottom_level), "instances[", i, "] has no bottom_level");
        caller.require(in.bottom_level.device() == device, "instances[", i, "].bottom_level belongs to another device");
        caller.require(in.bottom_level.type() == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, "instances[", i,
                       "].bottom_level is not a bottom-level structure");
        caller.require(in.custom_index < (1u << 24) && in.sbt_offset < (1u << 24), "instances[", i, "]: custom_index ",
                       in.custom_index, " or sbt_offset ", in.sbt_offset, " exceeds 24 bits");
        caller.require(in.flags < (1u << 8), "instances[", i, "]: flags ", detail::Hex{in.flags}, " exceed 8 bits");
        VkAccelerationStructureInstanceKHR r{};
        r.transform = in.transform;
        r.instanceCustomIndex = in.custom_index & 0xFFFFFFu;  // checked above
        r.mask = in.mask;
        r.instanceShaderBindingTableRecordOffset = in.sbt_offset & 0xFFFFFFu;
        r.flags = in.flags & 0xFFu;
        r.accelerationStructureReference = in.bottom_level.device_address();
        records.push_back(r);
        bottom.push_back(in.bottom_level);
    }
    return records;
}

// Writes the instances, records the build into top_level (null: makes one)
// and swaps in the bottom levels it keeps; returns the structure.
AccelerationStructure record_top_level(const detail::Caller& caller, const CommandBuffer& cmd,
                                       AccelerationStructure top_level, const TopLevelBuildInfo& info) {
    const Device& device = cmd.pool().device();
    List<AccelerationStructure> bottom;
    const auto records = instance_records(caller, device, info, bottom);
    VkDeviceAddress address = 0;
    // Dropped on return, as the scratch is: held until cmd closes and the GPU is done.
    const Buffer instances = build_buffer(device, records.size() * sizeof(records[0]),
                                          VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                                          MemoryUsage::upload, info.allocator, 16, address);
    instances.allocation().write(address - instances.device_address(), records.data(), records.size());
    auto geometry = geometry_of(VK_GEOMETRY_TYPE_INSTANCES_KHR, 0);
    geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    geometry.geometry.instances.data.deviceAddress = address;
    const auto count = static_cast<std::uint32_t>(records.size());
    const VkAccelerationStructureBuildRangeInfoKHR range{count, 0, 0, 0};
    const auto build = build_info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, info.flags, &geometry, 1);
    top_level = record_build(caller, cmd, build, &count, &range, top_level, info.allocator);
    auto& s = *top_level.state();
    {
        LockGuard lock(s.mutex);
        s.bottom_levels.swap(bottom);
    }
    // bottom now holds the previous build's: released here, as drops (after the GPU).
    return top_level;
}

}  // namespace

AccelerationStructure build_top_level(const CommandBuffer& cmd, const TopLevelBuildInfo& info) {
    const detail::Caller caller{"vkrc::build_top_level"};
    build_device(caller, cmd);
    return record_top_level(caller, cmd, {}, info);
}

void rebuild_top_level(const CommandBuffer& cmd, const AccelerationStructure& top_level,
                       const TopLevelBuildInfo& info) {
    const detail::Caller caller{"vkrc::rebuild_top_level"};
    structure_device(caller, cmd, top_level, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
    record_top_level(caller, cmd, top_level, info);
}

AccelerationStructure compact(const CommandBuffer& cmd, const AccelerationStructure& source,
                              VkDeviceSize compacted_size, AllocatorView allocator) {
    const detail::Caller caller{"vkrc::compact"};
    const Device& device = structure_device(caller, cmd, source, VK_ACCELERATION_STRUCTURE_TYPE_MAX_ENUM_KHR);
    caller.require(source.build_flags() & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR,
                   "the structure was not built with ALLOW_COMPACTION (VUID-VkCopyAccelerationStructureInfoKHR-src-"
                   "03411)");
    caller.require(compacted_size != 0 && compacted_size <= source.size(), "compacted_size ", compacted_size,
                   " is 0 or more than the structure's ", source.size(),
                   " bytes (read it with a "
                   "ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR query)");
    AccelerationStructure dst = structure_of(device, source.type(), compacted_size, allocator);
    cmd.copy_acceleration_structure(source, dst, VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
    auto& d = *dst.state();
    d.build_flags = source.build_flags();
    List<AccelerationStructure> bottom = source.bottom_levels();
    LockGuard lock(d.mutex);
    d.bottom_levels.swap(bottom);
    return dst;
}

// The accessors, out of line: none is on a per-frame path.
VkAccelerationStructureTypeKHR AccelerationStructure::type() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::AccelerationStructure::type").type;
}
VkDeviceSize AccelerationStructure::size() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::AccelerationStructure::size").size;
}
VkDeviceAddress AccelerationStructure::device_address() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::AccelerationStructure::device_address").device_address;
}
const Buffer& AccelerationStructure::buffer() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::AccelerationStructure::buffer").buffer;
}
VkBuildAccelerationStructureFlagsKHR AccelerationStructure::build_flags() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::AccelerationStructure::build_flags").build_flags;
}

VKRC_END_NAMESPACE
