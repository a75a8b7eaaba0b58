// Issue 14's pipeline state: specialization constants, the full graphics
// state of GraphicsPipelineBuilder, and ComputePipeline's create info.
#include "vkrc/pipeline.hpp"

#include <algorithm>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

void require(bool ok, const char* who, const std::string& problem) {
    if (!ok) throw UsageError(std::string(who) + ": " + problem);
}

void check_specialization(const Specialization& spec, const char* who) {
    for (const auto& e : spec.map_entries) {
        require(e.offset <= spec.data.size() && e.size <= spec.data.size() - e.offset, who,
                "specialization constant " + std::to_string(e.constantID) + " lies outside the data (" +
                    std::to_string(spec.data.size()) + " bytes)");
    }
}

VkSpecializationInfo specialization_info(Span<const VkSpecializationMapEntry> entries, Span<const std::byte> data) {
    return {static_cast<std::uint32_t>(entries.size()), entries.data(), data.size(), data.data()};
}

constexpr VkShaderStageFlags tessellation_stages =
    VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT | VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT;

bool contains(Span<const VkDynamicState> states, VkDynamicState state) {
    return std::find(states.begin(), states.end(), state) != states.end();
}

VkBool32 vk_bool(bool b) { return b ? VK_TRUE : VK_FALSE; }

constexpr const char* build_who = "vkrc::GraphicsPipelineBuilder::build";

}  // namespace

ComputePipeline ComputePipeline::create(const PipelineLayout& layout, const ComputePipelineCreateInfo& info) {
    const char* who = "vkrc::ComputePipeline::create";
    require(static_cast<bool>(layout), who, "the PipelineLayout handle is empty");
    require(static_cast<bool>(info.module), who, "the ShaderModule handle is empty");
    require(info.module.device() == layout.device(), who,
            "the ShaderModule belongs to another device than the pipeline layout");
    check_specialization(info.specialization, who);
    const auto spec = specialization_info(info.specialization.map_entries, info.specialization.data);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.pNext = info.next;
    ci.flags = info.flags;
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.pNext = info.stage_next;
    ci.stage.flags = info.stage_flags;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = info.module.vk();
    ci.stage.pName = info.entry_point;
    ci.stage.pSpecializationInfo = info.specialization.map_entries.empty() ? nullptr : &spec;
    ci.layout = layout.vk();
    const auto& d = layout.device();
    detail::Ref<detail::PipelineState> s(new detail::PipelineState);
    s->layout = layout;
    s->bind_point = VK_PIPELINE_BIND_POINT_COMPUTE;
    const VkPipelineCache cache = info.cache ? info.cache.vk() : VK_NULL_HANDLE;
    check(d.fn().vkCreateComputePipelines(d.vk(), cache, 1, &ci, nullptr, &s->handle), "vkCreateComputePipelines");
    return ComputePipeline(std::move(s));
}

