// The command line and the ending shared by the examples that render into a
// window or, headless, into a PNG (triangle, teapot, renderer):
//     NAME [--frames N] [--validation]                                a window (closes after N frames)
//     NAME --headless [--frames N] [--validation] [--out NAME.png]
// and, for the examples that use them (renderer): --threads N (recording
// threads), --resize-every N (resize the window every N frames, for tests),
// --report N (print timings every N frames). An example with options of its
// own (raytrace) takes them out of argv first and names them in extra_usage.
// Header-only: it uses vkrc's presenter, and each example picks its policy.
#pragma once

#include "support/png.hpp"

#include <vkrc/swapchain.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <span>
#include <string>

namespace vkrc_examples {

struct WindowOrHeadless {
    bool headless = false;
    bool validation = false;
    long frames = -1;  // -1: until the window closes (one frame headless)
    std::string out_file;
    long threads = 0;  // 0: the example's default
    long resize_every = 0;
    long report_every = 100;

    // How many frames the loop draws; -1: until the window closes.
    long frame_limit() const { return frames >= 0 ? frames : headless ? 1 : -1; }
};

// Parses the command line and runs run(options): exit status 2 and the usage
// on a bad argument, 1 and the message when run throws.
inline int run_example(int argc, char** argv, const char* name, const std::function<int(const WindowOrHeadless&)>& run,
                       const char* extra_usage = "") {
    WindowOrHeadless options;
    options.out_file = std::string(name) + ".png";
    for (int i = 1; i < argc; ++i) {
        const bool has_value = i + 1 < argc;
        if (std::strcmp(argv[i], "--headless") == 0) options.headless = true;
        else if (std::strcmp(argv[i], "--validation") == 0) options.validation = true;
        else if (std::strcmp(argv[i], "--out") == 0 && has_value) options.out_file = argv[++i];
        else if (std::strcmp(argv[i], "--frames") == 0 && has_value)
            options.frames = std::strtol(argv[++i], nullptr, 10);
        else if (std::strcmp(argv[i], "--threads") == 0 && has_value)
            options.threads = std::strtol(argv[++i], nullptr, 10);
        else if (std::strcmp(argv[i], "--resize-every") == 0 && has_value)
            options.resize_every = std::strtol(argv[++i], nullptr, 10);
        else if (std::strcmp(argv[i], "--report") == 0 && has_value)
            options.report_every = std::strtol(argv[++i], nullptr, 10);
        else {
            std::fprintf(stderr,
                         "usage: %s [--headless [--out FILE.png]] [--frames N] [--validation] [--threads N] "
                         "[--resize-every N] [--report N]%s\n",
                         argv[0], extra_usage);
            return 2;
        }
    }
    try {
        return run(options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", name, e.what());
        return 1;
    }
}

// Reads the presenter's last presented image back (once the GPU is done
// with it) and writes it to file; nothing when no frame was presented.
inline void save_last_frame(const vkrc::HeadlessPresenter& presenter, const std::string& file) {
    if (presenter.last_presented() == UINT32_MAX) return;
    auto pixels = presenter.read_back(presenter.last_presented());
    write_png(file, presenter.extent().width, presenter.extent().height,
              std::span(reinterpret_cast<const std::uint8_t*>(pixels.data()), pixels.size()));
    std::printf("wrote %s\n", file.c_str());
}

}  // namespace vkrc_examples
