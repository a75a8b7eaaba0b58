#include "vkrc/submit.hpp"

VKRC_BEGIN_NAMESPACE

namespace {

// What one batch of a frame loop needs fits on the stack; more goes to the heap.
constexpr std::size_t inline_semaphores = 4;
constexpr std::size_t inline_command_buffers = 8;
constexpr std::size_t inline_batches = 4;

// Fills info for batch, its semaphores and command buffers going to the
// given arrays, which have room for them. Inlined into the one-batch submit,
// the frame loop's.
[[gnu::always_inline]] inline void fill_batch(const Queue& queue, const SubmitBatch& batch, VkSubmitInfo2& info,
                                              VkSemaphoreSubmitInfo* waits, VkSemaphoreSubmitInfo* signals,
                                              VkCommandBufferSubmitInfo* cmds) {
    info = VkSubmitInfo2{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    info.waitSemaphoreInfoCount = static_cast<std::uint32_t>(batch.waits.size());
    info.pWaitSemaphoreInfos = waits;
    for (const auto& w : batch.waits) *waits++ = w.info();
    info.signalSemaphoreInfoCount = static_cast<std::uint32_t>(batch.signals.size());
    info.pSignalSemaphoreInfos = signals;
    for (const auto& s : batch.signals) *signals++ = s.info();
    info.commandBufferInfoCount = static_cast<std::uint32_t>(batch.command_buffers.size());
    info.pCommandBufferInfos = cmds;
    for (const auto& c : batch.command_buffers) {
        if (!c) [[unlikely]]
            throw UsageError("vkrc::submit: a CommandBuffer handle is empty");
#if VKRC_RUNTIME_CHECKS
        if (!(c.pool().device() == queue.device())) {
            throw UsageError("vkrc::submit: a CommandBuffer belongs to another device than the queue");
        }
#else
        (void)queue;
#endif
        *cmds = VkCommandBufferSubmitInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
        cmds++->commandBuffer = c.vk();
    }
}

[[gnu::always_inline]] inline void submit_infos(const Queue& queue, Span<const VkSubmitInfo2> infos,
                                                const Fence& fence) {
#if VKRC_RUNTIME_CHECKS
    if (fence && !(fence.device() == queue.device())) {
        throw UsageError("vkrc::submit: the Fence belongs to another device than the queue");
    }
#endif
    auto& q = *queue.state();
    detail::FenceState* f = fence.state();
    const std::uint64_t number = queue.device().state()->submit(q, infos, f ? f->handle : VK_NULL_HANDLE);
    if (f) f->note_submitted(q, number);
}

// An array of n elements: on the stack up to N, on the heap beyond.
template <class T, std::size_t N>
class Scratch {
public:
    explicit Scratch(std::size_t n) : data_(n <= N ? inline_ : (heap_.resize(n), heap_.data())) {}
    T* data() noexcept { return data_; }

private:
    T inline_[N];
    List<T> heap_;
    T* data_;
};

}  // namespace

void submit(const Queue& queue, Span<const SubmitBatch> batches, const Fence& fence) {
    if (!queue) throw UsageError("vkrc::submit: the Queue is empty");
    std::size_t n_waits = 0, n_signals = 0, n_cmds = 0;
    for (const auto& b : batches) {
        n_waits += b.waits.size();
        n_signals += b.signals.size();
        n_cmds += b.command_buffers.size();
    }
    Scratch<VkSubmitInfo2, inline_batches> infos(batches.size());
    Scratch<VkSemaphoreSubmitInfo, inline_semaphores> waits(n_waits);
    Scratch<VkSemaphoreSubmitInfo, inline_semaphores> signals(n_signals);
    Scratch<VkCommandBufferSubmitInfo, inline_command_buffers> cmds(n_cmds);
    std::size_t w = 0, s = 0, c = 0;
    for (std::size_t i = 0; i < batches.size(); ++i) {
        const SubmitBatch& b = batches[i];
        fill_batch(queue, b, infos.data()[i], waits.data() + w, signals.data() + s, cmds.data() + c);
        w += b.waits.size();
        s += b.signals.size();
        c += b.command_buffers.size();
    }
    submit_infos(queue, Span<const VkSubmitInfo2>(infos.data(), batches.size()), fence);
    for (const auto& batch : batches) detail::close_submitted(batch.command_buffers);
}

void submit(const Queue& queue, const SubmitBatch& batch, const Fence& fence) {
    if (batch.waits.size() > inline_semaphores || batch.signals.size() > inline_semaphores ||
        batch.command_buffers.size() > inline_command_buffers) [[unlikely]] {
        return submit(queue, Span<const SubmitBatch>(&batch, 1), fence);
    }
    if (!queue) throw UsageError("vkrc::submit: the Queue is empty");
    VkSubmitInfo2 info;
    VkSemaphoreSubmitInfo waits[inline_semaphores];
    VkSemaphoreSubmitInfo signals[inline_semaphores];
    VkCommandBufferSubmitInfo cmds[inline_command_buffers];
    fill_batch(queue, batch, info, waits, signals, cmds);
    submit_infos(queue, Span<const VkSubmitInfo2>(&info, 1), fence);
    detail::close_submitted(batch.command_buffers);
}

VKRC_END_NAMESPACE
