// State blocks behind Swapchain and HeadlessPresenter: only swapchain.cpp
// needs them, so the public header declares the handles' copy, move and
// destruction out of line instead of including these (header cost).
#pragma once

#include "vkrc/swapchain.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

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
    std::vector<Semaphore> render_done;
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
    std::vector<Image> images;
    std::vector<ImageView> views;
    // Ring of acquire semaphores, each reused once the queue has reached the
    // value recorded when the frame that waited on it was presented.
    std::vector<Semaphore> acquire_semaphores;
    std::vector<std::uint64_t> acquire_done_values;
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
    std::vector<Image> images;
    std::vector<ImageView> views;
    std::uint64_t acquired = 0;  // under mutex
    // Written by present without the lock: present then touches no state it
    // must read first (its frame is checked against the frame's own fields).
    Atomic<std::uint32_t> last_presented{UINT32_MAX};
    bool needs_resize = false;
    mutable Mutex mutex;
};

}  // namespace detail

VKRC_END_NAMESPACE
