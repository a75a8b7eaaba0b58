#include "xvfb.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

extern char** environ;

namespace vkrc_test {

namespace {

bool exists(const std::string& path) {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0;
}

// The pid in an X lock file, or -1.
pid_t lock_owner(int display) {
    std::ifstream lock("/tmp/.X" + std::to_string(display) + "-lock");
    long pid = -1;
    if (!(lock >> pid)) return -1;
    return static_cast<pid_t>(pid);
}

pid_t spawn_xvfb(const std::string& display) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    std::string name = "Xvfb", screen = "-screen", zero = "0", geometry = "1280x1024x24", nolisten = "-nolisten",
                tcp = "tcp";
    char* argv[] = {name.data(),     const_cast<char*>(display.c_str()),
                    screen.data(),   zero.data(),
                    geometry.data(), nolisten.data(),
                    tcp.data(),      nullptr};
    pid_t pid = -1;
    int r = posix_spawnp(&pid, "Xvfb", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    return r == 0 ? pid : -1;
}

}  // namespace

Xvfb::Xvfb() {
    if (const char* d = std::getenv("DISPLAY")) {
        had_display_ = true;
        old_display_ = d;
    }
    for (int n = 90; n <= 150; ++n) {
        if (exists("/tmp/.X" + std::to_string(n) + "-lock") || exists("/tmp/.X11-unix/X" + std::to_string(n))) continue;
        const std::string display = ":" + std::to_string(n);
        pid_t pid = spawn_xvfb(display);
        if (pid <= 0) {
            error_ = "cannot run Xvfb (is the xvfb package installed?)";
            return;
        }
        // Ours once its lock names it and its socket exists; another server
        // that won the number makes ours exit, and the next number is tried.
        bool ready = false;
        for (int i = 0; i < 500; ++i) {
            int status = 0;
            if (::waitpid(pid, &status, WNOHANG) == pid) {
                pid = -1;
                break;
            }
            if (lock_owner(n) == pid && exists("/tmp/.X11-unix/X" + std::to_string(n))) {
                ready = true;
                break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        if (ready) {
            pid_ = pid;
            display_ = display;
            ::setenv("DISPLAY", display.c_str(), 1);
            return;
        }
        if (pid > 0) {
            ::kill(pid, SIGTERM);
            ::waitpid(pid, nullptr, 0);
        }
    }
    error_ = "no free display number in :90..:150";
}

Xvfb::~Xvfb() {
    if (pid_ > 0) {
        ::kill(pid_, SIGTERM);
        ::waitpid(pid_, nullptr, 0);
    }
    if (had_display_) {
        ::setenv("DISPLAY", old_display_.c_str(), 1);
    } else {
        ::unsetenv("DISPLAY");
    }
}

}  // namespace vkrc_test
