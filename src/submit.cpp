#include "vkrc/submit.hpp"

#include "caller.hpp"

VKRC_BEGIN_NAMESPACE

namespace {

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

void detail::refuse_submit(const char* what) { Caller("vkrc::submit").refuse(what); }

void detail::submit_large_batch(const Queue& queue, Span<const SemaphoreSubmit> waits,
                                Span<const CommandBuffer> command_buffers, Span<const SemaphoreSubmit> signals,
                                const Fence& fence) {
    const SubmitBatch batch{.waits = waits, .command_buffers = command_buffers, .signals = signals};
    submit(queue, Span<const SubmitBatch>(&batch, 1), fence);
}

void submit(const Queue& queue, Span<const SubmitBatch> batches, const Fence& fence) {
    if (!queue) detail::refuse_submit("the Queue is empty");
    std::size_t n_waits = 0, n_signals = 0, n_cmds = 0;
    for (const auto& b : batches) {
        n_waits += b.waits.size();
        n_signals += b.signals.size();
        n_cmds += b.command_buffers.size();
    }
    Scratch<VkSubmitInfo2, detail::inline_batches> infos(batches.size());
    Scratch<VkSemaphoreSubmitInfo, detail::inline_semaphores> waits(n_waits);
    Scratch<VkSemaphoreSubmitInfo, detail::inline_semaphores> signals(n_signals);
    Scratch<VkCommandBufferSubmitInfo, detail::inline_command_buffers> cmds(n_cmds);
    std::size_t w = 0, s = 0, c = 0;
    for (std::size_t i = 0; i < batches.size(); ++i) {
        const SubmitBatch& b = batches[i];
        detail::fill_batch(queue, b, infos.data()[i], waits.data() + w, signals.data() + s, cmds.data() + c);
        w += b.waits.size();
        s += b.signals.size();
        c += b.command_buffers.size();
    }
    detail::submit_infos(queue, Span<const VkSubmitInfo2>(infos.data(), batches.size()), fence);
    for (const auto& batch : batches) detail::close_submitted(batch.command_buffers);
}

VKRC_END_NAMESPACE
