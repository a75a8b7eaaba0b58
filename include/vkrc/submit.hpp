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

// Limits of one submit() call, whose Vulkan structures are built on the stack.
struct SubmitLimits {
    static constexpr std::size_t batches = 16;
    static constexpr std::size_t semaphores = 32;        // waits and signals, each, over all batches
    static constexpr std::size_t command_buffers = 128;  // over all batches
};

// Queue::submit with typed batches; the fence (if any) signals when all are
// done. No heap allocation; throws UsageError beyond SubmitLimits.
void submit(const Queue& queue, std::span<const SubmitBatch> batches, const Fence& fence = {});
void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence = {});

VKRC_END_NAMESPACE
