#include "vkrc/swapchain.hpp"

#include "object_state.hpp"
#include "text.hpp"

#include <algorithm>
#include <atomic>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

// A Swapchain's hold on its surface: Vulkan allows one non-retired swapchain
// per surface (SurfaceState::taken and ::releasing, under its mutex).
struct SurfaceLease {
    // Marks the surface taken; waits once for a previous swapchain's
    // destruction still running, and throws UsageError when it stays.
    static void take(const detail::Caller& caller, const Surface& surface, const Device& device);
    // From ~SwapchainState: the surface is free again, or releasing until the
    // destruction of chain (the current Vulkan swapchain, if any) has run.
    static void give_back(detail::SurfaceState& surface, detail::SwapchainChainState* chain) noexcept;
    // From that last chain's destruction: the surface may be taken again.
    static void end_release(detail::SurfaceState& surface) noexcept;
};

void SurfaceLease::take(const detail::Caller& caller, const Surface& surface, const Device& device) {
    auto& state = *surface.state();
    for (bool waited = false;; waited = true) {
        {
            LockGuard lock(state.mutex);
            caller.require(!state.taken, "the surface already has a live Swapchain (re-create that one)");
            if (!state.releasing) {
                state.taken = true;
                return;
            }
        }
        caller.require(!waited,
                       "the surface's previous swapchain still exists (a Frame or Image holds one of its images, or "
                       "another device has not destroyed it)");
        // The previous Swapchain's Vulkan swapchain is not retired: its
        // destruction must run before a new one can be made for the surface.
        device.wait_idle();
    }
}

void SurfaceLease::give_back(detail::SurfaceState& surface, detail::SwapchainChainState* chain) noexcept {
    LockGuard lock(surface.mutex);
    surface.taken = false;
    if (chain) {
        chain->last = true;
        surface.releasing = true;
    }
}

void SurfaceLease::end_release(detail::SurfaceState& surface) noexcept {
    LockGuard lock(surface.mutex);
    surface.releasing = false;
}

// The deferred destruction of one Vulkan swapchain; context is its
// SurfaceState, whose reference it releases.
void destroy_swapchain(detail::DeviceState& d, std::uint64_t bits, void* context) noexcept {
    d.fn.vkDestroySwapchainKHR(d.device, detail::handle_from_bits<VkSwapchainKHR>(bits), nullptr);
    static_cast<detail::SurfaceState*>(context)->release();
}

void destroy_last_swapchain(detail::DeviceState& d, std::uint64_t bits, void* context) noexcept {
    d.fn.vkDestroySwapchainKHR(d.device, detail::handle_from_bits<VkSwapchainKHR>(bits), nullptr);
    auto* surface = static_cast<detail::SurfaceState*>(context);
    SurfaceLease::end_release(*surface);
    surface->release();
}

}  // namespace

namespace detail {

SwapchainChainState::~SwapchainChainState() {
    if (swapchain == VK_NULL_HANDLE) return;
    auto& device = *queue.device().state();
    if (presented) {
        // Without VK_EXT_swapchain_maintenance1 nothing says when a present
        // is done. An empty submission signalling the queue's timeline after
        // the last present puts a value after it in queue order;
        // destroy_after_gpu below waits for that value (docs/design.md,
        // Presentation).
        try {
            request_signal(queue);
            queue.submit({});
        } catch (...) {
            LockGuard lock(queue.mutex());
            device.fn.vkQueueWaitIdle(queue.vk());
        }
    }
    render_done.clear();  // queued before the swapchain, after the presents that wait on them
    // The action carries a reference to the surface (not a device ancestor,
    // so no cycle): the surface must outlive the swapchain's destruction.
    SurfaceState* s = surface.state();
    s->add_ref();
    device.destroy_after_gpu({last ? destroy_last_swapchain : destroy_swapchain, handle_bits(swapchain), s}, serial());
}

SwapchainState::~SwapchainState() {
    if (!surface) return;
    // Runs before the chain member is released (after this body).
    SurfaceLease::give_back(*surface.state(), chain.get());
}

}  // namespace detail

