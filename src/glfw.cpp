#include "vkrc/glfw.hpp"

#include "text.hpp"
#include "object_state.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

VKRC_BEGIN_NAMESPACE
namespace glfw {

namespace {

int live_windows = 0;  // main thread only (GLFW's rule)

[[noreturn]] void throw_glfw(const char* call) {
    const char* description = nullptr;
    glfwGetError(&description);
    throw std::runtime_error(std::string(call) +
                             " failed: " + (description ? description : "no GLFW error description"));
}

void init() {
    if (glfwInit() != GLFW_TRUE) throw_glfw("vkrc::glfw: glfwInit");
    if (glfwVulkanSupported() != GLFW_TRUE) throw_glfw("vkrc::glfw: glfwVulkanSupported");
}

}  // namespace

List<const char*> required_instance_extensions() {
    init();
    std::uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    if (!names) throw_glfw("vkrc::glfw: glfwGetRequiredInstanceExtensions");
    return List<const char*>(names, count);
}

Surface create_surface(const Instance& instance, GLFWwindow* window) {
    const detail::Caller caller{"vkrc::glfw::create_surface"};
    caller.require_handle(instance, "the Instance");
    caller.require(window != nullptr, "the window is null");
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    check(glfwCreateWindowSurface(instance.vk(), window, nullptr, &surface), "glfwCreateWindowSurface");
    try {
        return Surface::adopt(instance, surface, Ownership::owned);
    } catch (...) {
        instance.fn().vkDestroySurfaceKHR(instance.vk(), surface, nullptr);
        throw;
    }
}

Window Window::create(const WindowCreateInfo& info) {
    init();
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, info.resizable ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, info.visible ? GLFW_TRUE : GLFW_FALSE);
    GLFWwindow* window = glfwCreateWindow(info.width, info.height, info.title, nullptr, nullptr);
    if (!window) {
        if (live_windows == 0) glfwTerminate();
        throw_glfw("vkrc::glfw::Window::create: glfwCreateWindow");
    }
    ++live_windows;
    return Window(window);
}

Window::Window(Window&& other) noexcept : window_(std::exchange(other.window_, nullptr)) {}

Window& Window::operator=(Window&& other) noexcept {
    Window old(std::move(*this));
    window_ = std::exchange(other.window_, nullptr);
    return *this;
}

Window::~Window() {
    if (!window_) return;
    glfwDestroyWindow(window_);
    if (--live_windows == 0) glfwTerminate();
}

bool Window::should_close() const noexcept { return glfwWindowShouldClose(window_) == GLFW_TRUE; }

VkExtent2D Window::framebuffer_extent() const noexcept {
    int width = 0, height = 0;
    glfwGetFramebufferSize(window_, &width, &height);
    return {static_cast<std::uint32_t>(std::max(width, 0)), static_cast<std::uint32_t>(std::max(height, 0))};
}

void Window::poll_events() noexcept { glfwPollEvents(); }
void Window::wait_events() noexcept { glfwWaitEvents(); }

WindowSurface create_window_surface(const WindowCreateInfo& window_info, InstanceCreateInfo instance_info) {
    WindowSurface out;
    out.window = Window::create(window_info);
    for (const char* name : required_instance_extensions()) {
        detail::add_unique(instance_info.enabled_extension_names, name);
    }
    out.instance = Instance::create(instance_info);
    out.surface = create_surface(out.instance, out.window.get());
    return out;
}

}  // namespace glfw
VKRC_END_NAMESPACE
