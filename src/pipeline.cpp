#include "vkrc/pipeline.hpp"

#include "caller.hpp"
#include "object_state.hpp"
#include "text.hpp"

#include <algorithm>
#include <filesystem>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {
PipelineLayoutState::~PipelineLayoutState() { destroy_owned<&DeviceFunctions::vkDestroyPipelineLayout>(*this, device); }
RenderPassState::~RenderPassState() { destroy_owned<&DeviceFunctions::vkDestroyRenderPass>(*this, device); }
FramebufferState::~FramebufferState() {
    if (render_pass) destroy_owned<&DeviceFunctions::vkDestroyFramebuffer>(*this, render_pass.device());
}
PipelineCacheState::~PipelineCacheState() { destroy_owned<&DeviceFunctions::vkDestroyPipelineCache>(*this, device); }
PipelineState::~PipelineState() {
    if (layout) destroy_owned<&DeviceFunctions::vkDestroyPipeline>(*this, layout.device());
}
}  // namespace detail

PipelineLayout::PipelineLayout(detail::Ref<detail::PipelineLayoutState> state) noexcept
    : DeviceChild(std::move(state)), handle_(state_->handle) {}

PipelineLayout PipelineLayout::create(const Device& device) { return create(device, PipelineLayoutCreateInfo{}); }

PipelineLayout PipelineLayout::adopt(const Device& device, VkPipelineLayout layout, Ownership ownership) {
    return PipelineLayout(detail::adopted_state<detail::PipelineLayoutState>(
        detail::Caller{"vkrc::PipelineLayout::adopt"}, device, "the Device", layout, "VkPipelineLayout", ownership));
}

RenderPass RenderPass::adopt(const Device& device, VkRenderPass render_pass,
                             Span<const std::uint32_t> color_attachment_counts, Ownership ownership) {
    List<std::uint32_t> counts(color_attachment_counts);  // before the state: a failed copy must not destroy
    auto s = detail::adopted_state<detail::RenderPassState>(detail::Caller{"vkrc::RenderPass::adopt"}, device,
                                                            "the Device", render_pass, "VkRenderPass", ownership);
    s->color_counts = std::move(counts);
    return RenderPass(std::move(s));
}

Framebuffer Framebuffer::adopt(const RenderPass& render_pass, VkFramebuffer framebuffer, VkExtent2D extent,
                               Ownership ownership) {
    auto s = detail::adopted_state<detail::FramebufferState, &detail::FramebufferState::render_pass>(
        detail::Caller{"vkrc::Framebuffer::adopt"}, render_pass, "the RenderPass", framebuffer, "VkFramebuffer",
        ownership);
    s->extent = extent;
    return Framebuffer(std::move(s));
}

PipelineCache PipelineCache::adopt(const Device& device, VkPipelineCache cache, Ownership ownership) {
    return PipelineCache(detail::adopted_state<detail::PipelineCacheState>(
        detail::Caller{"vkrc::PipelineCache::adopt"}, device, "the Device", cache, "VkPipelineCache", ownership));
}

Pipeline Pipeline::adopt(const PipelineLayout& layout, VkPipeline pipeline, VkPipelineBindPoint bind_point,
                         Ownership ownership) {
    auto s = detail::adopted_state<detail::PipelineState, &detail::PipelineState::layout>(
        detail::Caller{"vkrc::Pipeline::adopt"}, layout, "the PipelineLayout", pipeline, "VkPipeline", ownership);
    s->bind_point = bind_point;
    return Pipeline(std::move(s));
}

PipelineLayout PipelineLayout::create(const Device& device, const PipelineLayoutCreateInfo& info) {
    const detail::Caller caller{"vkrc::PipelineLayout::create"};
    caller.require_handle(device, "the Device");
    std::vector<VkDescriptorSetLayout> sets;
    for (const auto& l : info.set_layouts) {
        caller.require_handle(l, "a DescriptorSetLayout");
        caller.require(l.device() == device, "a DescriptorSetLayout belongs to another device");
        sets.push_back(l.vk());
    }
    VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    ci.pNext = info.next;
    ci.flags = info.flags;
    ci.setLayoutCount = static_cast<std::uint32_t>(sets.size());
    ci.pSetLayouts = sets.data();
    ci.pushConstantRangeCount = static_cast<std::uint32_t>(info.push_constant_ranges.size());
    ci.pPushConstantRanges = info.push_constant_ranges.data();
    List<VkPushConstantRange> ranges(info.push_constant_ranges);  // before the layout: a failed copy must not leak it
    auto s = detail::created_state<detail::PipelineLayoutState, &DeviceFunctions::vkCreatePipelineLayout>(
        device, ci, "vkCreatePipelineLayout");
    s->push_constant_ranges = std::move(ranges);
    s->push_constant_ranges_known = true;
    return PipelineLayout(std::move(s));
}

