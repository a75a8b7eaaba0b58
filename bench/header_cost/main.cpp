// Header-cost benchmark: how long a translation unit that creates a device
// takes to compile with vkrc and with Vulkan-Hpp's vk::raii.
//
// Compiles vkrc_device.cpp and raii_device.cpp (compile only, no link) with
// the build's compiler and flags, interleaved, and prints the median wall and
// CPU (user + system of the compiler) times and their ratio. A third probe,
// api_floor.cpp, is the part of vkrc's cost that its API's standard headers
// fix: how far vkrc's own headers are from the least they could cost. vkrc's goal is at
// most 0.08 of vk::raii's (issue 18). CPU time is the steadier figure on a shared
// machine; wall time is what a developer waits.
//
// Usage: header_cost [--csv FILE] [repetitions] [extra compiler flags...]
//   repetitions defaults to 5; extra flags come after the build's (so -O0
//   overrides the build's -O level). --csv writes the medians (one row per
//   probe) for docs/results/ (bench/header_cost_run.sh adds the run's header).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

extern char** environ;

namespace {

struct Sample {
    double wall_ms;
    double cpu_ms;
};

double cpu_ms_of_children() {
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    auto ms = [](const timeval& t) { return double(t.tv_sec) * 1e3 + double(t.tv_usec) / 1e3; };
    return ms(usage.ru_utime) + ms(usage.ru_stime);
}

// Splits the build's flag string at spaces (CMake flag strings hold no quoting).
std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> words;
    std::size_t i = 0;
    while (i < text.size()) {
        std::size_t end = text.find(' ', i);
        if (end == std::string::npos) end = text.size();
        if (end > i) words.push_back(text.substr(i, end - i));
        i = end + 1;
    }
    return words;
}

// Runs the compiler once; exits the benchmark if the compile fails.
Sample compile(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);

    const double cpu_before = cpu_ms_of_children();
    const auto start = std::chrono::steady_clock::now();
    pid_t pid = 0;
    if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) {
        std::fprintf(stderr, "header_cost: cannot run %s\n", argv[0]);
        std::exit(2);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    const auto stop = std::chrono::steady_clock::now();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::string command;
        for (const std::string& a : args) command += a + ' ';
        std::fprintf(stderr, "header_cost: compile failed: %s\n", command.c_str());
        std::exit(1);
    }
    return {std::chrono::duration<double, std::milli>(stop - start).count(), cpu_ms_of_children() - cpu_before};
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string csv;
    int first = 1;
    if (argc > 2 && std::string(argv[1]) == "--csv") {
        csv = argv[2];
        first = 3;
    }
    int repetitions = argc > first ? std::atoi(argv[first]) : 5;
    if (repetitions < 1) {
        std::fprintf(stderr, "usage: header_cost [--csv FILE] [repetitions] [extra compiler flags...]\n");
        return 2;
    }
    std::vector<std::string> flags = split(VKRC_BENCH_CXX_FLAGS);
    for (int i = first + 1; i < argc; ++i) flags.push_back(argv[i]);

    struct Probe {
        const char* label;
        const char* source;
        std::vector<std::string> args;
        std::vector<Sample> samples;
    };
    // vkrc, vk::raii, and the floor: the headers vkrc's API names, no vkrc.
    const char* names[] = {"vkrc", "vk::raii", "floor"};
    Probe probes[] = {{"<vkrc/vkrc.hpp>, device", VKRC_BENCH_SOURCE_DIR "/vkrc_device.cpp", {}, {}},
                      {"<vulkan/vulkan_raii.hpp>, device", VKRC_BENCH_SOURCE_DIR "/raii_device.cpp", {}, {}},
                      {"floor: std/Vulkan headers of API", VKRC_BENCH_SOURCE_DIR "/api_floor.cpp", {}, {}}};
    std::string shown_flags;
    for (const std::string& f : flags) shown_flags += ' ' + f;
    for (Probe& p : probes) {
        p.args = {VKRC_BENCH_CXX_COMPILER};
        p.args.insert(p.args.end(), flags.begin(), flags.end());
        p.args.insert(p.args.end(), {"-std=c++20", "-I" VKRC_BENCH_INCLUDE_DIR});
        // Empty when the Vulkan headers are in a default include directory.
        if (*VKRC_BENCH_VULKAN_INCLUDE_DIR) p.args.push_back("-I" VKRC_BENCH_VULKAN_INCLUDE_DIR);
        p.args.insert(p.args.end(), {"-c", p.source, "-o", VKRC_BENCH_BINARY_DIR "/probe.o"});
    }

    std::printf("compiler: %s\nflags (%s, then arguments):%s -std=c++20\nmedian of %d, interleaved\n\n",
                VKRC_BENCH_CXX_COMPILER, VKRC_BENCH_FLAGS_ORIGIN, shown_flags.c_str(), repetitions);
    for (int r = 0; r < repetitions; ++r) {
        for (Probe& p : probes) p.samples.push_back(compile(p.args));
    }

    double wall[3], cpu[3];
    std::printf("%-34s %10s %10s\n", "translation unit", "wall ms", "cpu ms");
    for (int i = 0; i < 3; ++i) {
        std::vector<double> w, c;
        for (const Sample& s : probes[i].samples) {
            w.push_back(s.wall_ms);
            c.push_back(s.cpu_ms);
        }
        wall[i] = median(w);
        cpu[i] = median(c);
        std::printf("%-34s %10.0f %10.0f\n", probes[i].label, wall[i], cpu[i]);
    }
    std::printf("%-34s %10.3f %10.3f   (goal: at most 0.080)\n", "ratio vkrc / vk::raii", wall[0] / wall[1],
                cpu[0] / cpu[1]);
    std::printf("%-34s %10.3f %10.3f\n", "ratio floor / vk::raii", wall[2] / wall[1], cpu[2] / cpu[1]);
    if (!csv.empty()) {
        std::ofstream out(csv);
        out << "probe,compiler,flags,repetitions,wall_ms,cpu_ms,cpu_ratio_to_raii,wall_ratio_to_raii\n";
        std::string all_flags = shown_flags + " -std=c++20";
        all_flags.erase(0, all_flags.find_first_not_of(' '));
        for (int i = 0; i < 3; ++i) {
            char row[160];
            std::snprintf(row, sizeof row, ",%d,%.0f,%.0f,%.3f,%.3f\n", repetitions, wall[i], cpu[i], cpu[i] / cpu[1],
                          wall[i] / wall[1]);
            out << names[i] << ',' << VKRC_BENCH_CXX_COMPILER << ",\"" << all_flags << '"' << row;
        }
        if (!out) {
            std::fprintf(stderr, "header_cost: cannot write %s\n", csv.c_str());
            return 1;
        }
    }
    return 0;
}
