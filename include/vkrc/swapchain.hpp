// Presentation: the Presenter interface, Swapchain (VK_KHR_swapchain) and
// HeadlessPresenter (a ring of offscreen images), so that one frame loop
// serves a window and a machine without a display:
//
//     vkrc::Frame frame;  // kept across frames: refilled by each acquire
//     ...
//     presenter.acquire(frame);
//     if (!frame) continue;  // minimised, or re-created next time: no image this time
//     ... record: barrier UNDEFINED -> attachment (src stage frame.acquire_stage),
//         render into frame.view() (frame.extent), barrier -> frame.present_layout
//     vkrc::submit(queue, {.waits = frame.waits(), .command_buffers = ...,
//                          .signals = frame.signals()}, fence);
//     presenter.present(frame);
//
// Every acquired frame must be submitted (waiting on frame.waits()) and
// presented: its semaphores are reused on that condition.
#pragma once

#include "vkrc/submit.hpp"
#include "vkrc/resource.hpp"
#include "vkrc/surface.hpp"
#include "vkrc/sync.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class SwapchainState;
class SwapchainChainState;
class HeadlessPresenterState;
class FrameImages;
}  // namespace detail

// What acquire() and present() report; none of them is an exception.
enum class PresentStatus : std::uint8_t {
    success,
    // The image is usable (acquire) or was presented (present), but no longer
    // matches the surface: the presenter re-creates its images before the
    // next acquire.
    suboptimal,
    // No image (acquire) / not presented (present): the surface changed. The
    // next acquire re-creates the images first.
    out_of_date,
    // The surface has no area (a minimised window): no image and nothing to
    // render. Acquire again later (after waiting for window events).
    zero_extent,
};

// One acquired image and what its submission waits on and signals. Keep one
// Frame across the frame loop and let acquire() refill it: it then holds the
// presenter's image set by one reference taken when the set changes (first
// acquire, re-creation), so a steady frame loop has no reference-count
// traffic, and a frame's image stays alive across a resize.
class Frame {
public:
    PresentStatus status = PresentStatus::out_of_date;
    std::uint32_t image_index = 0;
    VkExtent2D extent{};
    VkFormat format = VK_FORMAT_UNDEFINED;
    // The layout the image must be in when present() is called:
    // PRESENT_SRC_KHR for a swapchain, TRANSFER_SRC_OPTIMAL headless.
    VkImageLayout present_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    // The stage at which the submission waits for the image: the source
    // stage of the first barrier on the image.
    static constexpr VkPipelineStageFlags2 acquire_stage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;

    // True when there is an image to render.
    explicit operator bool() const noexcept { return image_ != nullptr; }
    // The image and its view, borrowed from the presenter's image set, which
    // this Frame keeps alive. Only on a frame that has an image.
    const Image& image() const noexcept { return *image_; }
    const ImageView& view() const noexcept { return *view_; }
    // For the submission that renders the image: it waits until the image is
    // free and signals when rendering is done. Empty spans headless.
    Span<const SemaphoreSubmit> waits() const noexcept { return {&wait_, sync_count_}; }
    Span<const SemaphoreSubmit> signals() const noexcept { return {&signal_, sync_count_}; }

private:
    friend class Swapchain;
    friend class HeadlessPresenter;
    // The per-image fields from image index of set, which the frame holds.
    void point_at(const detail::FrameImages& set, std::uint32_t index) noexcept;
    // For a frame last filled from another set (or none): takes a reference
    // to set; the caller then fills the fields that stay the same for a
    // presenter (format, layout, ...). A steady loop never comes here, so it
    // has no reference-count traffic.
    void hold(const detail::Ref<detail::FrameImages>& set) noexcept;
    // Marks the frame empty (status says why); keeps the set it holds.
    void clear(PresentStatus why) noexcept {
        status = why;
        image_ = nullptr;
        view_ = nullptr;
        filled_from_ = nullptr;
        sync_count_ = 0;
        chain_ = nullptr;
        source_ = nullptr;
    }
    detail::Ref<detail::RefCounted> set_;
    const void* filled_from_ = nullptr;  // the set the per-presenter fields were filled from
    const Image* image_ = nullptr;
    const ImageView* view_ = nullptr;
    SemaphoreSubmit wait_;
    SemaphoreSubmit signal_;
    std::uint32_t sync_count_ = 0;
    std::uint32_t acquire_slot_ = 0;
    detail::SwapchainChainState* chain_ = nullptr;  // kept alive by set_ (its images keep it)
    const void* source_ = nullptr;                  // the headless presenter's state that made it
};

