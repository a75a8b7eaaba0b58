// Pipeline layouts, render passes, framebuffers, pipelines and pipeline caches.
#pragma once

#include "vkrc/descriptor.hpp"
#include "vkrc/shader.hpp"

#include "vkrc/detail/span.hpp"
#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class PipelineLayoutState;
class RenderPassState;
class FramebufferState;
class PipelineState;
class PipelineCacheState;
}  // namespace detail

// Mirrors VkPipelineLayoutCreateInfo.
struct PipelineLayoutCreateInfo {
    // Optional (empty: no sets). Read during create(); the PipelineLayout does not keep them.
    List<DescriptorSetLayout> set_layouts{};
    // Optional (empty: no push constants). Copied during create(): the
    // PipelineLayout keeps them for the checks of CommandBuffer::push_constants.
    List<VkPushConstantRange> push_constant_ranges{};
    // Optional (default none).
    VkPipelineLayoutCreateFlags flags = 0;
    // Optional pNext chain; read during create only.
    const void* next = nullptr;
};

class PipelineLayout : public DeviceChild<detail::PipelineLayoutState, VkPipelineLayout> {
public:
    PipelineLayout() noexcept = default;
    static PipelineLayout create(const Device& device, const PipelineLayoutCreateInfo& info);
    static PipelineLayout create(const Device& device);  // no sets, no push constants
    // Wraps one made elsewhere from device. With Ownership::owned vkrc destroys
    // it once the GPU is done; borrowed, its maker does (after vkrc's last use).
    // Its push constant ranges are not known, so push_constants into it is not
    // checked against them.
    static PipelineLayout adopt(const Device& device, VkPipelineLayout layout, Ownership ownership);

    VkPipelineLayout vk() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::PipelineLayout::vk");
        return handle_;
    }

private:
    explicit PipelineLayout(detail::Ref<detail::PipelineLayoutState> state) noexcept;
    // The state's handle, copied into the wrapper (as CommandBuffer's): a
    // push_constants per draw then reads it in one load, not two.
    VkPipelineLayout handle_ = VK_NULL_HANDLE;
};

// Mirrors VkSubpassDescription (graphics subpasses).
// Every list is optional (empty: none) and read during RenderPass::create().
struct SubpassDescription {
    List<VkAttachmentReference> input_attachments{};
    List<VkAttachmentReference> color_attachments{};
    List<VkAttachmentReference> resolve_attachments{};  // empty or one per colour attachment
    // attachment VK_ATTACHMENT_UNUSED (the default): no depth/stencil attachment.
    VkAttachmentReference depth_stencil_attachment{VK_ATTACHMENT_UNUSED, VK_IMAGE_LAYOUT_UNDEFINED};
    List<std::uint32_t> preserve_attachments{};
};

// Mirrors VkRenderPassCreateInfo.
// Read during create(); the RenderPass keeps only each subpass's colour count.
struct RenderPassCreateInfo {
    // Optional (empty: an attachment-less render pass).
    List<VkAttachmentDescription> attachments{};
    // Required: at least one.
    List<SubpassDescription> subpasses{};
    // Optional (empty: none).
    List<VkSubpassDependency> dependencies{};
    // Optional (default none).
    VkRenderPassCreateFlags flags = 0;
    // Optional pNext chain; read during create only.
    const void* next = nullptr;
};

class RenderPass : public DeviceChild<detail::RenderPassState, VkRenderPass> {
public:
    static RenderPass create(const Device& device, const RenderPassCreateInfo& info);
    // Wraps one made elsewhere from device; color_attachment_counts: each
    // subpass's (copied). Ownership as for PipelineLayout::adopt.
    static RenderPass adopt(const Device& device, VkRenderPass render_pass,
                            Span<const std::uint32_t> color_attachment_counts, Ownership ownership);
    std::uint32_t color_attachment_count(std::uint32_t subpass) const;

private:
    using DeviceChild::DeviceChild;
};

