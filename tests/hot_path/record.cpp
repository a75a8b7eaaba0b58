// Recording functions compiled with -O2 for check_assembly.cmake: each must be
// exactly one indirect call through the device table, with no atomic
// instruction, no lock and no other call.
#include <vkrc/command.hpp>

#include <span>

void hot_draw(const vkrc::CommandBuffer& cmd) { cmd.draw(3); }
void hot_draw_indexed(const vkrc::CommandBuffer& cmd) { cmd.draw_indexed(36, 1, 0, 0, 0); }
void hot_bind_pipeline(const vkrc::CommandBuffer& cmd, const vkrc::Pipeline& p) { cmd.bind_pipeline(p); }
void hot_bind_set(const vkrc::CommandBuffer& cmd, const vkrc::Pipeline& p, const vkrc::DescriptorSet& s) {
    cmd.bind_descriptor_set(p, 0, s);
}
void hot_bind_vertex_buffer(const vkrc::CommandBuffer& cmd, const vkrc::Buffer& b) { cmd.bind_vertex_buffer(0, b); }
void hot_push(const vkrc::CommandBuffer& cmd, const vkrc::PipelineLayout& l, const float (&m)[16]) {
    cmd.push_constants(l, VK_SHADER_STAGE_VERTEX_BIT, m);
}
void hot_dispatch(const vkrc::CommandBuffer& cmd) { cmd.dispatch(8, 8, 1); }