// The interface the frame loop uses; Swapchain and HeadlessPresenter
// implement it. acquire and present take the presenter's lock (and present
// the queue's), so under the multi-thread policy any thread may call them.
class Presenter {
public:
    virtual ~Presenter() = default;
    // Refills frame with the next image to render and returns frame.status;
    // see PresentStatus for an empty frame.
    virtual PresentStatus acquire(Frame& frame) = 0;
    // Hands the rendered image over (after the submission that renders it).
    virtual PresentStatus present(const Frame& frame) = 0;
    virtual VkExtent2D extent() const noexcept = 0;
    virtual VkFormat format() const noexcept = 0;
    virtual std::uint32_t image_count() const noexcept = 0;

protected:
    Presenter() = default;
    Presenter(const Presenter&) = default;
    Presenter& operator=(const Presenter&) = default;
};

// Mirrors what vkrc chooses for VkSwapchainCreateInfoKHR. Every member is
// optional; the Swapchain keeps a copy and re-reads it at every re-creation.
struct SwapchainCreateInfo {
    // Tried in order; the first the surface supports wins, otherwise the
    // surface's first format. Default: 8-bit BGRA, then RGBA, sRGB.
    List<VkSurfaceFormatKHR> preferred_formats = {{VK_FORMAT_B8G8R8A8_SRGB, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR},
                                                  {VK_FORMAT_R8G8B8A8_SRGB, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR}};
    // IMMEDIATE falls back to MAILBOX, MAILBOX to IMMEDIATE, both then to
    // FIFO (which every surface supports), the default.
    VkPresentModeKHR present_mode = VK_PRESENT_MODE_FIFO_KHR;
    // Clamped to the surface's minimum and maximum (default 3).
    std::uint32_t min_image_count = 3;
    // Default colour attachment; must be supported by the surface.
    VkImageUsageFlags image_usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    // Falls back to the first alpha mode the surface supports (default opaque).
    VkCompositeAlphaFlagBitsKHR composite_alpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    // Default true.
    bool clipped = true;
    // Only for surfaces that leave the extent to the swapchain (currentExtent
    // 0xFFFFFFFF, e.g. Wayland): the window's size in pixels; see set_extent.
    VkExtent2D extent{};
    // Receives the choices made and why, at creation and every re-creation (empty: no log).
    // Copied into the Swapchain: what it refers to must outlive the Swapchain. The text lives
    // for the call only.
    Function<void(const char*)> log{};
    // Optional pNext chain of VkSwapchainCreateInfoKHR (e.g. full-screen
    // exclusive, present-mode lists). Read at creation and at every
    // re-creation: what it points to must outlive the Swapchain.
    const void* next = nullptr;
};

// A swapchain for one Surface, re-created in place. Keeps its Surface,
// Queue and Device alive. Its images are borrowed Image handles that keep
// the Vulkan swapchain they belong to alive, so a retired swapchain stays
// until every frame that used it is dropped and its work has completed.
class Swapchain final : public Handle<detail::SwapchainState>, public Presenter {
public:
    // Creates the swapchain and takes the surface: a second live Swapchain
    // for the same surface is a UsageError. After a previous Swapchain of the
    // surface was dropped, waits for the device to be idle so that its Vulkan
    // swapchain is destroyed (UsageError if frames still hold its images).
    // The device needs
    // VK_KHR_swapchain, and the queue's family must present to the surface.
    // A surface with zero extent (minimised) gets its swapchain at the first
    // acquire after it has an area again.
    static Swapchain create(const Queue& queue, const Surface& surface, const SwapchainCreateInfo& info);
    static Swapchain create(const Queue& queue, const Surface& surface);  // the defaults