GraphicsPipelineBuilder& GraphicsPipelineBuilder::rasterization(const RasterizationState& state) {
    raster_ = state;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::depth_stencil(const DepthStencilState& state) {
    depth_stencil_ = state;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::multisample(const MultisampleState& state) {
    multisample_ = state;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::blend_attachments(
    Span<const VkPipelineColorBlendAttachmentState> states) {
    blends_ = states;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::blend_constants(const float (&constants)[4]) {
    std::copy(std::begin(constants), std::end(constants), blend_constants_);
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::logic_op(VkLogicOp op) {
    logic_op_enable_ = true;
    logic_op_ = op;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::viewports(Span<const VkViewport> viewports) {
    viewports_ = viewports;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::scissors(Span<const VkRect2D> scissors) {
    scissors_ = scissors;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::dynamic_states(Span<const VkDynamicState> states) {
    dynamic_states_ = states;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::primitive_restart(bool enable) {
    primitive_restart_ = enable;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::specialization(VkShaderStageFlagBits stage,
                                                                 const Specialization& spec) {
    check_specialization(spec, "vkrc::GraphicsPipelineBuilder::specialization");
    Specialized copy{stage, spec.map_entries, spec.data};
    for (auto& s : specializations_) {
        if (s.stage == stage) {
            s = std::move(copy);
            return *this;
        }
    }
    specializations_.push_back(std::move(copy));
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::tessellation(std::uint32_t patch_control_points) {
    patch_control_points_ = patch_control_points;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::view_mask(std::uint32_t mask) {
    view_mask_ = mask;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::flags(VkPipelineCreateFlags flags) {
    flags_ = flags;
    return *this;
}
GraphicsPipelineBuilder& GraphicsPipelineBuilder::next(const void* chain) {
    next_ = chain;
    return *this;
}

void GraphicsPipelineBuilder::attach_specializations(Span<VkPipelineShaderStageCreateInfo> stages,
                                                     Span<VkSpecializationInfo> infos) const {
    for (const auto& sp : specializations_) {
        auto it = std::find_if(stages.begin(), stages.end(), [&](const auto& st) { return st.stage == sp.stage; });
        require(it != stages.end(), build_who, "a specialization names a stage without a shader");
        auto& info = infos[static_cast<std::size_t>(it - stages.begin())];
        info = specialization_info(sp.entries, sp.data);
        it->pSpecializationInfo = &info;
    }
}

void GraphicsPipelineBuilder::check_tessellation() const {
    bool tessellated = false;
    for (const auto& st : stages_) tessellated |= (st.stage & tessellation_stages) != 0;
    require(!tessellated || patch_control_points_ > 0, build_who, "tessellation shaders without tessellation()");
    require(!tessellated || topology_ == VK_PRIMITIVE_TOPOLOGY_PATCH_LIST, build_who,
            "tessellation shaders need topology PATCH_LIST");
}

VkPipelineViewportStateCreateInfo GraphicsPipelineBuilder::viewport_state() const {
    require(viewports_.empty() || scissors_.empty() || viewports_.size() == scissors_.size(), build_who,
            "viewports and scissors differ in count");
    const auto count = static_cast<std::uint32_t>(std::max<std::size_t>({1, viewports_.size(), scissors_.size()}));
    VkPipelineViewportStateCreateInfo v{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    // With counts dynamic, Vulkan wants 0 here.
    const bool dynamic_viewports = contains(dynamic_states_, VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT);
    const bool dynamic_scissors = contains(dynamic_states_, VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT);
    // Static ones must be given: Vulkan would read them from a null pointer.
    require(viewports_.size() > 0 || dynamic_viewports || contains(dynamic_states_, VK_DYNAMIC_STATE_VIEWPORT),
            build_who, "viewports are neither dynamic nor given with viewports()");
    require(scissors_.size() > 0 || dynamic_scissors || contains(dynamic_states_, VK_DYNAMIC_STATE_SCISSOR), build_who,
            "scissors are neither dynamic nor given with scissors()");
    v.viewportCount = dynamic_viewports ? 0 : count;
    v.pViewports = viewports_.empty() ? nullptr : viewports_.data();
    v.scissorCount = dynamic_scissors ? 0 : count;
    v.pScissors = scissors_.empty() ? nullptr : scissors_.data();
    return v;
}

VkPipelineRasterizationStateCreateInfo GraphicsPipelineBuilder::rasterization_state() const {
    VkPipelineRasterizationStateCreateInfo r{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    r.pNext = raster_.next;
    r.depthClampEnable = vk_bool(raster_.depth_clamp_enable);
    r.rasterizerDiscardEnable = vk_bool(raster_.rasterizer_discard_enable);
    r.polygonMode = raster_.polygon_mode;
    r.cullMode = raster_.cull_mode;
    r.frontFace = raster_.front_face;
    r.depthBiasEnable = vk_bool(raster_.depth_bias_enable);
    r.depthBiasConstantFactor = raster_.depth_bias_constant_factor;
    r.depthBiasClamp = raster_.depth_bias_clamp;
    r.depthBiasSlopeFactor = raster_.depth_bias_slope_factor;
    r.lineWidth = raster_.line_width;
    return r;
}

VkPipelineMultisampleStateCreateInfo GraphicsPipelineBuilder::multisample_state() const {
    VkPipelineMultisampleStateCreateInfo m{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    m.pNext = multisample_.next;
    m.rasterizationSamples = multisample_.rasterization_samples;
    m.sampleShadingEnable = vk_bool(multisample_.sample_shading_enable);
    m.minSampleShading = multisample_.min_sample_shading;
    m.alphaToCoverageEnable = vk_bool(multisample_.alpha_to_coverage_enable);
    m.alphaToOneEnable = vk_bool(multisample_.alpha_to_one_enable);
    return m;
}

VkPipelineDepthStencilStateCreateInfo GraphicsPipelineBuilder::depth_stencil_state() const {
    VkPipelineDepthStencilStateCreateInfo d{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    d.pNext = depth_stencil_.next;
    d.flags = depth_stencil_.flags;
    d.depthTestEnable = vk_bool(depth_stencil_.depth_test_enable);
    d.depthWriteEnable = vk_bool(depth_stencil_.depth_write_enable);
    d.depthCompareOp = depth_stencil_.depth_compare_op;
    d.depthBoundsTestEnable = vk_bool(depth_stencil_.depth_bounds_test_enable);
    d.stencilTestEnable = vk_bool(depth_stencil_.stencil_test_enable);
    d.front = depth_stencil_.front;
    d.back = depth_stencil_.back;
    d.minDepthBounds = depth_stencil_.min_depth_bounds;
    d.maxDepthBounds = depth_stencil_.max_depth_bounds;
    return d;
}

VkPipelineVertexInputStateCreateInfo GraphicsPipelineBuilder::vertex_input_state() const {
    VkPipelineVertexInputStateCreateInfo v{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    v.vertexBindingDescriptionCount = static_cast<std::uint32_t>(bindings_.size());
    v.pVertexBindingDescriptions = bindings_.data();
    v.vertexAttributeDescriptionCount = static_cast<std::uint32_t>(attributes_.size());
    v.pVertexAttributeDescriptions = attributes_.data();
    return v;
}

VkPipelineInputAssemblyStateCreateInfo GraphicsPipelineBuilder::input_assembly_state() const {
    VkPipelineInputAssemblyStateCreateInfo a{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    a.topology = topology_;
    a.primitiveRestartEnable = vk_bool(primitive_restart_);
    return a;
}

VkPipelineRenderingCreateInfo GraphicsPipelineBuilder::rendering_info() const {
    require(!render_pass_ || view_mask_ == 0, build_who,
            "view_mask is for dynamic rendering; a render pass has its own");
    VkPipelineRenderingCreateInfo r{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    r.pNext = next_;
    if (render_pass_) return r;  // unused: the render pass describes the attachments
    r.colorAttachmentCount = static_cast<std::uint32_t>(color_formats_.size());
    r.pColorAttachmentFormats = color_formats_.data();
    r.depthAttachmentFormat = depth_format_;
    r.stencilAttachmentFormat = stencil_format_;
    r.viewMask = view_mask_;
    return r;
}

VkPipelineColorBlendStateCreateInfo GraphicsPipelineBuilder::color_blend_state(
    std::uint32_t color_count, List<VkPipelineColorBlendAttachmentState>& attachments) const {
    if (!blends_.empty() && blends_.size() != color_count) {
        throw UsageError(std::string(build_who) + ": blend_attachments has " + std::to_string(blends_.size()) +
                         " states for " + std::to_string(color_count) + " colour attachments");
    }
    if (!blends_.empty()) {
        attachments = blends_;
    } else {
        attachments = List<VkPipelineColorBlendAttachmentState>(color_count);
        std::fill(attachments.begin(), attachments.end(), blend_);
    }
    VkPipelineColorBlendStateCreateInfo b{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    b.attachmentCount = color_count;
    b.pAttachments = attachments.data();
    b.logicOpEnable = vk_bool(logic_op_enable_);
    b.logicOp = logic_op_;
    std::copy(std::begin(blend_constants_), std::end(blend_constants_), b.blendConstants);
    return b;
}

VkPipelineDynamicStateCreateInfo GraphicsPipelineBuilder::dynamic_state_info() const {
    VkPipelineDynamicStateCreateInfo d{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    d.dynamicStateCount = static_cast<std::uint32_t>(dynamic_states_.size());
    d.pDynamicStates = dynamic_states_.data();
    return d;
}

VKRC_END_NAMESPACE
