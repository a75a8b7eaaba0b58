// Making pipelines: specialization constants, the full graphics state of
// GraphicsPipelineBuilder and its build(), and ComputePipeline::create.
#include "vkrc/pipeline.hpp"

#include "object_state.hpp"

#include <algorithm>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

void check_specialization(const detail::Caller& caller, const Specialization& spec) {
    for (const auto& e : spec.map_entries) {
        caller.require(e.offset <= spec.data.size() && e.size <= spec.data.size() - e.offset,
                       "specialization constant ", e.constantID, " lies outside the data (", spec.data.size(),
                       " bytes)");
    }
}

VkSpecializationInfo specialization_info(Span<const VkSpecializationMapEntry> entries, Span<const std::byte> data) {
    return {static_cast<std::uint32_t>(entries.size()), entries.data(), data.size(), data.data()};
}

constexpr VkShaderStageFlags tessellation_stages =
    VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT | VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT;
// The primitive shading stages a mesh pipeline replaces (VUID-VkGraphicsPipelineCreateInfo-pStages-02095).
constexpr VkShaderStageFlags vertex_pipeline_stages =
    VK_SHADER_STAGE_VERTEX_BIT | tessellation_stages | VK_SHADER_STAGE_GEOMETRY_BIT;

bool contains(Span<const VkDynamicState> states, VkDynamicState state) {
    return std::find(states.begin(), states.end(), state) != states.end();
}

VkBool32 vk_bool(bool b) { return b ? VK_TRUE : VK_FALSE; }

// build() and the private members it calls (declared in the public header,
// which does not know detail::Caller) refuse as one function.
constexpr detail::Caller build_caller{"vkrc::GraphicsPipelineBuilder::build"};

// The state of a new pipeline of layout, its handle made by create
// (vkCreateGraphicsPipelines or vkCreateComputePipelines; call names it) from ci.
template <auto create, class CreateInfo>
detail::Ref<detail::PipelineState> created_pipeline(const PipelineLayout& layout, VkPipelineBindPoint bind_point,
                                                    const PipelineCache& cache, const CreateInfo& ci,
                                                    const char* call) {
    const auto& d = layout.device();
    detail::Ref<detail::PipelineState> s(new detail::PipelineState);
    s->layout = layout;
    s->bind_point = bind_point;
    check((d.fn().*create)(d.vk(), cache ? cache.vk() : VK_NULL_HANDLE, 1, &ci, nullptr, &s->handle), call);
    return s;
}

}  // namespace