namespace detail {
namespace {
// "[offset, offset + size) of stage flags 0x..", as push_constants' messages write a range.
std::string range_text(std::uint32_t offset, std::uint32_t size, VkShaderStageFlags stages) {
    // Appended, not "[" + string: GCC 12's -Wrestrict misfires on a literal
    // inserted before a temporary string (GCC bug 105651).
    std::string text("[");
    text += std::to_string(offset);
    text += ", ";
    text += std::to_string(std::uint64_t(offset) + size);
    text += ") of stage flags 0x";
    text += hex(stages);
    return text;
}
std::string ranges_text(Span<const VkPushConstantRange> ranges) {
    if (ranges.empty()) return "none";
    std::string out;
    for (const auto& r : ranges) out += (out.empty() ? "" : ", ") + range_text(r.offset, r.size, r.stageFlags);
    return out;
}
bool holds(const VkPushConstantRange& range, std::uint64_t byte) noexcept {
    return byte >= range.offset && byte < std::uint64_t(range.offset) + range.size;
}
}  // namespace

void check_push_constants(const PipelineLayout& layout, VkShaderStageFlags stages, std::uint32_t offset,
                          std::uint32_t size) {
    const Caller caller{"vkrc::CommandBuffer::push_constants"};
    caller.require_handle(layout, "the PipelineLayout");
    caller.require(stages != 0, "the stage flags are 0");
    caller.require(size != 0 && size % 4 == 0 && offset % 4 == 0, "offset ", offset, " and size ", size,
                   " must be multiples of 4 and size not 0");
    const PipelineLayoutState& s = *layout.state();
    if (!s.push_constant_ranges_known) return;
    const Span<const VkPushConstantRange> ranges(s.push_constant_ranges);
    const std::uint64_t end = std::uint64_t(offset) + size;
    for (const auto& r : ranges) {  // VUID-vkCmdPushConstants-offset-01796
        const bool overlaps = r.offset < end && offset < std::uint64_t(r.offset) + r.size;
        if (overlaps && (r.stageFlags & ~stages) != 0) {
            caller.refuse(range_text(offset, size, stages), " overlaps the layout's range ",
                          range_text(r.offset, r.size, r.stageFlags),
                          ", so the stage flags must include all of its stages");
        }
    }
    for (std::uint64_t byte = offset; byte < end; byte += 4) {  // VUID-vkCmdPushConstants-offset-01795
        VkShaderStageFlags covered = 0;
        for (const auto& r : ranges) covered |= holds(r, byte) ? r.stageFlags : 0;
        if ((stages & ~covered) != 0) {
            caller.refuse(range_text(offset, size, stages), ": byte ", byte,
                          " is in no push constant range of the layout for stage flags 0x", hex(stages & ~covered),
                          " (the layout's ranges: ", ranges_text(ranges), ")");
        }
    }
}
}  // namespace detail

RenderPass RenderPass::create(const Device& device, const RenderPassCreateInfo& info) {
    const detail::Caller caller{"vkrc::RenderPass::create"};
    caller.require_handle(device, "the Device");
    caller.require(!info.subpasses.empty(), "subpasses is empty");
    std::vector<VkSubpassDescription> subpasses;
    std::vector<std::uint32_t> color_counts;
    for (const auto& sp : info.subpasses) {
        caller.require(sp.resolve_attachments.empty() || sp.resolve_attachments.size() == sp.color_attachments.size(),
                       "resolve_attachments must be empty or one per colour attachment");
        VkSubpassDescription d{};
        d.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
        d.inputAttachmentCount = static_cast<std::uint32_t>(sp.input_attachments.size());
        d.pInputAttachments = sp.input_attachments.data();
        d.colorAttachmentCount = static_cast<std::uint32_t>(sp.color_attachments.size());
        d.pColorAttachments = sp.color_attachments.data();
        d.pResolveAttachments = sp.resolve_attachments.empty() ? nullptr : sp.resolve_attachments.data();
        d.pDepthStencilAttachment =
            sp.depth_stencil_attachment.attachment != VK_ATTACHMENT_UNUSED ? &sp.depth_stencil_attachment : nullptr;
        d.preserveAttachmentCount = static_cast<std::uint32_t>(sp.preserve_attachments.size());
        d.pPreserveAttachments = sp.preserve_attachments.data();
        subpasses.push_back(d);
        color_counts.push_back(d.colorAttachmentCount);
    }
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    ci.pNext = info.next;
    ci.flags = info.flags;
    ci.attachmentCount = static_cast<std::uint32_t>(info.attachments.size());
    ci.pAttachments = info.attachments.data();
    ci.subpassCount = static_cast<std::uint32_t>(subpasses.size());
    ci.pSubpasses = subpasses.data();
    ci.dependencyCount = static_cast<std::uint32_t>(info.dependencies.size());
    ci.pDependencies = info.dependencies.data();
    auto s = detail::created_state<detail::RenderPassState, &DeviceFunctions::vkCreateRenderPass>(device, ci,
                                                                                                  "vkCreateRenderPass");
    s->color_counts = std::move(color_counts);
    return RenderPass(std::move(s));
}