namespace {

std::string format_name(VkFormat format) {
    switch (format) {
        case VK_FORMAT_B8G8R8A8_SRGB: return "B8G8R8A8_SRGB";
        case VK_FORMAT_B8G8R8A8_UNORM: return "B8G8R8A8_UNORM";
        case VK_FORMAT_R8G8B8A8_SRGB: return "R8G8B8A8_SRGB";
        case VK_FORMAT_R8G8B8A8_UNORM: return "R8G8B8A8_UNORM";
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32: return "A2B10G10R10_UNORM_PACK32";
        default: return "VkFormat " + std::to_string(format);
    }
}

const char* present_mode_name(VkPresentModeKHR mode) {
    switch (mode) {
        case VK_PRESENT_MODE_IMMEDIATE_KHR: return "IMMEDIATE";
        case VK_PRESENT_MODE_MAILBOX_KHR: return "MAILBOX";
        case VK_PRESENT_MODE_FIFO_KHR: return "FIFO";
        case VK_PRESENT_MODE_FIFO_RELAXED_KHR: return "FIFO_RELAXED";
        default: return "other";
    }
}

void log(const detail::SwapchainState& s, const std::string& message) {
    if (s.info.log) s.info.log(("vkrc::Swapchain: " + message).c_str());
}

// A choice and why it was made, for the log.
template <class T>
struct Choice {
    T value;
    std::string reason;
};

// The first preferred format the surface supports, else the surface's first.
Choice<VkSurfaceFormatKHR> choose_format(Span<const VkSurfaceFormatKHR> formats,
                                         Span<const VkSurfaceFormatKHR> preferred) {
    if (formats.size() == 1 && formats[0].format == VK_FORMAT_UNDEFINED && !preferred.empty()) {
        return {preferred[0], "the surface accepts any format: the first preferred one"};
    }
    for (std::size_t i = 0; i < preferred.size(); ++i) {
        const auto& want = preferred[i];
        auto it = std::find_if(formats.begin(), formats.end(), [&](const VkSurfaceFormatKHR& f) {
            return f.format == want.format && f.colorSpace == want.colorSpace;
        });
        if (it != formats.end()) {
            return {*it, "preferred format " + std::to_string(i + 1) + " of " + std::to_string(preferred.size()) +
                             ", the first the surface supports"};
        }
    }
    return {formats[0], "no preferred format is supported: the surface's first"};
}

// requested if supported; IMMEDIATE and MAILBOX fall back to each other,
// everything at last to FIFO (which every surface supports).
VkPresentModeKHR choose_present_mode(Span<const VkPresentModeKHR> modes, VkPresentModeKHR requested) {
    std::vector<VkPresentModeKHR> order{requested};
    if (requested == VK_PRESENT_MODE_IMMEDIATE_KHR) order.push_back(VK_PRESENT_MODE_MAILBOX_KHR);
    if (requested == VK_PRESENT_MODE_MAILBOX_KHR) order.push_back(VK_PRESENT_MODE_IMMEDIATE_KHR);
    for (auto mode : order) {
        if (std::find(modes.begin(), modes.end(), mode) != modes.end()) return mode;
    }
    return VK_PRESENT_MODE_FIFO_KHR;
}

// The surface's extent, or (where it leaves that to the swapchain) the
// application's, clamped to the surface's limits.
Choice<VkExtent2D> choose_extent(const VkSurfaceCapabilitiesKHR& caps, VkExtent2D wanted) {
    if (caps.currentExtent.width != UINT32_MAX) return {caps.currentExtent, "the surface's current extent"};
    return {{std::clamp(wanted.width, caps.minImageExtent.width, caps.maxImageExtent.width),
             std::clamp(wanted.height, caps.minImageExtent.height, caps.maxImageExtent.height)},
            "the application's extent (the surface leaves it to the swapchain), clamped to its limits"};
}

std::uint32_t choose_image_count(const VkSurfaceCapabilitiesKHR& caps, std::uint32_t wanted) {
    std::uint32_t count = std::max(wanted, caps.minImageCount);
    return caps.maxImageCount != 0 ? std::min(count, caps.maxImageCount) : count;
}

// wanted if supported, else the lowest mode the surface supports.
VkCompositeAlphaFlagBitsKHR choose_composite_alpha(const VkSurfaceCapabilitiesKHR& caps,
                                                   VkCompositeAlphaFlagBitsKHR wanted) {
    if (caps.supportedCompositeAlpha & wanted) return wanted;
    for (std::uint32_t bit = 1; bit != 0 && bit <= caps.supportedCompositeAlpha; bit <<= 1) {
        if (caps.supportedCompositeAlpha & bit) return static_cast<VkCompositeAlphaFlagBitsKHR>(bit);
    }
    return wanted;
}

void log_format(const detail::SwapchainState& s, const std::string& reason) {
    const bool srgb = s.surface_format.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
    log(s, "format " + format_name(s.surface_format.format) + ", colour space " +
               (srgb ? std::string("SRGB_NONLINEAR") : std::to_string(s.surface_format.colorSpace)) + " (" + reason +
               ")");
}

void log_present_mode(const detail::SwapchainState& s) {
    const VkPresentModeKHR requested = s.info.present_mode;
    std::string message = std::string("present mode ") + present_mode_name(s.present_mode);
    if (s.present_mode == requested) {
        message += " (as requested)";
    } else {
        message += std::string(" (requested ") + present_mode_name(requested) +
                   ", which the surface does not support; the fallback order is IMMEDIATE/MAILBOX, the other, FIFO)";
    }
    log(s, message);
}

void log_images(const detail::SwapchainState& s, const VkSurfaceCapabilitiesKHR& caps, const std::string& extent_reason,
                bool replacing) {
    log(s, std::to_string(s.images->images.size()) + " images (asked for " + std::to_string(s.info.min_image_count) +
               ", the surface allows " + std::to_string(caps.minImageCount) + " to " +
               (caps.maxImageCount ? std::to_string(caps.maxImageCount) : std::string("any number")) + "), extent " +
               std::to_string(s.extent.width) + "x" + std::to_string(s.extent.height) + " (" + extent_reason + ")" +
               (replacing ? ", replacing the previous swapchain" : ""));
}

// Format, colour space and present mode: fixed for the swapchain's life,
// so that pipelines made for its format stay valid across re-creation.
void choose_format_and_mode(const detail::Caller& caller, detail::SwapchainState& s) {
    const auto& physical = s.queue.device().physical_device();
    auto formats = s.surface.formats(physical);
    caller.require(!formats.empty(), "the surface reports no formats");
    auto format = choose_format(formats, s.info.preferred_formats);
    s.surface_format = format.value;
    log_format(s, format.reason);
    s.present_mode = choose_present_mode(s.surface.present_modes(physical), s.info.present_mode);
    log_present_mode(s);
}

void check_usage_supported(const VkSurfaceCapabilitiesKHR& caps, VkImageUsageFlags usage) {
    // Reached from create, acquire and recreate alike.
    detail::Caller("vkrc::Swapchain")
        .require((caps.supportedUsageFlags & usage) == usage, "the surface does not support image_usage ",
                 detail::Hex{usage}, " (supported: ", detail::Hex{caps.supportedUsageFlags}, ")");
}

VkSwapchainCreateInfoKHR swapchain_create_info(const detail::SwapchainState& s, const VkSurfaceCapabilitiesKHR& caps,
                                               VkExtent2D extent) {
    VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    ci.pNext = s.info.next;
    ci.surface = s.surface.vk();
    ci.minImageCount = choose_image_count(caps, s.info.min_image_count);
    ci.imageFormat = s.surface_format.format;
    ci.imageColorSpace = s.surface_format.colorSpace;
    ci.imageExtent = extent;
    ci.imageArrayLayers = 1;
    ci.imageUsage = s.info.image_usage;
    ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ci.preTransform = caps.currentTransform;
    ci.compositeAlpha = choose_composite_alpha(caps, s.info.composite_alpha);
    ci.presentMode = s.present_mode;
    ci.clipped = s.info.clipped ? VK_TRUE : VK_FALSE;
    ci.oldSwapchain = s.chain ? s.chain->swapchain : VK_NULL_HANDLE;
    return ci;
}

// A new chain's images (borrowed, each keeping the chain alive) and views.
detail::Ref<detail::FrameImages> wrap_images(const detail::SwapchainState& s, detail::SwapchainChainState& chain,
                                             VkExtent2D extent) {
    const Device& device = s.queue.device();
    const auto raw = detail::enumerate<VkImage>(device.fn().vkGetSwapchainImagesKHR, "vkGetSwapchainImagesKHR",
                                                device.vk(), chain.swapchain);
    ImageCreateInfo info;
    info.format = s.surface_format.format;
    info.extent = {extent.width, extent.height, 1};
    info.usage = s.info.image_usage;
    detail::Ref<detail::FrameImages> out(new detail::FrameImages);
    out->extent = extent;
    for (VkImage image : raw) {
        auto wrapped = Image::adopt(device, image, info, Ownership::borrowed);
        wrapped.state()->owner = detail::Ref<detail::RefCounted>::share(&chain);
        out->views.push_back(ImageView::create(wrapped));
        out->images.push_back(std::move(wrapped));
        chain.render_done.push_back(Semaphore::create_binary(device));
    }
    return out;
}

// One acquire semaphore more than images, so that the next acquire
// normally finds its semaphore's last frame long finished.
void grow_acquire_ring(detail::SwapchainState& s, std::size_t image_count) {
    while (s.acquire_semaphores.size() < image_count + 1) {
        s.acquire_semaphores.push_back(Semaphore::create_binary(s.queue.device()));
        s.acquire_done_values.push_back(0);
    }
}

// After a failed creation: the old swapchain is retired even so; dropping
// it lets the next attempt start without an oldSwapchain.
void drop_chain(detail::SwapchainState& s) noexcept {
    s.images.reset();
    s.chain.reset();
    s.needs_recreate = true;
}

// Creates the next Vulkan swapchain, retiring the current one. Under s.mutex.
PresentStatus recreate_locked(detail::SwapchainState& s) {
    const Device& device = s.queue.device();
    const auto caps = s.surface.capabilities(device.physical_device());
    const auto extent = choose_extent(caps, s.info.extent);
    if (extent.value.width == 0 || extent.value.height == 0) {
        // A minimised window: no swapchain can have this extent. The current
        // one (if any) stays until the window has an area again.
        s.needs_recreate = true;
        return PresentStatus::zero_extent;
    }
    check_usage_supported(caps, s.info.image_usage);
    const VkSwapchainCreateInfoKHR ci = swapchain_create_info(s, caps, extent.value);
    detail::Ref<detail::SwapchainChainState> chain(new detail::SwapchainChainState);
    chain->queue = s.queue;
    chain->surface = s.surface;
    detail::Ref<detail::FrameImages> made;
    try {
        device.state()->check_result(device.fn().vkCreateSwapchainKHR(device.vk(), &ci, nullptr, &chain->swapchain),
                                     "vkCreateSwapchainKHR");
        made = wrap_images(s, *chain, extent.value);
        grow_acquire_ring(s, made->images.size());
    } catch (...) {
        drop_chain(s);
        throw;
    }
    // The old images and views go; the old swapchain follows once no frame
    // holds its images (its destruction then waits for the GPU).
    const bool replacing = static_cast<bool>(s.chain);
    s.images = std::move(made);
    s.chain = std::move(chain);
    s.extent = extent.value;
    s.needs_recreate = false;
    log_images(s, caps, extent.reason, replacing);
    return PresentStatus::success;
}

}  // namespace

