// Typed submission: semaphores to wait on and signal, batches, vkrc::submit.
#pragma once

#include "vkrc/command.hpp"

#include <span>

VKRC_BEGIN_NAMESPACE

// A semaphore to wait on or signal in a submission (VkSemaphoreSubmitInfo);
// value is ignored for binary semaphores.
struct SemaphoreSubmit {
    SemaphoreSubmit() noexcept = default;
    SemaphoreSubmit(const Semaphore& s, std::uint64_t v = 0,
                    VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT) noexcept
        : semaphore(s.vk()), value(v), stage_mask(stages) {}
    VkSemaphore semaphore = VK_NULL_HANDLE;
    std::uint64_t value = 0;
    VkPipelineStageFlags2 stage_mask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
};

// One batch of a submission (VkSubmitInfo2).
struct SubmitBatch {
    std::span<const SemaphoreSubmit> waits{};
    std::span<const CommandBuffer> command_buffers{};
    std::span<const SemaphoreSubmit> signals{};
};

// Queue::submit with typed batches; the fence (if any) signals when all are
// done. The Vulkan structures are built on the stack up to 4 wait and 4
// signal semaphores and 8 command buffers per batch (4 batches), on the heap
// beyond.
void submit(const Queue& queue, std::span<const SubmitBatch> batches, const Fence& fence = {});
void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence = {});

VKRC_END_NAMESPACE