std::uint32_t RenderPass::color_attachment_count(std::uint32_t subpass) const {
    detail::Caller("vkrc::RenderPass::color_attachment_count")
        .require(subpass < state_->color_counts.size(), "the subpass does not exist");
    return state_->color_counts[subpass];
}

Framebuffer Framebuffer::create(const Device& device, const FramebufferCreateInfo& info) {
    const detail::Caller caller{"vkrc::Framebuffer::create"};
    caller.require_handle(device, "the Device");
    caller.require(static_cast<bool>(info.render_pass), "render_pass is empty");
    caller.require(info.width > 0 && info.height > 0 && info.layers > 0, "width, height and layers must be non-zero");
    std::vector<VkImageView> views;
    for (const auto& v : info.attachments) {
        caller.require_handle(v, "an attachment ImageView");
        views.push_back(v.vk());
    }
    VkFramebufferCreateInfo ci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    ci.pNext = info.next;
    ci.flags = info.flags;
    ci.renderPass = info.render_pass.vk();
    ci.attachmentCount = static_cast<std::uint32_t>(views.size());
    ci.pAttachments = views.data();
    ci.width = info.width;
    ci.height = info.height;
    ci.layers = info.layers;
    detail::Ref<detail::FramebufferState> s(new detail::FramebufferState);
    s->render_pass = info.render_pass;
    s->attachments = info.attachments;
    s->extent = {info.width, info.height};
    check(device.fn().vkCreateFramebuffer(device.vk(), &ci, nullptr, &s->handle), "vkCreateFramebuffer");
    return Framebuffer(std::move(s));
}

// Pipeline caches

PipelineCache PipelineCache::create(const Device& device, Span<const std::byte> initial_data) {
    detail::Caller("vkrc::PipelineCache::create").require_handle(device, "the Device");
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    ci.initialDataSize = initial_data.size();
    ci.pInitialData = initial_data.data();
    auto s = detail::created_state<detail::PipelineCacheState, &DeviceFunctions::vkCreatePipelineCache>(
        device, ci, "vkCreatePipelineCache");
    s->loaded_from_file = !initial_data.empty();
    return PipelineCache(std::move(s));
}

namespace {
// Why data cannot prime a cache on this device, or nullptr when it can. Drivers
// are meant to reject foreign data themselves; checking the header first keeps
// a buggy driver from ever seeing it.
const char* cache_data_problem(const PhysicalDevice& physical, const std::vector<std::byte>& data) {
    VkPipelineCacheHeaderVersionOne header{};
    if (data.size() < sizeof header) return "too short for a pipeline cache header";
    std::memcpy(&header, data.data(), sizeof header);
    const auto& p = physical.properties();
    if (header.headerSize < sizeof header || header.headerSize > data.size()) return "corrupt header";
    if (header.headerVersion != VK_PIPELINE_CACHE_HEADER_VERSION_ONE) return "unknown header version";
    if (header.vendorID != p.vendorID || header.deviceID != p.deviceID ||
        std::memcmp(header.pipelineCacheUUID, p.pipelineCacheUUID, VK_UUID_SIZE) != 0) {
        return "written by another driver or device";
    }
    return nullptr;
}
}  // namespace

