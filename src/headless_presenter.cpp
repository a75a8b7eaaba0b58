// HeadlessPresenter: the Presenter for machines without a display.
#include "vkrc/swapchain.hpp"
#include "vkrc/upload.hpp"

#include "caller.hpp"

#include <atomic>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

detail::Ref<detail::FrameImages> make_ring(const detail::HeadlessPresenterState& s, VkExtent2D extent) {
    ImageCreateInfo info;
    info.format = s.info.format;
    info.extent = {extent.width, extent.height, 1};
    info.usage = s.info.image_usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    detail::Ref<detail::FrameImages> ring(new detail::FrameImages);
    ring->extent = extent;
    ring->images.reserve(s.info.image_count);
    ring->views.reserve(s.info.image_count);
    for (std::uint32_t i = 0; i < s.info.image_count; ++i) {
        ring->images.push_back(Image::create(s.queue.device(), info));
        ring->views.push_back(ImageView::create(ring->images.back()));
    }
    return ring;
}

}  // namespace

HeadlessPresenter HeadlessPresenter::create(const Queue& queue, const HeadlessPresenterCreateInfo& info) {
    const detail::Caller caller{"vkrc::HeadlessPresenter::create"};
    caller.require(static_cast<bool>(queue), "the Queue is empty");
    caller.require(info.extent.width != 0 && info.extent.height != 0, "extent is zero");
    caller.require(info.image_count != 0, "image_count is 0");
    detail::Ref<detail::HeadlessPresenterState> state(new detail::HeadlessPresenterState);
    state->queue = queue;
    state->info = info;
    state->ring = make_ring(*state, info.extent);
    return HeadlessPresenter(std::move(state));
}

// The new ring is made outside the spin lock, which acquire holds.
bool HeadlessPresenter::apply_resize(detail::HeadlessPresenterState& s) {
    LockGuard resizing(s.resize_mutex);
    if (!s.needs_resize.load(std::memory_order_acquire)) return true;  // another thread did it
    const VkExtent2D extent = s.info.extent;
    if (extent.width == 0 || extent.height == 0) return false;
    detail::Ref<detail::FrameImages> ring = make_ring(s, extent);
    {
        LockGuard lock(s.lock);
        std::swap(s.ring, ring);
    }
    s.needs_resize.store(false, std::memory_order_release);
    return true;  // the old ring goes with ring, outside the spin lock
}

PresentStatus HeadlessPresenter::refill(Frame& frame, detail::HeadlessPresenterState& s, std::uint32_t index) noexcept {
    frame.hold(s.ring);
    frame.format = s.info.format;
    frame.present_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    frame.sync_count_ = 0;
    frame.chain_ = nullptr;
    frame.source_ = &s;
    frame.point_at(*s.ring, index);
    frame.status = PresentStatus::success;
    return PresentStatus::success;
}

void HeadlessPresenter::refuse_present() {
    detail::Caller("vkrc::HeadlessPresenter::present").refuse("the frame was not acquired from this presenter");
}

List<std::byte> HeadlessPresenter::read_back(std::uint32_t image_index) const {
    auto& s = *state_;
    detail::Ref<detail::FrameImages> ring;
    {
        LockGuard lock(s.lock);
        ring = s.ring;
    }
    detail::Caller("vkrc::HeadlessPresenter::read_back")
        .require(image_index < ring->images.size(), "image ", image_index, " does not exist (the ring has ",
                 ring->images.size(), ")");
    const Image& image = ring->images[image_index];
    detail::await(s.queue, detail::last_submitted(s.queue));
    return download_image(s.queue, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

void HeadlessPresenter::resize(VkExtent2D extent) {
    auto& s = *state_;
    LockGuard resizing(s.resize_mutex);
    s.info.extent = extent;
    s.needs_resize.store(true, std::memory_order_release);
}

VkExtent2D HeadlessPresenter::extent() const noexcept { return state_->info.extent; }
VkFormat HeadlessPresenter::format() const noexcept { return state_->info.format; }
std::uint32_t HeadlessPresenter::image_count() const noexcept { return state_->info.image_count; }
std::uint32_t HeadlessPresenter::last_presented() const noexcept {
    return state_->last_presented.load(std::memory_order_relaxed);
}

VKRC_END_NAMESPACE
