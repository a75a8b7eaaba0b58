// Starts a private Xvfb for tests that need a display, so that they run on
// machines without one (CI, GPU servers) and in parallel with each other.
#pragma once

#include <sys/types.h>

#include <string>

namespace vkrc_test {

// Starts Xvfb on the first free display number in :90..:150 and points
// DISPLAY at it; the destructor stops it and restores DISPLAY.
class Xvfb {
public:
    Xvfb();
    ~Xvfb();
    Xvfb(const Xvfb&) = delete;
    Xvfb& operator=(const Xvfb&) = delete;

    bool running() const { return pid_ > 0; }
    // ":<n>", or why no server could be started.
    const std::string& display() const { return display_; }
    const std::string& error() const { return error_; }

private:
    pid_t pid_ = -1;
    std::string display_;
    std::string error_;
    bool had_display_ = false;
    std::string old_display_;
};

}  // namespace vkrc_test
