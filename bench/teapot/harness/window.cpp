#include "harness/window.hpp"

#define GLFW_INCLUDE_NONE  // Vulkan only, no OpenGL headers
#include <GLFW/glfw3.h>

#include <stdexcept>
#include <string>
#include <utility>

namespace teapot {

namespace {

[[noreturn]] void throw_glfw(const char* call, const char* hint = "") {
    const char* description = nullptr;
    glfwGetError(&description);
    throw std::runtime_error(std::string("--window: ") + call +
                             " failed: " + (description ? description : "no GLFW error description") + hint);
}

}  // namespace

GlfwSession::GlfwSession() {
    if (glfwInit() != GLFW_TRUE)
        throw_glfw("glfwInit", " (no display? tests/with_xvfb.sh runs a command on a private Xvfb)");
    if (glfwVulkanSupported() != GLFW_TRUE) {
        glfwTerminate();
        throw_glfw("glfwVulkanSupported");
    }
}

GlfwSession::~GlfwSession() { glfwTerminate(); }

BenchWindow::BenchWindow(const Config& config) {
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    window_ = glfwCreateWindow(int(config.width), int(config.height), "vkrc teapot benchmark", nullptr, nullptr);
    if (!window_) throw_glfw("glfwCreateWindow");
}

BenchWindow::BenchWindow(BenchWindow&& other) noexcept : window_(std::exchange(other.window_, nullptr)) {}

BenchWindow& BenchWindow::operator=(BenchWindow&& other) noexcept {
    BenchWindow old(std::move(*this));
    window_ = std::exchange(other.window_, nullptr);
    return *this;
}

BenchWindow::~BenchWindow() {
    if (window_) glfwDestroyWindow(window_);
}

void BenchWindow::raise() const { glfwFocusWindow(window_); }

void poll_window_events() { glfwPollEvents(); }
void wait_window_events() { glfwWaitEvents(); }

std::vector<const char*> window_instance_extensions() {
    std::uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    if (!names) throw std::runtime_error("glfwGetRequiredInstanceExtensions failed");
    return std::vector<const char*>(names, names + count);
}

}  // namespace teapot
