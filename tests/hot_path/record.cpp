// Recording functions compiled with -O2 for check_assembly.cmake: each must be
// exactly one indirect call through the device table, with no atomic
// instruction, no lock and no other call.
#include <vkrc/command.hpp>

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