ComputePipeline ComputePipeline::create(const PipelineLayout& layout, const ComputePipelineCreateInfo& info) {
    const detail::Caller caller{"vkrc::ComputePipeline::create"};
    caller.require_handle(layout, "the PipelineLayout");
    caller.require_handle(info.module, "the ShaderModule");
    caller.require(info.module.device() == layout.device(),
                   "the ShaderModule belongs to another device than the pipeline layout");
    check_specialization(caller, info.specialization);
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
    return ComputePipeline(created_pipeline<&DeviceFunctions::vkCreateComputePipelines>(
        layout, VK_PIPELINE_BIND_POINT_COMPUTE, info.cache, ci, "vkCreateComputePipelines"));
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
GraphicsPipelineBuilder& GraphicsPipelineBuilder::specialization(VkShaderStageFlagBits stage,
                                                                 const Specialization& spec) {
    check_specialization(detail::Caller{"vkrc::GraphicsPipelineBuilder::specialization"}, spec);
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

List<VkPipelineShaderStageCreateInfo> GraphicsPipelineBuilder::shader_stages() const {
    List<VkPipelineShaderStageCreateInfo> stages;
    for (const auto& st : stages_) {
        build_caller.require_handle(st.module, "a ShaderModule");
        VkPipelineShaderStageCreateInfo si{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        si.stage = st.stage;
        si.module = st.module.vk();
        si.pName = st.entry_point;
        stages.push_back(si);
    }
    return stages;
}

void GraphicsPipelineBuilder::attach_specializations(Span<VkPipelineShaderStageCreateInfo> stages,
                                                     Span<VkSpecializationInfo> infos) const {
    for (const auto& sp : specializations_) {
        auto it = std::find_if(stages.begin(), stages.end(), [&](const auto& st) { return st.stage == sp.stage; });
        build_caller.require(it != stages.end(), "a specialization names a stage without a shader");
        auto& info = infos[static_cast<std::size_t>(it - stages.begin())];
        info = specialization_info(sp.entries, sp.data);
        it->pSpecializationInfo = &info;
    }
}

void GraphicsPipelineBuilder::check_tessellation() const {
    bool tessellated = false;
    for (const auto& st : stages_) tessellated |= (st.stage & tessellation_stages) != 0;
    build_caller.require(!tessellated || patch_control_points_ > 0, "tessellation shaders without tessellation()");
    build_caller.require(!tessellated || topology_ == VK_PRIMITIVE_TOPOLOGY_PATCH_LIST,
                         "tessellation shaders need topology PATCH_LIST");
}

bool GraphicsPipelineBuilder::check_mesh_stages() const {
    VkShaderStageFlags present = 0;
    for (const auto& st : stages_) present |= st.stage;
    const bool mesh = (present & VK_SHADER_STAGE_MESH_BIT_EXT) != 0;
    // VUID-VkGraphicsPipelineCreateInfo-stage-02096: a task stage only feeds a mesh stage.
    build_caller.require(mesh || (present & VK_SHADER_STAGE_TASK_BIT_EXT) == 0, "a task shader without a mesh shader");
    if (!mesh) return false;
    build_caller.require((present & vertex_pipeline_stages) == 0,
                         "a mesh shader with vertex, tessellation or geometry shaders (stage flags ",
                         detail::Hex{present & vertex_pipeline_stages}, "): a pipeline has one or the other");
    // Vulkan ignores vertex input with a mesh stage: refused rather than silently unused.
    build_caller.require(bindings_.empty() && attributes_.empty(), "vertex bindings or attributes (", bindings_.size(),
                         " and ", attributes_.size(), ") with a mesh shader, which has no vertex input");
    return true;
}

VkPipelineViewportStateCreateInfo GraphicsPipelineBuilder::viewport_state() const {
    build_caller.require(viewports_.empty() || scissors_.empty() || viewports_.size() == scissors_.size(),
                         "viewports and scissors differ in count");
    const auto count = static_cast<std::uint32_t>(std::max<std::size_t>({1, viewports_.size(), scissors_.size()}));
    VkPipelineViewportStateCreateInfo v{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    // With counts dynamic, Vulkan wants 0 here.
    const bool dynamic_viewports = contains(dynamic_states_, VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT);
    const bool dynamic_scissors = contains(dynamic_states_, VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT);
    // Static ones must be given: Vulkan would read them from a null pointer.
    build_caller.require(
        viewports_.size() > 0 || dynamic_viewports || contains(dynamic_states_, VK_DYNAMIC_STATE_VIEWPORT),
        "viewports are neither dynamic nor given with viewports()");
    build_caller.require(
        scissors_.size() > 0 || dynamic_scissors || contains(dynamic_states_, VK_DYNAMIC_STATE_SCISSOR),
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
    build_caller.require(!render_pass_ || view_mask_ == 0,
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
    build_caller.require(blends_.empty() || blends_.size() == color_count, "blend_attachments has ", blends_.size(),
                         " states for ", color_count, " colour attachments");
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

GraphicsPipeline GraphicsPipelineBuilder::build(const PipelineCache& cache) const {
    build_caller.require_handle(layout_, "the PipelineLayout");
    build_caller.require(!stages_.empty(), "no shader stages");
    auto stages = shader_stages();
    std::vector<VkSpecializationInfo> specs(stages_.size());
    attach_specializations(stages, specs);
    check_tessellation();
    const bool mesh = check_mesh_stages();
    const auto vertex = vertex_input_state();
    const auto assembly = input_assembly_state();
    VkPipelineTessellationStateCreateInfo tessellation{VK_STRUCTURE_TYPE_PIPELINE_TESSELLATION_STATE_CREATE_INFO};
    tessellation.patchControlPoints = patch_control_points_;
    const auto viewport = viewport_state();
    const auto raster = rasterization_state();
    const std::uint32_t sample_mask[2] = {static_cast<std::uint32_t>(multisample_.sample_mask),
                                          static_cast<std::uint32_t>(multisample_.sample_mask >> 32)};
    auto multisample = multisample_state();
    multisample.pSampleMask = sample_mask;
    const auto depth = depth_stencil_state();
    const std::uint32_t color_count = render_pass_ ? render_pass_.color_attachment_count(subpass_)
                                                   : static_cast<std::uint32_t>(color_formats_.size());
    const auto rendering = rendering_info();
    List<VkPipelineColorBlendAttachmentState> blends;
    const auto blend = color_blend_state(color_count, blends);
    const auto dynamic = dynamic_state_info();

    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.pNext = render_pass_ ? next_ : &rendering;
    ci.flags = flags_;
    ci.pTessellationState = patch_control_points_ ? &tessellation : nullptr;
    ci.stageCount = static_cast<std::uint32_t>(stages.size());
    ci.pStages = stages.data();
    // A mesh pipeline makes its own primitives: no vertex input, no input assembly.
    ci.pVertexInputState = mesh ? nullptr : &vertex;
    ci.pInputAssemblyState = mesh ? nullptr : &assembly;
    ci.pViewportState = &viewport;
    ci.pRasterizationState = &raster;
    ci.pMultisampleState = &multisample;
    ci.pDepthStencilState = &depth;
    ci.pColorBlendState = &blend;
    ci.pDynamicState = &dynamic;
    ci.layout = layout_.vk();
    ci.renderPass = render_pass_ ? render_pass_.vk() : VK_NULL_HANDLE;
    ci.subpass = subpass_;
    return GraphicsPipeline(created_pipeline<&DeviceFunctions::vkCreateGraphicsPipelines>(
        layout_, VK_PIPELINE_BIND_POINT_GRAPHICS, cache, ci, "vkCreateGraphicsPipelines"));
}

VKRC_END_NAMESPACE
