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
// beyond.
void submit(const Queue& queue, Span<const SubmitBatch> batches, const Fence& fence = {});
void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence = {});

VKRC_END_NAMESPACE