// Mirrors VkFramebufferCreateInfo.
struct FramebufferCreateInfo {
    // Required. The Framebuffer keeps it alive.
    RenderPass render_pass{};
    // Required: one per render-pass attachment (empty for an attachment-less
    // pass, or with IMAGELESS_BIT). The Framebuffer keeps them alive.
    List<ImageView> attachments{};
    // Required, non-zero.
    std::uint32_t width = 0;
    // Required, non-zero.
    std::uint32_t height = 0;
    // Optional (default 1), non-zero.
    std::uint32_t layers = 1;
    // Optional (default none).
    VkFramebufferCreateFlags flags = 0;
    // Optional pNext chain; read during create only.
    const void* next = nullptr;
};

// Keeps its render pass and attachments alive.
class Framebuffer : public VulkanObject<detail::FramebufferState, VkFramebuffer> {
public:
    static Framebuffer create(const Device& device, const FramebufferCreateInfo& info);
    // Wraps one made elsewhere for render_pass. Its attachments are not kept
    // alive: their maker keeps them until the framebuffer is gone. Ownership
    // as for PipelineLayout::adopt.
    static Framebuffer adopt(const RenderPass& render_pass, VkFramebuffer framebuffer, VkExtent2D extent,
                             Ownership ownership);
    VkExtent2D extent() const VKRC_UNCHECKED_NOEXCEPT;
    const RenderPass& render_pass() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using VulkanObject::VulkanObject;
};

// A driver's compiled-pipeline cache, persisted between runs.
class PipelineCache : public DeviceChild<detail::PipelineCacheState, VkPipelineCache> {
public:
    // An empty cache, or one primed with data from save().
    static PipelineCache create(const Device& device, Span<const std::byte> initial_data = {});
    // Primes the cache from a file written by save(). A missing, truncated,
    // corrupt or foreign (other driver/device) file is ignored with a warning
    // on stderr: the cache starts empty and loaded_from_file() is false.
    static PipelineCache load(const Device& device, const char* file);
    // Wraps one made elsewhere from device. With Ownership::owned vkrc destroys
    // it once the GPU is done; borrowed, its maker does (after vkrc's last use).
    static PipelineCache adopt(const Device& device, VkPipelineCache cache, Ownership ownership);

    bool loaded_from_file() const VKRC_UNCHECKED_NOEXCEPT;
    // vkGetPipelineCacheData.
    List<std::byte> data() const;
    // Writes data() to file (replacing it); throws std::system_error on I/O failure.
    void save(const char* file) const;

private:
    using DeviceChild::DeviceChild;
};

// Specialization constants of one shader stage (VkSpecializationInfo). The
// builder and ComputePipeline::create copy both spans: they need only live
// through the call. Each entry's offset + size must lie within data.
struct Specialization {
    Span<const VkSpecializationMapEntry> map_entries{};
    Span<const std::byte> data{};
};

// Mirrors VkComputePipelineCreateInfo and its one stage.
struct ComputePipelineCreateInfo {
    VkPipelineCreateFlags flags = 0;                   // optional (default none)
    ShaderModule module{};                             // required; kept alive by nothing after create
    const char* entry_point = "main";                  // read during create only
    Specialization specialization{};                   // optional
    VkPipelineShaderStageCreateFlags stage_flags = 0;  // optional (default none)
    PipelineCache cache{};                             // optional
    const void* stage_next = nullptr;                  // optional pNext of the stage; read during create only
    const void* next = nullptr;                        // optional pNext; read during create only
};

// A graphics or compute pipeline; keeps its layout alive.
class Pipeline : public VulkanObject<detail::PipelineState, VkPipeline> {
public:
    // Wraps a pipeline made elsewhere (any kind: graphics, compute, ray
    // tracing) with layout, so that it binds through vkrc. With
    // Ownership::owned vkrc destroys it once the GPU is done; borrowed, its
    // maker does (after vkrc's last use).
    static Pipeline adopt(const PipelineLayout& layout, VkPipeline pipeline, VkPipelineBindPoint bind_point,
                          Ownership ownership);
    VkPipelineBindPoint bind_point() const VKRC_UNCHECKED_NOEXCEPT;
    const PipelineLayout& layout() const VKRC_UNCHECKED_NOEXCEPT;

protected:
    using VulkanObject::VulkanObject;
};

