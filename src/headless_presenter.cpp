// HeadlessPresenter: the Presenter for machines without a display.
#include "vkrc/swapchain.hpp"
#include "vkrc/upload.hpp"

#include <atomic>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

void make_ring(detail::HeadlessPresenterState& s) {
    ImageCreateInfo info;
    info.format = s.info.format;
    info.extent = {s.info.extent.width, s.info.extent.height, 1};
    info.usage = s.info.image_usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    std::vector<Image> images;
    std::vector<ImageView> views;
    for (std::uint32_t i = 0; i < s.info.image_count; ++i) {
        images.push_back(Image::create(s.queue.device(), info));
        views.push_back(ImageView::create(images.back()));
    }
    s.images = std::move(images);
    s.views = std::move(views);
    s.needs_resize = false;
}

}  // namespace

HeadlessPresenter HeadlessPresenter::create(const Queue& queue, const HeadlessPresenterCreateInfo& info) {
    if (!queue) throw UsageError("vkrc::HeadlessPresenter::create: the Queue is empty");
    if (info.extent.width == 0 || info.extent.height == 0) {
        throw UsageError("vkrc::HeadlessPresenter::create: extent is zero");
    }
    if (info.image_count == 0) throw UsageError("vkrc::HeadlessPresenter::create: image_count is 0");
    detail::Ref<detail::HeadlessPresenterState> state(new detail::HeadlessPresenterState);
    state->queue = queue;
    state->info = info;
    make_ring(*state);
    return HeadlessPresenter(std::move(state));
}

Frame HeadlessPresenter::acquire() {
    auto& s = *state_;
    LockGuard lock(s.mutex);
    Frame frame;
    if (s.needs_resize) {
        if (s.info.extent.width == 0 || s.info.extent.height == 0) {
            frame.status = PresentStatus::zero_extent;
            return frame;
        }
        make_ring(s);
    }
    const auto index = static_cast<std::uint32_t>(s.acquired++ % s.info.image_count);
    frame.status = PresentStatus::success;
    frame.image_index = index;
    frame.image = s.images[index];
    frame.view = s.views[index];
    frame.extent = s.info.extent;
    frame.format = s.info.format;
    frame.present_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    frame.source_ = &s;
    return frame;
}

PresentStatus HeadlessPresenter::present(const Frame& frame) {
    auto& s = *state_;
    if (!frame.image || frame.source_ != &s) {
        throw UsageError("vkrc::HeadlessPresenter::present: the frame was not acquired from this presenter");
    }
    s.last_presented.store(frame.image_index, std::memory_order_relaxed);
    return PresentStatus::success;
}

List<std::byte> HeadlessPresenter::read_back(std::uint32_t image_index) const {
    auto& s = *state_;
    Image image;
    {
        LockGuard lock(s.mutex);
        if (image_index >= s.images.size()) {
            throw UsageError("vkrc::HeadlessPresenter::read_back: image " + std::to_string(image_index) +
                             " does not exist (the ring has " + std::to_string(s.images.size()) + ")");
        }
        image = s.images[image_index];
    }
    s.queue.device().state()->await_submission(*s.queue.state(), s.queue.state()->timeline.last_submitted());
    return download_image(s.queue, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

void HeadlessPresenter::resize(VkExtent2D extent) {
    auto& s = *state_;
    LockGuard lock(s.mutex);
    s.info.extent = extent;
    s.needs_resize = true;
}

VkExtent2D HeadlessPresenter::extent() const noexcept { return state_->info.extent; }
VkFormat HeadlessPresenter::format() const noexcept { return state_->info.format; }
std::uint32_t HeadlessPresenter::image_count() const noexcept { return state_->info.image_count; }
std::uint32_t HeadlessPresenter::last_presented() const noexcept {
    return state_->last_presented.load(std::memory_order_relaxed);
}

VKRC_END_NAMESPACE
