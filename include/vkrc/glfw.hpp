// GLFW windows and surfaces: the vkrc::glfw library (vkrc_glfw_st /
// vkrc_glfw_mt), the only part of vkrc that links GLFW. Three tiers:
//   * Surface::adopt (vkrc core) for a VkSurfaceKHR made any other way;
//   * glfw::create_surface for a GLFWwindow the application made;
//   * glfw::create_window_surface: window, instance and surface in one call.
// GLFW calls must come from the main thread (GLFW's rule).
#pragma once

#include "vkrc/surface.hpp"

struct GLFWwindow;

VKRC_BEGIN_NAMESPACE
namespace glfw {

// Initialises GLFW and returns the instance extensions its surfaces need
// (names owned by GLFW, valid until it terminates). Throws std::runtime_error
// when GLFW or its Vulkan support is unavailable (no display, no loader).
List<const char*> required_instance_extensions();

// A surface for window (glfwCreateWindowSurface), destroyed by vkrc. The
// instance needs required_instance_extensions(); the window must outlive the
// surface and every swapchain made for it.
Surface create_surface(const Instance& instance, GLFWwindow* window);

// Every member is optional.
struct WindowCreateInfo {
    // Screen coordinates (default 800x600).
    int width = 800;
    int height = 600;
    // Default "vkrc". Read during create() (GLFW copies it); need not outlive the call.
    const char* title = "vkrc";
    // Defaults true.
    bool resizable = true;
    bool visible = true;
};

// A GLFW window without an OpenGL context (GLFW_NO_API). Move-only. The
// first Window initialises GLFW and the last one destroyed terminates it.
class Window {
public:
    Window() noexcept = default;
    static Window create(const WindowCreateInfo& info = {});
    Window(Window&& other) noexcept;
    Window& operator=(Window&& other) noexcept;
    ~Window();

    GLFWwindow* get() const noexcept { return window_; }
    explicit operator bool() const noexcept { return window_ != nullptr; }
    bool should_close() const noexcept;
    // The drawable size in pixels (0x0 while minimised).
    VkExtent2D framebuffer_extent() const noexcept;
    // glfwPollEvents / glfwWaitEvents (all windows).
    static void poll_events() noexcept;
    static void wait_events() noexcept;

private:
    explicit Window(GLFWwindow* window) noexcept : window_(window) {}
    GLFWwindow* window_ = nullptr;
};

// A window, an instance made from instance_info plus GLFW's extensions, and
// a surface for the window. Members are destroyed surface first, window last.
struct WindowSurface {
    Window window{};
    Instance instance{};
    Surface surface{};
};
WindowSurface create_window_surface(const WindowCreateInfo& window, InstanceCreateInfo instance_info = {});

}  // namespace glfw
VKRC_END_NAMESPACE
