#include "vkrc/submit.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE

void submit(const Queue& queue, std::span<const SubmitBatch> batches, const Fence& fence) {
    if (!queue) throw UsageError("vkrc::submit: the Queue is empty");
    VkSubmitInfo2 infos[SubmitLimits::batches];
    VkSemaphoreSubmitInfo waits[SubmitLimits::semaphores];
    VkSemaphoreSubmitInfo signals[SubmitLimits::semaphores];
    VkCommandBufferSubmitInfo cmds[SubmitLimits::command_buffers];
    std::size_t n_waits = 0, n_signals = 0, n_cmds = 0;
    if (batches.size() > SubmitLimits::batches) {
        throw UsageError("vkrc::submit: more than " + std::to_string(SubmitLimits::batches) + " batches");
    }
    auto semaphore_info = [](const SemaphoreSubmit& s) {
        VkSemaphoreSubmitInfo i{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        i.semaphore = s.semaphore;
        i.value = s.value;
        i.stageMask = s.stage_mask;
        return i;
    };
    for (std::size_t b = 0; b < batches.size(); ++b) {
        const auto& batch = batches[b];
        if (batch.waits.size() > SubmitLimits::semaphores - n_waits ||
            batch.signals.size() > SubmitLimits::semaphores - n_signals) {
            throw UsageError("vkrc::submit: more than " + std::to_string(SubmitLimits::semaphores) +
                             " wait or signal semaphores");
        }
        if (batch.command_buffers.size() > SubmitLimits::command_buffers - n_cmds) {
            throw UsageError("vkrc::submit: more than " + std::to_string(SubmitLimits::command_buffers) +
                             " command buffers");
        }
        VkSubmitInfo2& info = infos[b];
        info = VkSubmitInfo2{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        info.waitSemaphoreInfoCount = static_cast<std::uint32_t>(batch.waits.size());
        info.pWaitSemaphoreInfos = waits + n_waits;
        for (const auto& w : batch.waits) waits[n_waits++] = semaphore_info(w);
        info.signalSemaphoreInfoCount = static_cast<std::uint32_t>(batch.signals.size());
        info.pSignalSemaphoreInfos = signals + n_signals;
        for (const auto& s : batch.signals) signals[n_signals++] = semaphore_info(s);
        info.commandBufferInfoCount = static_cast<std::uint32_t>(batch.command_buffers.size());
        info.pCommandBufferInfos = cmds + n_cmds;
        for (const auto& c : batch.command_buffers) {
            if (!c) throw UsageError("vkrc::submit: a CommandBuffer handle is empty");
#if VKRC_RUNTIME_CHECKS
            if (!(c.pool().device() == queue.device())) {
                throw UsageError("vkrc::submit: a CommandBuffer belongs to another device than the queue");
            }
#endif
            cmds[n_cmds] = VkCommandBufferSubmitInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
            cmds[n_cmds++].commandBuffer = c.vk();
        }
    }
#if VKRC_RUNTIME_CHECKS
    if (fence && !(fence.device() == queue.device())) {
        throw UsageError("vkrc::submit: the Fence belongs to another device than the queue");
    }
#endif
    const std::uint64_t number =
        queue.submit(std::span<const VkSubmitInfo2>(infos, batches.size()), fence ? fence.vk() : VK_NULL_HANDLE);
    if (fence) {
        fence.state()->note_submitted(*queue.state(), number);
    }
    for (const auto& batch : batches) detail::close_submitted(batch.command_buffers);
}

void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence) {
    submit(queue, std::span<const SubmitBatch>(&batch, 1), fence);
}

VKRC_END_NAMESPACE
