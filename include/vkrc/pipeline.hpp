// Pipeline layouts, render passes, framebuffers, pipelines and pipeline caches.
#pragma once

#include "vkrc/descriptor.hpp"
#include "vkrc/shader.hpp"

#include <span>
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
    List<DescriptorSetLayout> set_layouts{};
    List<VkPushConstantRange> push_constant_ranges{};
};

class PipelineLayout : public Handle<detail::PipelineLayoutState> {
public:
    PipelineLayout() noexcept = default;
    static PipelineLayout create(const Device& device, const PipelineLayoutCreateInfo& info);
    static PipelineLayout create(const Device& device);  // no sets, no push constants
    VkPipelineLayout vk() const VKRC_UNCHECKED_NOEXCEPT;
    const Device& device() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using Handle::Handle;
};

// Mirrors VkSubpassDescription (graphics subpasses).
struct SubpassDescription {
    List<VkAttachmentReference> input_attachments{};
    List<VkAttachmentReference> color_attachments{};
    List<VkAttachmentReference> resolve_attachments{};  // empty or one per colour attachment
    // attachment VK_ATTACHMENT_UNUSED (the default): no depth/stencil attachment.
    VkAttachmentReference depth_stencil_attachment{VK_ATTACHMENT_UNUSED, VK_IMAGE_LAYOUT_UNDEFINED};
    List<std::uint32_t> preserve_attachments{};
};

// Mirrors VkRenderPassCreateInfo.
struct RenderPassCreateInfo {
    List<VkAttachmentDescription> attachments{};
    List<SubpassDescription> subpasses{};
    List<VkSubpassDependency> dependencies{};
};

class RenderPass : public Handle<detail::RenderPassState> {
public:
    RenderPass() noexcept = default;
    static RenderPass create(const Device& device, const RenderPassCreateInfo& info);
    VkRenderPass vk() const VKRC_UNCHECKED_NOEXCEPT;
    const Device& device() const VKRC_UNCHECKED_NOEXCEPT;
    std::uint32_t color_attachment_count(std::uint32_t subpass) const;

private:
    using Handle::Handle;
};

// Mirrors VkFramebufferCreateInfo.
struct FramebufferCreateInfo {
    RenderPass render_pass{};
    List<ImageView> attachments{};
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::uint32_t layers = 1;
};

// Keeps its render pass and attachments alive.
class Framebuffer : public Handle<detail::FramebufferState> {
public:
    Framebuffer() noexcept = default;
    static Framebuffer create(const Device& device, const FramebufferCreateInfo& info);
    VkFramebuffer vk() const VKRC_UNCHECKED_NOEXCEPT;
    VkExtent2D extent() const VKRC_UNCHECKED_NOEXCEPT;
    const RenderPass& render_pass() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using Handle::Handle;
};

// A driver's compiled-pipeline cache, persisted between runs.
class PipelineCache : public Handle<detail::PipelineCacheState> {
public:
    PipelineCache() noexcept = default;
    // An empty cache, or one primed with data from save().
    static PipelineCache create(const Device& device, std::span<const std::byte> initial_data = {});
    // Primes the cache from a file written by save(). A missing, truncated,
    // corrupt or foreign (other driver/device) file is ignored with a warning
    // on stderr: the cache starts empty and loaded_from_file() is false.
    static PipelineCache load(const Device& device, const char* file);

    VkPipelineCache vk() const VKRC_UNCHECKED_NOEXCEPT;
    bool loaded_from_file() const VKRC_UNCHECKED_NOEXCEPT;
    // vkGetPipelineCacheData.
    List<std::byte> data() const;
    // Writes data() to file (replacing it); throws std::system_error on I/O failure.
    void save(const char* file) const;

private:
    using Handle::Handle;
};

// A graphics or compute pipeline; keeps its layout alive.
class Pipeline : public Handle<detail::PipelineState> {
public:
    Pipeline() noexcept = default;
    VkPipeline vk() const VKRC_UNCHECKED_NOEXCEPT;
    VkPipelineBindPoint bind_point() const VKRC_UNCHECKED_NOEXCEPT;
    const PipelineLayout& layout() const VKRC_UNCHECKED_NOEXCEPT;

protected:
    using Handle::Handle;
};

class GraphicsPipeline : public Pipeline {
public:
    GraphicsPipeline() noexcept = default;

private:
    friend class GraphicsPipelineBuilder;
    using Pipeline::Pipeline;
};

class ComputePipeline : public Pipeline {
public:
    ComputePipeline() noexcept = default;
    static ComputePipeline create(const PipelineLayout& layout, const ShaderModule& module,
                                  const char* entry_point = "main", const PipelineCache& cache = {});

private:
    using Pipeline::Pipeline;
};

// Builds a GraphicsPipeline. Defaults: triangle list, fill, back-face culling
// with counter-clockwise front faces, depth test and write with LESS (used
// when there is a depth attachment), no blending, one sample, and dynamic
// viewport and scissor (set them with CommandBuffer::set_viewport/set_scissor).
// Target either a render pass subpass or dynamic rendering formats.
class GraphicsPipelineBuilder {
public:
    explicit GraphicsPipelineBuilder(PipelineLayout layout);