class GraphicsPipeline : public Pipeline {
public:
private:
    friend class GraphicsPipelineBuilder;
    using Pipeline::Pipeline;
};

class ComputePipeline : public Pipeline {
public:
    static ComputePipeline create(const PipelineLayout& layout, const ShaderModule& module,
                                  const char* entry_point = "main", const PipelineCache& cache = {});
    static ComputePipeline create(const PipelineLayout& layout, const ComputePipelineCreateInfo& info);

private:
    using Pipeline::Pipeline;
};

// Mirrors VkPipelineRasterizationStateCreateInfo (defaults: the builder's).
struct RasterizationState {
    bool depth_clamp_enable = false;  // needs the depthClamp feature
    bool rasterizer_discard_enable = false;
    VkPolygonMode polygon_mode = VK_POLYGON_MODE_FILL;  // LINE and POINT need fillModeNonSolid
    VkCullModeFlags cull_mode = VK_CULL_MODE_BACK_BIT;
    VkFrontFace front_face = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    bool depth_bias_enable = false;
    float depth_bias_constant_factor = 0.0f;
    float depth_bias_clamp = 0.0f;  // non-zero needs depthBiasClamp
    float depth_bias_slope_factor = 0.0f;
    float line_width = 1.0f;     // other than 1 needs wideLines
    const void* next = nullptr;  // optional pNext; must live until build()
};

// Mirrors VkPipelineDepthStencilStateCreateInfo (defaults: the builder's).
struct DepthStencilState {
    VkPipelineDepthStencilStateCreateFlags flags = 0;
    bool depth_test_enable = true;
    bool depth_write_enable = true;
    VkCompareOp depth_compare_op = VK_COMPARE_OP_LESS;
    bool depth_bounds_test_enable = false;  // needs the depthBounds feature
    bool stencil_test_enable = false;
    // Per face; reference, compare_mask and write_mask are static unless made dynamic.
    VkStencilOpState front{};
    VkStencilOpState back{};
    float min_depth_bounds = 0.0f;
    float max_depth_bounds = 1.0f;
    const void* next = nullptr;  // optional pNext; must live until build()
};

// Mirrors VkPipelineMultisampleStateCreateInfo.
struct MultisampleState {
    VkSampleCountFlagBits rasterization_samples = VK_SAMPLE_COUNT_1_BIT;
    bool sample_shading_enable = false;  // needs sampleRateShading
    float min_sample_shading = 0.0f;
    std::uint64_t sample_mask = ~std::uint64_t{0};  // bit i: sample i (copied; up to 64 samples)
    bool alpha_to_coverage_enable = false;
    bool alpha_to_one_enable = false;  // needs alphaToOne
    const void* next = nullptr;        // optional pNext; must live until build()
};

// Builds a GraphicsPipeline. Defaults: triangle list, fill, back-face culling
// with counter-clockwise front faces, depth test and write with LESS (used
// when there is a depth attachment), no blending, one sample, and dynamic
// viewport and scissor (set them with CommandBuffer::set_viewport/set_scissor).
// Target either a render pass subpass or dynamic rendering formats.
class GraphicsPipelineBuilder {
public:
    explicit GraphicsPipelineBuilder(PipelineLayout layout);