    PresentStatus acquire(Frame& frame) override;
    PresentStatus present(const Frame& frame) override;
    // As of the last (re)creation; under the multi-thread policy read them on
    // the thread that acquires, or use the Frame's.
    VkExtent2D extent() const noexcept override;
    VkFormat format() const noexcept override;
    std::uint32_t image_count() const noexcept override;

    // Re-creates for the surface's current extent now (oldSwapchain set to
    // the current one, which is retired). zero_extent when the surface has
    // no area (the old swapchain stays until it has); success otherwise.
    // acquire() does this itself after out_of_date or suboptimal.
    PresentStatus recreate();
    // The extent for surfaces that leave it to the swapchain (see
    // SwapchainCreateInfo::extent); takes effect at the next re-creation.
    void set_extent(VkExtent2D extent);

    // The current Vulkan swapchain (VK_NULL_HANDLE while the surface has no area).
    VkSwapchainKHR vk() const noexcept;
    const Surface& surface() const noexcept;
    const Queue& queue() const noexcept;
    VkColorSpaceKHR color_space() const noexcept;
    VkPresentModeKHR present_mode() const noexcept;

private:
    using Handle::Handle;
};

// Mirrors what a swapchain would be made of, for rendering offscreen.
// Copied by create().
struct HeadlessPresenterCreateInfo {
    // Required, non-zero.
    VkExtent2D extent{};
    // Optional (default 8-bit RGBA, unorm).
    VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
    // The ring's size: frames in flight + 1, as a swapchain would have. Optional (default 3), non-zero.
    std::uint32_t image_count = 3;
    // TRANSFER_SRC is always added (for read_back). Optional (default colour attachment).
    VkImageUsageFlags image_usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
};

// The Presenter for machines without a display: the n-th acquire returns
// ring image n % image_count; acquire and present are bookkeeping only (no
// semaphores, no Vulkan call; present records the last presented image and
// takes no lock), as in the teapot benchmark's convention
// (bench/teapot/harness/variant.hpp). Like a swapchain image, a ring image
// is reused image_count frames later: the frame loop's fences keep it from
// being rewritten while the GPU still renders into it.
class HeadlessPresenter final : public Handle<detail::HeadlessPresenterState>, public Presenter {
public:
    static HeadlessPresenter create(const Queue& queue, const HeadlessPresenterCreateInfo& info);

    // Inline (as the frame loop's other calls): a steady loop's acquire and
    // present pay no call of their own.
    PresentStatus acquire(Frame& frame) override;
    PresentStatus present(const Frame& frame) override;
    VkExtent2D extent() const noexcept override;
    VkFormat format() const noexcept override;
    std::uint32_t image_count() const noexcept override;

    // The ring image last presented; UINT32_MAX before the first present.
    std::uint32_t last_presented() const noexcept;
    // Waits for the image's rendering (the queue's submitted work) and copies
    // it out: extent.width * extent.height texels, top row first.
    List<std::byte> read_back(std::uint32_t image_index) const;
    // New images of this extent from the next acquire (frames holding the
    // old ones keep them alive).
    void resize(VkExtent2D extent);

private:
    using Handle::Handle;
    // acquire() for a frame last filled from elsewhere; under the state's lock.
    [[gnu::noinline]] static PresentStatus refill(Frame& frame, detail::HeadlessPresenterState& s,
                                                  std::uint32_t index) noexcept;
    // Makes the ring a pending resize() asked for; false while its extent is
    // zero. Cold: kept out of acquire's fast path.
    [[gnu::cold]] static bool apply_resize(detail::HeadlessPresenterState& s);
    // present() of a frame another presenter (or none) filled: throws UsageError.
    [[noreturn, gnu::cold]] static void refuse_present();
};