// Issue 14's commands.
using Cmd = vkrc::CommandBuffer;
void hot_blit(const Cmd& c, const vkrc::Image& a, const vkrc::Image& b, std::span<const VkImageBlit> r) {
    c.blit_image(a, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, r);
}
void hot_resolve(const Cmd& c, const vkrc::Image& a, const vkrc::Image& b, std::span<const VkImageResolve> r) {
    c.resolve_image(a, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, r);
}
void hot_copy_image(const Cmd& c, const vkrc::Image& a, const vkrc::Image& b, std::span<const VkImageCopy> r) {
    c.copy_image(a, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, r);
}
void hot_clear_color(const Cmd& c, const vkrc::Image& i, const VkClearColorValue& v,
                     std::span<const VkImageSubresourceRange> r) {
    c.clear_color_image(i, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, v, r);
}
void hot_clear_depth(const Cmd& c, const vkrc::Image& i, const VkClearDepthStencilValue& v,
                     std::span<const VkImageSubresourceRange> r) {
    c.clear_depth_stencil_image(i, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, v, r);
}
void hot_clear_attachments(const Cmd& c, std::span<const VkClearAttachment> a, std::span<const VkClearRect> r) {
    c.clear_attachments(a, r);
}
void hot_update_buffer(const Cmd& c, const vkrc::Buffer& b, const std::uint32_t (&d)[4]) {
    c.update_buffer(b, 0, sizeof d, d);
}
void hot_draw_indirect(const Cmd& c, const vkrc::Buffer& b) { c.draw_indirect(b, 0, 4); }
void hot_draw_indexed_indirect(const Cmd& c, const vkrc::Buffer& b) { c.draw_indexed_indirect(b, 0, 4); }
void hot_dispatch_indirect(const Cmd& c, const vkrc::Buffer& b) { c.dispatch_indirect(b); }
void hot_draw_indirect_count(const Cmd& c, const vkrc::Buffer& b, const vkrc::Buffer& n) {
    c.draw_indirect_count(b, 0, n, 0, 16);
}
void hot_draw_indexed_indirect_count(const Cmd& c, const vkrc::Buffer& b, const vkrc::Buffer& n) {
    c.draw_indexed_indirect_count(b, 0, n, 0, 16);
}
void hot_begin_query(const Cmd& c, const vkrc::QueryPool& q) { c.begin_query(q, 0); }
void hot_end_query(const Cmd& c, const vkrc::QueryPool& q) { c.end_query(q, 0); }
void hot_copy_query_results(const Cmd& c, const vkrc::QueryPool& q, const vkrc::Buffer& b) {
    c.copy_query_results(q, 0, 2, b, 0, 8);
}
// Issue 31's acceleration structure commands.
void hot_build_acceleration_structures(const Cmd& c, std::span<const VkAccelerationStructureBuildGeometryInfoKHR> i,
                                       const VkAccelerationStructureBuildRangeInfoKHR* const* r) {
    c.build_acceleration_structures(i, r);
}
void hot_copy_acceleration_structure(const Cmd& c, VkAccelerationStructureKHR a, VkAccelerationStructureKHR b) {
    c.copy_acceleration_structure(a, b, VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
}
void hot_write_acceleration_structures_properties(const Cmd& c, std::span<const VkAccelerationStructureKHR> a,
                                                  const vkrc::QueryPool& q) {
    c.write_acceleration_structures_properties(a, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, q, 0);
}
void hot_begin_label(const Cmd& c) { c.begin_label("pass", {1.0f, 0.0f, 0.0f, 1.0f}); }
void hot_end_label(const Cmd& c) { c.end_label(); }
void hot_insert_label(const Cmd& c) { c.insert_label("marker"); }
void hot_set_viewports(const Cmd& c, std::span<const VkViewport> v) { c.set_viewports(0, v); }
void hot_set_scissors(const Cmd& c, std::span<const VkRect2D> s) { c.set_scissors(0, s); }
void hot_set_line_width(const Cmd& c) { c.set_line_width(1.0f); }
void hot_set_depth_bias(const Cmd& c) { c.set_depth_bias(1.0f, 0.0f, 2.0f); }
void hot_set_blend_constants(const Cmd& c, const float (&k)[4]) { c.set_blend_constants(k); }
void hot_set_depth_bounds(const Cmd& c) { c.set_depth_bounds(0.0f, 1.0f); }
void hot_set_stencil_compare_mask(const Cmd& c) { c.set_stencil_compare_mask(VK_STENCIL_FACE_FRONT_AND_BACK, 0xff); }
void hot_set_stencil_write_mask(const Cmd& c) { c.set_stencil_write_mask(VK_STENCIL_FACE_FRONT_AND_BACK, 0xff); }
void hot_set_stencil_reference(const Cmd& c) { c.set_stencil_reference(VK_STENCIL_FACE_FRONT_AND_BACK, 1); }
void hot_set_cull_mode(const Cmd& c) { c.set_cull_mode(VK_CULL_MODE_NONE); }
void hot_set_front_face(const Cmd& c) { c.set_front_face(VK_FRONT_FACE_CLOCKWISE); }
void hot_set_primitive_topology(const Cmd& c) { c.set_primitive_topology(VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP); }
void hot_set_viewport_with_count(const Cmd& c, std::span<const VkViewport> v) { c.set_viewport_with_count(v); }
void hot_set_scissor_with_count(const Cmd& c, std::span<const VkRect2D> s) { c.set_scissor_with_count(s); }
void hot_bind_vertex_buffers2(const Cmd& c, std::span<const VkBuffer> b, std::span<const VkDeviceSize> o) {
    c.bind_vertex_buffers2(0, b, o);
}
void hot_set_depth_test_enable(const Cmd& c, bool e) { c.set_depth_test_enable(e); }
void hot_set_depth_write_enable(const Cmd& c, bool e) { c.set_depth_write_enable(e); }
void hot_set_depth_compare_op(const Cmd& c) { c.set_depth_compare_op(VK_COMPARE_OP_LESS_OR_EQUAL); }
void hot_set_depth_bounds_test_enable(const Cmd& c, bool e) { c.set_depth_bounds_test_enable(e); }
void hot_set_stencil_test_enable(const Cmd& c, bool e) { c.set_stencil_test_enable(e); }
void hot_set_stencil_op(const Cmd& c) {
    c.set_stencil_op(VK_STENCIL_FACE_FRONT_BIT, VK_STENCIL_OP_KEEP, VK_STENCIL_OP_REPLACE, VK_STENCIL_OP_KEEP,
                     VK_COMPARE_OP_ALWAYS);
}
void hot_set_rasterizer_discard_enable(const Cmd& c, bool e) { c.set_rasterizer_discard_enable(e); }
void hot_set_depth_bias_enable(const Cmd& c, bool e) { c.set_depth_bias_enable(e); }
void hot_set_primitive_restart_enable(const Cmd& c, bool e) { c.set_primitive_restart_enable(e); }
void hot_bind_raw_pipeline(const Cmd& c, VkPipeline p) { c.bind_pipeline(VK_PIPELINE_BIND_POINT_COMPUTE, p); }
void hot_bind_sets_by_layout(const Cmd& c, const vkrc::PipelineLayout& l, std::span<const VkDescriptorSet> s) {
    c.bind_descriptor_sets(VK_PIPELINE_BIND_POINT_COMPUTE, l, 0, s);
}
void hot_push_raw(const Cmd& c, VkPipelineLayout l, const float (&m)[4]) {
    c.push_constants(l, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof m, m);
}
void hot_push_descriptor_set(const Cmd& c, const vkrc::PipelineLayout& l, std::span<const VkWriteDescriptorSet> w) {
    c.push_descriptor_set(VK_PIPELINE_BIND_POINT_COMPUTE, l, 0, w);
}
void hot_push_descriptor_set_with_template(const Cmd& c, const vkrc::DescriptorUpdateTemplate& t, const void* d) {
    c.push_descriptor_set_with_template(t, d);
}
// Raw twins, for pipelines, layouts, templates and secondaries made by other code.
void hot_push_descriptor_set_raw(const Cmd& c, VkPipelineLayout l, std::span<const VkWriteDescriptorSet> w) {
    c.push_descriptor_set(VK_PIPELINE_BIND_POINT_COMPUTE, l, 0, w);
}
void hot_push_descriptor_set_with_template_raw(const Cmd& c, VkDescriptorUpdateTemplate t, VkPipelineLayout l,
                                               const void* d) {
    c.push_descriptor_set_with_template(t, l, 0, d);
}
void hot_execute_commands_raw(const Cmd& c, std::span<const VkCommandBuffer> s) { c.execute_commands(s); }