    // Adds a stage (required: at least one). Keeps the module alive until the builder dies; entry_point
    // is kept as a pointer: it must outlive build(). TASK_BIT_EXT and MESH_BIT_EXT need the device's
    // taskShader and meshShader features (DeviceCreateInfo::mesh_shader_features; UsageError otherwise).
    // With a mesh stage the pipeline has no vertex input or input assembly (topology and
    // primitive_restart are unused), and build() refuses vertex, tessellation or geometry stages and
    // vertex bindings or attributes beside it, and a task stage without one.
    GraphicsPipelineBuilder& shader(VkShaderStageFlagBits stage, const ShaderModule& module,
                                    const char* entry_point = "main");
    // Adds a vertex buffer binding (default: none).
    GraphicsPipelineBuilder& vertex_binding(std::uint32_t binding, std::uint32_t stride,
                                            VkVertexInputRate input_rate = VK_VERTEX_INPUT_RATE_VERTEX);
    // Adds a vertex attribute (default: none).
    GraphicsPipelineBuilder& vertex_attribute(std::uint32_t location, std::uint32_t binding, VkFormat format,
                                              std::uint32_t offset);
    // Primitive topology (default: triangle list).
    GraphicsPipelineBuilder& topology(VkPrimitiveTopology topology) {
        topology_ = topology;
        return *this;
    }
    // Polygon mode (default: fill).
    GraphicsPipelineBuilder& polygon_mode(VkPolygonMode mode) {
        raster_.polygon_mode = mode;
        return *this;
    }
    // Cull mode (default: back faces).
    GraphicsPipelineBuilder& cull_mode(VkCullModeFlags mode) {
        raster_.cull_mode = mode;
        return *this;
    }
    // Front face winding (default: counter-clockwise).
    GraphicsPipelineBuilder& front_face(VkFrontFace face) {
        raster_.front_face = face;
        return *this;
    }
    // Depth test, write and compare op (default: test and write with LESS).
    GraphicsPipelineBuilder& depth_test(bool test, bool write = true, VkCompareOp compare = VK_COMPARE_OP_LESS);
    // The blend state of every colour attachment (default: no blending, all channels written).
    GraphicsPipelineBuilder& blend(const VkPipelineColorBlendAttachmentState& state) {
        blend_ = state;
        return *this;
    }
    // Rasterization samples (default: one).
    GraphicsPipelineBuilder& samples(VkSampleCountFlagBits samples) {
        multisample_.rasterization_samples = samples;
        return *this;
    }
    // Adds a dynamic state to viewport and scissor (the default set).
    GraphicsPipelineBuilder& dynamic_state(VkDynamicState state);
    // Targets a render pass subpass (default: none, dynamic rendering); wins over rendering().
    GraphicsPipelineBuilder& render_pass(const RenderPass& render_pass, std::uint32_t subpass = 0);
    // Dynamic rendering (Vulkan 1.3) instead of a render pass (default: no attachments). The formats
    // are copied: the span need not outlive the call.
    GraphicsPipelineBuilder& rendering(Span<const VkFormat> color_formats, VkFormat depth_format = VK_FORMAT_UNDEFINED,
                                       VkFormat stencil_format = VK_FORMAT_UNDEFINED);