PipelineCache PipelineCache::load(const Device& device, const char* file) {
    detail::Caller("vkrc::PipelineCache::load").require_handle(device, "the Device");
    std::vector<std::byte> data;
    const char* problem = nullptr;
    std::ifstream in(file, std::ios::binary);
    if (!in) {
        problem = "cannot be opened";
    } else {
        std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        data.resize(bytes.size());
        if (!bytes.empty()) std::memcpy(data.data(), bytes.data(), bytes.size());
        problem = cache_data_problem(device.physical_device(), data);
    }
    if (problem) {
        std::fprintf(stderr, "vkrc warning: PipelineCache::load: %s %s; starting with an empty cache\n", file, problem);
        return create(device);
    }
    return create(device, data);
}

List<std::byte> PipelineCache::data() const {
    const auto& d = state_->device;
    std::size_t size = 0;
    check(d.fn().vkGetPipelineCacheData(d.vk(), state_->handle, &size, nullptr), "vkGetPipelineCacheData");
    std::vector<std::byte> out(size);
    VkResult r =
        check(d.fn().vkGetPipelineCacheData(d.vk(), state_->handle, &size, out.data()), "vkGetPipelineCacheData");
    out.resize(size);
    (void)r;  // VK_INCOMPLETE only if the cache grew in between: the prefix is a valid cache
    return out;
}

void PipelineCache::save(const char* file) const {
    auto bytes = data();
    // Write beside the target and rename, so a crash never leaves a torn cache.
    std::string tmp = file;
    tmp += ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        if (!out) throw std::system_error(errno, std::generic_category(), "vkrc::PipelineCache::save: " + tmp);
    }
    std::filesystem::rename(tmp, file);
}

// Pipelines

ComputePipeline ComputePipeline::create(const PipelineLayout& layout, const ShaderModule& module,
                                        const char* entry_point, const PipelineCache& cache) {
    ComputePipelineCreateInfo info;
    info.module = module;
    info.entry_point = entry_point;
    info.cache = cache;
    return create(layout, info);
}

// The default dynamic states are set here rather than by a default member
// initialiser, which would build a vector in every includer (header cost).
GraphicsPipelineBuilder::GraphicsPipelineBuilder(PipelineLayout layout)
    : layout_(std::move(layout)), dynamic_states_{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR} {}

GraphicsPipelineBuilder& GraphicsPipelineBuilder::shader(VkShaderStageFlagBits stage, const ShaderModule& module,
                                                         const char* entry_point) {
    const detail::Caller caller{"vkrc::GraphicsPipelineBuilder::shader"};
    caller.require_handle(module, "the ShaderModule");
    caller.require(module.device() == layout_.device(),
                   "the ShaderModule belongs to another device than the pipeline layout");
    // VUID-VkPipelineShaderStageCreateInfo-stage-02091 and -02092.
    const auto& mesh_features = layout_.device().state()->enabled_features.mesh_shader;
    caller.require(stage != VK_SHADER_STAGE_MESH_BIT_EXT || mesh_features.meshShader,
                   "a mesh shader on a device created without the meshShader feature "
                   "(DeviceCreateInfo::mesh_shader_features)");
    caller.require(stage != VK_SHADER_STAGE_TASK_BIT_EXT || mesh_features.taskShader,
                   "a task shader on a device created without the taskShader feature "
                   "(DeviceCreateInfo::mesh_shader_features)");
    stages_.push_back({stage, module, entry_point});
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::vertex_binding(std::uint32_t binding, std::uint32_t stride,
                                                                 VkVertexInputRate input_rate) {
    bindings_.push_back({binding, stride, input_rate});
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::vertex_attribute(std::uint32_t location, std::uint32_t binding,
                                                                   VkFormat format, std::uint32_t offset) {
    attributes_.push_back({location, binding, format, offset});
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::depth_test(bool test, bool write, VkCompareOp compare) {
    depth_stencil_.depth_test_enable = test;
    depth_stencil_.depth_write_enable = write;
    depth_stencil_.depth_compare_op = compare;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::dynamic_state(VkDynamicState state) {
    dynamic_states_.push_back(state);
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::render_pass(const RenderPass& rp, std::uint32_t subpass) {
    render_pass_ = rp;
    subpass_ = subpass;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::rendering(Span<const VkFormat> color_formats, VkFormat depth_format,
                                                            VkFormat stencil_format) {
    color_formats_ = color_formats;
    depth_format_ = depth_format;
    stencil_format_ = stencil_format;
    return *this;
}

VkExtent2D Framebuffer::extent() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Framebuffer::extent").extent; }
const RenderPass& Framebuffer::render_pass() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Framebuffer::render_pass").render_pass;
}
bool PipelineCache::loaded_from_file() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::PipelineCache::loaded_from_file").loaded_from_file;
}

VKRC_END_NAMESPACE