Swapchain Swapchain::create(const Queue& queue, const Surface& surface) {
    return create(queue, surface, SwapchainCreateInfo{});
}

Swapchain Swapchain::create(const Queue& queue, const Surface& surface, const SwapchainCreateInfo& info) {
    const detail::Caller caller{"vkrc::Swapchain::create"};
    caller.require(static_cast<bool>(queue), "the Queue is empty");
    caller.require_handle(surface, "the Surface");
    const Device& device = queue.device();
    caller.require(device.extension_enabled(VK_KHR_SWAPCHAIN_EXTENSION_NAME),
                   "the device was created without VK_KHR_swapchain");
    VkBool32 supported = VK_FALSE;
    check(device.instance().fn().vkGetPhysicalDeviceSurfaceSupportKHR(device.physical_device().vk(),
                                                                      queue.family_index(), surface.vk(), &supported),
          "vkGetPhysicalDeviceSurfaceSupportKHR");
    caller.require(supported == VK_TRUE, "queue family ", queue.family_index(), " cannot present to the surface");
    detail::Ref<detail::SwapchainState> state(new detail::SwapchainState);
    SurfaceLease::take(caller, surface, device);
    state->surface = surface;  // from here the state's destructor gives the surface back
    state->queue = queue;
    state->info = info;
    choose_format_and_mode(caller, *state);
    recreate_locked(*state);
    return Swapchain(std::move(state));
}

