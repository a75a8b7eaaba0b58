// Query commands of CommandBuffer (vkrc/command.hpp): resets, timestamps,
// occlusion and pipeline-statistics queries, and copies of their results,
// into a QueryPool (vkrc/sync.hpp) or a raw VkQueryPool. A base of
// vkrc::CommandRecorder (so of CommandBuffer), included by vkrc/command.hpp;
// call them on a CommandBuffer, as cmd.write_timestamp(stage, pool, 0).
//
// Inline, each one call through the device function table, as every
// recording method.
#pragma once

#include "vkrc/handle.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {

// Self is the CommandRecorder: each method records through the table and the
// raw handle of Self::recording(*this, who), which checks it holds one.
template <class Self>
class QueryCommands {
public:
    void reset_query_pool(Raw<VkQueryPool> pool, std::uint32_t first_query,
                          std::uint32_t query_count) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::reset_query_pool");
        self.fn_->vkCmdResetQueryPool(self.cmd_, pool, first_query, query_count);
    }
    void write_timestamp(VkPipelineStageFlags2 stage, Raw<VkQueryPool> pool,
                         std::uint32_t query) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::write_timestamp");
        self.fn_->vkCmdWriteTimestamp2(self.cmd_, stage, pool, query);
    }
    // Occlusion and pipeline-statistics queries (reset them first, outside rendering).
    void begin_query(Raw<VkQueryPool> pool, std::uint32_t query,
                     VkQueryControlFlags flags = 0) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::begin_query");
        self.fn_->vkCmdBeginQuery(self.cmd_, pool, query, flags);
    }
    void end_query(Raw<VkQueryPool> pool, std::uint32_t query) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::end_query");
        self.fn_->vkCmdEndQuery(self.cmd_, pool, query);
    }
    // vkCmdCopyQueryPoolResults into dst (TRANSFER_DST usage) as 64-bit values.
    void copy_query_results(Raw<VkQueryPool> pool, std::uint32_t first_query, std::uint32_t query_count,
                            Raw<VkBuffer> dst, VkDeviceSize offset, VkDeviceSize stride,
                            VkQueryResultFlags flags = VK_QUERY_RESULT_WAIT_BIT) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::copy_query_results");
        self.fn_->vkCmdCopyQueryPoolResults(self.cmd_, pool, first_query, query_count, dst, offset, stride,
                                            flags | VK_QUERY_RESULT_64_BIT);
    }
};

}  // namespace detail

VKRC_END_NAMESPACE