namespace detail {

// The images a Frame points into: one Vulkan swapchain's (each keeping its
// chain alive) or one headless ring. Replaced, not changed, by a re-creation.
class FrameImages final : public RefCounted {
public:
    List<Image> images;
    List<ImageView> views;
    VkExtent2D extent{};
};

// One Vulkan swapchain (current or retired) and its per-image semaphores.
class SwapchainChainState final : public RefCounted {
public:
    // Queues the swapchain's destruction after everything submitted on the
    // queue so far, including (by an empty submission) its last present;
    // see the Presentation section of docs/design.md.
    ~SwapchainChainState() override;
    Queue queue;
    Surface surface;
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    // Signalled by the rendering of image i, waited by its present; reused
    // only when image i is acquired again.
    List<Semaphore> render_done;
    bool presented = false;  // under the owning SwapchainState's mutex
    // Not retired when its Swapchain went: its destruction ends the surface's
    // SurfaceState::releasing.
    bool last = false;
};

class SwapchainState final : public RefCounted {
public:
    ~SwapchainState() override;  // gives the surface back
    Queue queue;
    Surface surface;
    SwapchainCreateInfo info;
    Ref<SwapchainChainState> chain;  // null until the surface has an area
    Ref<FrameImages> images;         // the chain's; null with it
    // Ring of acquire semaphores, each reused once the queue has reached the
    // value recorded when the frame that waited on it was presented.
    List<Semaphore> acquire_semaphores;
    List<std::uint64_t> acquire_done_values;
    std::uint32_t next_acquire = 0;
    VkSurfaceFormatKHR surface_format{};
    VkPresentModeKHR present_mode = VK_PRESENT_MODE_FIFO_KHR;
    VkExtent2D extent{};
    bool needs_recreate = false;
    Mutex mutex;
};

class HeadlessPresenterState final : public RefCounted {
public:
    Queue queue;
    HeadlessPresenterCreateInfo info;
    Ref<FrameImages> ring;         // under lock
    std::uint32_t next_index = 0;  // the image the next acquire gets; under lock
    // Written by present without the lock: present then touches no state it
    // must read first (its frame is checked against the frame's own fields).
    PolicyAtomic<std::uint32_t> last_presented{UINT32_MAX};
    PolicyAtomic<bool> needs_resize{false};
    // Guards ring and next_index: held for a few instructions per acquire.
    mutable SpinLock lock;
    // Serialises re-making the ring (Vulkan calls, allocation) outside lock.
    mutable Mutex resize_mutex;
};

}  // namespace detail

inline void Frame::point_at(const detail::FrameImages& set, std::uint32_t index) noexcept {
    image_index = index;
    image_ = &set.images[index];
    view_ = &set.views[index];
    extent = set.extent;
}

inline PresentStatus HeadlessPresenter::acquire(Frame& frame) {
    auto& s = *state_;
    if (s.needs_resize.load(__ATOMIC_ACQUIRE) && !apply_resize(s)) [[unlikely]] {
        frame.clear(PresentStatus::zero_extent);
        return frame.status;
    }
    LockGuard lock(s.lock);
    // A wrapping index, not a count modulo image_count: no division per frame.
    const std::uint32_t index = s.next_index;
    s.next_index = index + 1 == s.info.image_count ? 0 : index + 1;
    if (frame.filled_from_ != s.ring.get()) [[unlikely]]
        return refill(frame, s, index);
    frame.point_at(*s.ring, index);
    frame.status = PresentStatus::success;
    return PresentStatus::success;
}

inline PresentStatus HeadlessPresenter::present(const Frame& frame) {
    auto& s = *state_;
    if (!frame || frame.source_ != &s) [[unlikely]]
        refuse_present();
    s.last_presented.store(frame.image_index, __ATOMIC_RELAXED);
    return PresentStatus::success;
}

VKRC_END_NAMESPACE