PresentStatus Swapchain::acquire(Frame& frame) {
    auto& s = *state_;
    LockGuard lock(s.mutex);
    if (s.needs_recreate || !s.chain) {
        const PresentStatus status = recreate_locked(s);
        if (status != PresentStatus::success) {
            frame.clear(status);
            return status;
        }
    }
    const Device& device = s.queue.device();
    const std::uint32_t slot = s.next_acquire;
    // The semaphore must have no pending wait: its last frame was presented
    // after the submission that waited on it, at this queue value.
    detail::await(s.queue, s.acquire_done_values[slot]);
    std::uint32_t index = 0;
    VkResult r = device.fn().vkAcquireNextImageKHR(device.vk(), s.chain->swapchain, UINT64_MAX,
                                                   s.acquire_semaphores[slot].vk(), VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
        s.needs_recreate = true;
        frame.clear(PresentStatus::out_of_date);
        return frame.status;
    }
    device.state()->check_result(r, "vkAcquireNextImageKHR");
    if (r == VK_SUBOPTIMAL_KHR) s.needs_recreate = true;
    s.next_acquire = (slot + 1) % static_cast<std::uint32_t>(s.acquire_semaphores.size());
    if (frame.filled_from_ != s.images.get()) {
        frame.hold(s.images);
        frame.format = s.surface_format.format;
        frame.present_layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
        frame.source_ = nullptr;
    }
    frame.point_at(*s.images, index);
    frame.status = r == VK_SUBOPTIMAL_KHR ? PresentStatus::suboptimal : PresentStatus::success;
    frame.wait_ = SemaphoreSubmit(s.acquire_semaphores[slot], 0, Frame::acquire_stage);
    frame.signal_ = SemaphoreSubmit(s.chain->render_done[index], 0, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT);
    frame.sync_count_ = 1;
    frame.acquire_slot_ = slot;
    frame.chain_ = s.chain.get();
    return frame.status;
}

