// Typed submission: semaphores to wait on and signal, batches, vkrc::submit.
#pragma once

#include "vkrc/command.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

// A semaphore to wait on or signal in a submission (VkSemaphoreSubmitInfo);
// value is ignored for binary semaphores.
struct SemaphoreSubmit {
    SemaphoreSubmit() noexcept = default;
    SemaphoreSubmit(const Semaphore& s, std::uint64_t v = 0,
                    VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT) noexcept
        : semaphore(s.vk()), value(v), stage_mask(stages) {}
    // Required. The Semaphore must be alive at submit(); dropping it later is deferred past the GPU's use.
    VkSemaphore semaphore = VK_NULL_HANDLE;
    // The timeline value to wait for or signal (default 0; binary: ignored).
    std::uint64_t value = 0;
    // Optional (default all commands).
    VkPipelineStageFlags2 stage_mask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;

    // The Vulkan structure (device index 0).
    VkSemaphoreSubmitInfo info() const noexcept {
        return {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                .pNext = nullptr,
                .semaphore = semaphore,
                .value = value,
                .stageMask = stage_mask,
                .deviceIndex = 0};
    }
};

// One batch of a submission (VkSubmitInfo2).
// Every span is optional (empty: none) and read during submit(); it need not outlive the call.
struct SubmitBatch {
    Span<const SemaphoreSubmit> waits{};
    // Their handles must not be empty; dropping them after submit() is deferred past the GPU's use.
    Span<const CommandBuffer> command_buffers{};
    Span<const SemaphoreSubmit> signals{};
};

// Queue::submit with typed batches; the fence (if any) signals when all are
// done. The Vulkan structures are built on the stack up to 4 wait and 4
// signal semaphores and 8 command buffers per batch (4 batches), on the heap
// beyond. The one-batch form is inline: a frame's submit reaches
// vkQueueSubmit2 without a call of its own.
void submit(const Queue& queue, Span<const SubmitBatch> batches, const Fence& fence = {});
void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence = {});

namespace detail {

// What one batch of a frame loop needs fits on the stack; more goes to the heap.
inline constexpr std::size_t inline_semaphores = 4;
inline constexpr std::size_t inline_command_buffers = 8;
inline constexpr std::size_t inline_batches = 4;

// Throws UsageError "vkrc::submit: what".
[[noreturn]] void refuse_submit(const char* what);
// The one-batch submit of a batch too large for the stack: the Span form.
// Its parts are passed by value, so the inline caller's batch need not be
// stored to memory for the case it does not take.
[[gnu::noinline]] void submit_large_batch(const Queue& queue, Span<const SemaphoreSubmit> waits,
                                          Span<const CommandBuffer> command_buffers,
                                          Span<const SemaphoreSubmit> signals, const Fence& fence);

// Fills info for batch, its semaphores and command buffers going to the
// given arrays, which have room for them.
[[gnu::always_inline]] inline void fill_batch(const Queue& queue, const SubmitBatch& batch, VkSubmitInfo2& info,
                                              VkSemaphoreSubmitInfo* waits, VkSemaphoreSubmitInfo* signals,
                                              VkCommandBufferSubmitInfo* cmds) {
    info = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2,
            .pNext = nullptr,
            .flags = 0,
            .waitSemaphoreInfoCount = static_cast<std::uint32_t>(batch.waits.size()),
            .pWaitSemaphoreInfos = waits,
            .commandBufferInfoCount = static_cast<std::uint32_t>(batch.command_buffers.size()),
            .pCommandBufferInfos = cmds,
            .signalSemaphoreInfoCount = static_cast<std::uint32_t>(batch.signals.size()),
            .pSignalSemaphoreInfos = signals};
    // By index, as close_submitted: GCC folds the loops of a frame's fixed counts.
    for (std::size_t i = 0; i < batch.waits.size(); ++i) waits[i] = batch.waits[i].info();
    for (std::size_t i = 0; i < batch.signals.size(); ++i) signals[i] = batch.signals[i].info();
    for (std::size_t i = 0; i < batch.command_buffers.size(); ++i) {
        const CommandBuffer& c = batch.command_buffers[i];
        if (!c) [[unlikely]]
            refuse_submit("a CommandBuffer handle is empty");
#if VKRC_RUNTIME_CHECKS
        if (!(c.pool().device() == queue.device()))
            refuse_submit("a CommandBuffer belongs to another device than the queue");
#else
        (void)queue;
#endif
        cmds[i] = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
                   .pNext = nullptr,
                   .commandBuffer = c.vk(),
                   .deviceMask = 0};
    }
}

// Submits infos on queue (DeviceState::submit), the fence noting the submission.
[[gnu::always_inline]] inline void submit_infos(const Queue& queue, Span<const VkSubmitInfo2> infos,
                                                const Fence& fence) {
#if VKRC_RUNTIME_CHECKS
    if (fence && !(fence.device() == queue.device()))
        refuse_submit("the Fence belongs to another device than the queue");
#endif
    FenceState* f = fence.state();
    queue.device().state()->submit(*queue.state(), infos, f ? f->handle : VK_NULL_HANDLE, f ? &f->submission : nullptr);
}

}  // namespace detail

[[gnu::always_inline]] inline void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence) {
    if (batch.waits.size() > detail::inline_semaphores || batch.signals.size() > detail::inline_semaphores ||
        batch.command_buffers.size() > detail::inline_command_buffers) [[unlikely]] {
        return detail::submit_large_batch(queue, batch.waits, batch.command_buffers, batch.signals, fence);
    }
    if (!queue) [[unlikely]]
        detail::refuse_submit("the Queue is empty");
    VkSubmitInfo2 info;
    VkSemaphoreSubmitInfo waits[detail::inline_semaphores];
    VkSemaphoreSubmitInfo signals[detail::inline_semaphores];
    VkCommandBufferSubmitInfo cmds[detail::inline_command_buffers];
    detail::fill_batch(queue, batch, info, waits, signals, cmds);
    detail::submit_infos(queue, Span<const VkSubmitInfo2>(&info, 1), fence);
    detail::close_submitted(batch.command_buffers);
}

VKRC_END_NAMESPACE
