// Windowed mode (--window): GLFW for the whole run and the window each
// variant presents to.
//
// One window per variant, made in its init and destroyed in its destructor:
// the harness keeps every variant of a configuration alive at once (their
// blocks interleave), and Vulkan allows one non-retired swapchain per native
// window, so a window shared by all variants would need its swapchain torn
// down and rebuilt between blocks, work no single API would do.
//
// GLFW itself is initialised once by the harness (GlfwSession) rather than by
// the variants: glfwTerminate destroys every window, so a variant that
// terminated GLFW with its last window (as vkrc::glfw::Window does) would take
// the other variants' windows with it. The vkrc variants therefore make their
// surface with vkrc::glfw::create_surface for this window, the vkrc::glfw tier
// meant for windows the application owns.
#pragma once

#include "harness/variant.hpp"

struct GLFWwindow;

namespace teapot {

// glfwInit for the run, glfwTerminate at its end; throws std::runtime_error
// when GLFW or its Vulkan support is unavailable (no display, no loader).
class GlfwSession {
public:
    GlfwSession();
    ~GlfwSession();
    GlfwSession(const GlfwSession&) = delete;
    GlfwSession& operator=(const GlfwSession&) = delete;
};

// A visible, fixed-size window of Config width x height without a client API
// (GLFW_NO_API). Move-only; empty when default-constructed.
class BenchWindow {
public:
    BenchWindow() noexcept = default;
    explicit BenchWindow(const Config& config);
    BenchWindow(BenchWindow&& other) noexcept;
    BenchWindow& operator=(BenchWindow&& other) noexcept;
    ~BenchWindow();
    GLFWwindow* get() const noexcept { return window_; }
    // Brings the window to the front (glfwFocusWindow).
    void raise() const;

private:
    GLFWwindow* window_ = nullptr;
};

// The instance extensions a window surface needs (VK_KHR_surface and the
// platform's), from glfwGetRequiredInstanceExtensions; throws when GLFW has none.
std::vector<const char*> window_instance_extensions();

// glfwPollEvents: the harness calls it between blocks (untimed), so that the
// windows stay responsive. Before each variant's block it also raises that
// variant's window: the windows overlap, and presenting to the visible one
// costs the window system more than to a covered one (on Xvfb the topmost
// window's acquire was 2.3x the others'), so each variant is measured on top.
void poll_window_events();
// glfwWaitEvents: for a variant whose surface has no area (a minimised window).
void wait_window_events();

}  // namespace teapot