PresentStatus Swapchain::present(const Frame& frame) {
    auto& s = *state_;
    detail::Caller("vkrc::Swapchain::present")
        .require(frame && frame.chain_ && frame.chain_->surface.state() == s.surface.state(),
                 "the frame was not acquired from this swapchain");
    LockGuard lock(s.mutex);
    auto& chain = *frame.chain_;
    VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    info.waitSemaphoreCount = 1;
    info.pWaitSemaphores = &frame.signal_.semaphore;
    info.swapchainCount = 1;
    info.pSwapchains = &chain.swapchain;
    info.pImageIndices = &frame.image_index;
    const Device& device = s.queue.device();
    VkResult r;
    {
        LockGuard queue_lock(s.queue.mutex());
        r = device.fn().vkQueuePresentKHR(s.queue.vk(), &info);
    }
    // Even out of date, the present waits on its semaphore (queued as usual).
    chain.presented = true;
    // The slot's reuse waits for this submission number: in a frame loop the
    // frame's fence has usually shown it complete by then.
    s.acquire_done_values[frame.acquire_slot_] = detail::last_submitted(s.queue);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
        s.needs_recreate = true;
        return PresentStatus::out_of_date;
    }
    device.state()->check_result(r, "vkQueuePresentKHR");
    if (r == VK_SUBOPTIMAL_KHR) {
        s.needs_recreate = true;
        return PresentStatus::suboptimal;
    }
    return PresentStatus::success;
}

PresentStatus Swapchain::recreate() {
    auto& s = *state_;
    LockGuard lock(s.mutex);
    return recreate_locked(s);
}

void Swapchain::set_extent(VkExtent2D extent) {
    auto& s = *state_;
    LockGuard lock(s.mutex);
    s.info.extent = extent;
}

void Frame::hold(const detail::Ref<detail::FrameImages>& set) noexcept {
    if (set_.get() != set.get()) set_ = detail::Ref<detail::RefCounted>::share(set.get());
    filled_from_ = set.get();
}

VkExtent2D Swapchain::extent() const noexcept { return state_->extent; }
VkFormat Swapchain::format() const noexcept { return state_->surface_format.format; }
std::uint32_t Swapchain::image_count() const noexcept {
    return state_->images ? static_cast<std::uint32_t>(state_->images->images.size()) : 0;
}
VkSwapchainKHR Swapchain::vk() const noexcept { return state_->chain ? state_->chain->swapchain : VK_NULL_HANDLE; }
const Surface& Swapchain::surface() const noexcept { return state_->surface; }
const Queue& Swapchain::queue() const noexcept { return state_->queue; }
VkColorSpaceKHR Swapchain::color_space() const noexcept { return state_->surface_format.colorSpace; }
VkPresentModeKHR Swapchain::present_mode() const noexcept { return state_->present_mode; }

VKRC_END_NAMESPACE