    GraphicsPipelineBuilder& shader(VkShaderStageFlagBits stage, const ShaderModule& module,
                                    const char* entry_point = "main");
    GraphicsPipelineBuilder& vertex_binding(std::uint32_t binding, std::uint32_t stride,
                                            VkVertexInputRate input_rate = VK_VERTEX_INPUT_RATE_VERTEX);
    GraphicsPipelineBuilder& vertex_attribute(std::uint32_t location, std::uint32_t binding, VkFormat format,
                                              std::uint32_t offset);
    GraphicsPipelineBuilder& topology(VkPrimitiveTopology topology);
    GraphicsPipelineBuilder& polygon_mode(VkPolygonMode mode);
    GraphicsPipelineBuilder& cull_mode(VkCullModeFlags mode);
    GraphicsPipelineBuilder& front_face(VkFrontFace face);
    GraphicsPipelineBuilder& depth_test(bool test, bool write = true, VkCompareOp compare = VK_COMPARE_OP_LESS);
    // The blend state of every colour attachment.
    GraphicsPipelineBuilder& blend(const VkPipelineColorBlendAttachmentState& state);
    GraphicsPipelineBuilder& samples(VkSampleCountFlagBits samples);
    // Adds to viewport and scissor.
    GraphicsPipelineBuilder& dynamic_state(VkDynamicState state);
    GraphicsPipelineBuilder& render_pass(const RenderPass& render_pass, std::uint32_t subpass = 0);
    // Dynamic rendering (Vulkan 1.3) instead of a render pass.
    GraphicsPipelineBuilder& rendering(std::span<const VkFormat> color_formats,
                                       VkFormat depth_format = VK_FORMAT_UNDEFINED,
                                       VkFormat stencil_format = VK_FORMAT_UNDEFINED);

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
    VkPolygonMode polygon_mode_ = VK_POLYGON_MODE_FILL;
    VkCullModeFlags cull_mode_ = VK_CULL_MODE_BACK_BIT;
    VkFrontFace front_face_ = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    bool depth_test_ = true;
    bool depth_write_ = true;
    VkCompareOp depth_compare_ = VK_COMPARE_OP_LESS;
    VkPipelineColorBlendAttachmentState blend_{
        VK_FALSE,
        VK_BLEND_FACTOR_ONE,
        VK_BLEND_FACTOR_ZERO,
        VK_BLEND_OP_ADD,
        VK_BLEND_FACTOR_ONE,
        VK_BLEND_FACTOR_ZERO,
        VK_BLEND_OP_ADD,
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT};
    VkSampleCountFlagBits samples_ = VK_SAMPLE_COUNT_1_BIT;
    List<VkDynamicState> dynamic_states_;  // viewport and scissor, from the constructor
    RenderPass render_pass_;
    std::uint32_t subpass_ = 0;
    List<VkFormat> color_formats_;
    VkFormat depth_format_ = VK_FORMAT_UNDEFINED;
    VkFormat stencil_format_ = VK_FORMAT_UNDEFINED;
};

namespace detail {

class PipelineLayoutState final : public RefCounted {
public:
    ~PipelineLayoutState() override;
    Device device;
    VkPipelineLayout layout = VK_NULL_HANDLE;
};

class RenderPassState final : public RefCounted {
public:
    ~RenderPassState() override;
    Device device;
    VkRenderPass render_pass = VK_NULL_HANDLE;
    List<std::uint32_t> color_counts;  // per subpass
};

class FramebufferState final : public RefCounted {
public:
    ~FramebufferState() override;
    RenderPass render_pass;
    List<ImageView> attachments;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    VkExtent2D extent{};
};

class PipelineCacheState final : public RefCounted {
public:
    ~PipelineCacheState() override;
    Device device;
    VkPipelineCache cache = VK_NULL_HANDLE;
    bool loaded_from_file = false;
};

class PipelineState final : public RefCounted {
public:
    ~PipelineState() override;
    PipelineLayout layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkPipelineBindPoint bind_point = VK_PIPELINE_BIND_POINT_GRAPHICS;
};

}  // namespace detail

inline VkPipelineLayout PipelineLayout::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::PipelineLayout::vk");
    return state_->layout;
}
inline const Device& PipelineLayout::device() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::PipelineLayout::device");
    return state_->device;
}
inline VkRenderPass RenderPass::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::RenderPass::vk");
    return state_->render_pass;
}
inline const Device& RenderPass::device() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::RenderPass::device");
    return state_->device;
}
inline VkFramebuffer Framebuffer::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Framebuffer::vk");
    return state_->framebuffer;
}
inline VkExtent2D Framebuffer::extent() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Framebuffer::extent");
    return state_->extent;
}
inline const RenderPass& Framebuffer::render_pass() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Framebuffer::render_pass");
    return state_->render_pass;
}
inline VkPipelineCache PipelineCache::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::PipelineCache::vk");
    return state_->cache;
}
inline bool PipelineCache::loaded_from_file() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::PipelineCache::loaded_from_file");
    return state_->loaded_from_file;
}
inline VkPipeline Pipeline::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Pipeline::vk");
    return state_->pipeline;
}
inline VkPipelineBindPoint Pipeline::bind_point() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Pipeline::bind_point");
    return state_->bind_point;
}
inline const PipelineLayout& Pipeline::layout() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Pipeline::layout");
    return state_->layout;
}

VKRC_END_NAMESPACE