    // Full state (issue 14). Each replaces what the narrower calls above set:
    // rasterization their polygon mode, cull mode and front face; depth_stencil
    // depth_test's; multisample samples'.
    GraphicsPipelineBuilder& rasterization(const RasterizationState& state) {
        raster_ = state;
        return *this;
    }
    // The whole depth and stencil state (default: DepthStencilState's defaults).
    GraphicsPipelineBuilder& depth_stencil(const DepthStencilState& state) {
        depth_stencil_ = state;
        return *this;
    }
    // The whole multisample state (default: one sample, no sample shading).
    GraphicsPipelineBuilder& multisample(const MultisampleState& state) {
        multisample_ = state;
        return *this;
    }
    // One blend state per colour attachment (build() checks the count);
    // replaces blend() for every attachment. Different states need independentBlend.
    GraphicsPipelineBuilder& blend_attachments(Span<const VkPipelineColorBlendAttachmentState> states);
    // The blend constants (default zero; copied), unless BLEND_CONSTANTS is dynamic.
    GraphicsPipelineBuilder& blend_constants(const float (&constants)[4]);
    // Enables the logic op (needs the logicOp feature) instead of blending.
    GraphicsPipelineBuilder& logic_op(VkLogicOp op);
    // Static viewports and scissors (copied). Their counts are the pipeline's
    // (more than one needs multiViewport); the values count only when
    // VIEWPORT / SCISSOR are not dynamic (see dynamic_states).
    GraphicsPipelineBuilder& viewports(Span<const VkViewport> viewports);
    GraphicsPipelineBuilder& scissors(Span<const VkRect2D> scissors);
    // Replaces the dynamic state list (viewport and scissor by default).
    // With VIEWPORT_WITH_COUNT / SCISSOR_WITH_COUNT the counts are dynamic too.
    GraphicsPipelineBuilder& dynamic_states(Span<const VkDynamicState> states);
    // Restarts strips and fans at the all-ones index value (default off).
    GraphicsPipelineBuilder& primitive_restart(bool enable) {
        primitive_restart_ = enable;
        return *this;
    }
    // Specialization constants of the shader at stage (added with shader();
    // build() throws UsageError when there is none). Copied.
    GraphicsPipelineBuilder& specialization(VkShaderStageFlagBits stage, const Specialization& spec);
    // Patch size, required with tessellation shaders (topology PATCH_LIST).
    GraphicsPipelineBuilder& tessellation(std::uint32_t patch_control_points) {
        patch_control_points_ = patch_control_points;
        return *this;
    }
    // Multiview mask for dynamic rendering (needs the multiview feature).
    GraphicsPipelineBuilder& view_mask(std::uint32_t mask) {
        view_mask_ = mask;
        return *this;
    }
    // VkGraphicsPipelineCreateInfo::flags (default none).
    GraphicsPipelineBuilder& flags(VkPipelineCreateFlags flags) {
        flags_ = flags;
        return *this;
    }
    // Chained into VkGraphicsPipelineCreateInfo (after vkrc's rendering info);
    // must live until build().
    GraphicsPipelineBuilder& next(const void* chain) {
        next_ = chain;
        return *this;
    }

    // vkCreateGraphicsPipelines with what was set, through cache if given
    // (UsageError for what the builder can check: an empty layout, no stage,
    // a blend count other than the colour attachments', a mesh stage beside
    // vertex stages or vertex input, a task stage without a mesh stage). It may build again.
    GraphicsPipeline build(const PipelineCache& cache = {}) const;

private:
    struct Stage {
        VkShaderStageFlagBits stage;
        ShaderModule module;
        const char* entry_point;
    };
    PipelineLayout layout_;
    List<Stage> stages_;
    List<VkVertexInputBindingDescription> bindings_;
    List<VkVertexInputAttributeDescription> attributes_;
    VkPrimitiveTopology topology_ = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineColorBlendAttachmentState blend_{
        VK_FALSE,
        VK_BLEND_FACTOR_ONE,
        VK_BLEND_FACTOR_ZERO,
        VK_BLEND_OP_ADD,
        VK_BLEND_FACTOR_ONE,
        VK_BLEND_FACTOR_ZERO,
        VK_BLEND_OP_ADD,
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT};
    List<VkDynamicState> dynamic_states_;  // viewport and scissor, from the constructor
    RenderPass render_pass_;
    std::uint32_t subpass_ = 0;
    List<VkFormat> color_formats_;
    VkFormat depth_format_ = VK_FORMAT_UNDEFINED;
    VkFormat stencil_format_ = VK_FORMAT_UNDEFINED;
    // Full state: the fields the members above do not hold.
    struct Specialized {
        VkShaderStageFlagBits stage;
        List<VkSpecializationMapEntry> entries;
        List<std::byte> data;
    };
    // The state structs also hold what polygon_mode(), cull_mode(), front_face(),
    // depth_test() and samples() set: one place per value.
    RasterizationState raster_{};
    DepthStencilState depth_stencil_{};
    MultisampleState multisample_{};
    List<VkPipelineColorBlendAttachmentState> blends_;  // empty: blend_ for each attachment
    float blend_constants_[4] = {};
    bool logic_op_enable_ = false;
    VkLogicOp logic_op_ = VK_LOGIC_OP_COPY;
    List<VkViewport> viewports_;  // empty: one, dynamic
    List<VkRect2D> scissors_;
    List<Specialized> specializations_;
    bool primitive_restart_ = false;
    std::uint32_t patch_control_points_ = 0;
    std::uint32_t view_mask_ = 0;
    VkPipelineCreateFlags flags_ = 0;
    const void* next_ = nullptr;
    // build()'s pieces (src/pipeline_state.cpp); the results point into *this.
    List<VkPipelineShaderStageCreateInfo> shader_stages() const;
    void attach_specializations(Span<VkPipelineShaderStageCreateInfo> stages, Span<VkSpecializationInfo> infos) const;
    void check_tessellation() const;
    // Whether there is a mesh stage; refuses what Vulkan forbids beside one (or a task stage without one).
    bool check_mesh_stages() const;
    VkPipelineViewportStateCreateInfo viewport_state() const;
    VkPipelineRasterizationStateCreateInfo rasterization_state() const;
    VkPipelineMultisampleStateCreateInfo multisample_state() const;
    VkPipelineDepthStencilStateCreateInfo depth_stencil_state() const;
    VkPipelineVertexInputStateCreateInfo vertex_input_state() const;
    VkPipelineInputAssemblyStateCreateInfo input_assembly_state() const;
    // Chained before next(); with a render pass it describes nothing.
    VkPipelineRenderingCreateInfo rendering_info() const;
    // attachments receives the per-attachment states the result points to.
    VkPipelineColorBlendStateCreateInfo color_blend_state(std::uint32_t color_count,
                                                          List<VkPipelineColorBlendAttachmentState>& attachments) const;
    VkPipelineDynamicStateCreateInfo dynamic_state_info() const;
};

