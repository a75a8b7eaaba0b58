// A buffer the GPU reads, filled once through a staging copy (vkrc::upload_buffer): how the
// examples load their meshes. Header-only: each example picks its vkrc policy.
#pragma once

#include <vkrc/upload.hpp>

#include <span>
#include <vector>

namespace vkrc_examples {

template <typename T>
vkrc::Buffer device_buffer(const vkrc::Queue& queue, const std::vector<T>& data, VkBufferUsageFlags usage) {
    auto buffer = vkrc::Buffer::create(
        queue.device(), {.size = data.size() * sizeof(T), .usage = usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT});
    vkrc::upload_buffer(queue, buffer, 0, std::as_bytes(std::span(data)));
    return buffer;
}

}  // namespace vkrc_examples