namespace detail {

class PipelineLayoutState final : public DeviceChildState<VkPipelineLayout> {
public:
    static constexpr const char* type_name = "vkrc::PipelineLayout";
    ~PipelineLayoutState() override;
    // As created; unknown (not checked) for an adopted layout.
    List<VkPushConstantRange> push_constant_ranges;
    bool push_constant_ranges_known = false;
};

// CommandBuffer::push_constants' check (VKRC_RUNTIME_CHECKS): UsageError
// unless stages is not 0, offset and size are multiples of 4, size is not 0,
// every byte of [offset, offset + size) lies, for each stage of stages, in a
// range of layout with that stage (VUID-vkCmdPushConstants-offset-01795), and
// every range of layout holding one of those bytes has only stages of stages
// (VUID-vkCmdPushConstants-offset-01796).
void check_push_constants(const PipelineLayout& layout, VkShaderStageFlags stages, std::uint32_t offset,
                          std::uint32_t size);

class RenderPassState final : public DeviceChildState<VkRenderPass> {
public:
    static constexpr const char* type_name = "vkrc::RenderPass";
    ~RenderPassState() override;
    List<std::uint32_t> color_counts;  // per subpass
};

class FramebufferState final : public VulkanObjectState<VkFramebuffer> {
public:
    static constexpr const char* type_name = "vkrc::Framebuffer";
    ~FramebufferState() override;
    RenderPass render_pass;
    List<ImageView> attachments;
    VkExtent2D extent{};
};

class PipelineCacheState final : public DeviceChildState<VkPipelineCache> {
public:
    static constexpr const char* type_name = "vkrc::PipelineCache";
    ~PipelineCacheState() override;
    bool loaded_from_file = false;
};

// Not final: a ray tracing pipeline's state adds its groups (vkrc/ray_tracing.hpp).
class PipelineState : public VulkanObjectState<VkPipeline> {
public:
    static constexpr const char* type_name = "vkrc::Pipeline";
    ~PipelineState() override;
    PipelineLayout layout;
    VkPipelineBindPoint bind_point = VK_PIPELINE_BIND_POINT_GRAPHICS;
};

}  // namespace detail

// Pipeline's accessors stay inline: bind_descriptor_set records with them.
inline VkPipelineBindPoint Pipeline::bind_point() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Pipeline::bind_point").bind_point;
}
inline const PipelineLayout& Pipeline::layout() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Pipeline::layout").layout;
}

VKRC_END_NAMESPACE
