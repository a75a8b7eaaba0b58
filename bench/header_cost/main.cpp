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
// Usage: header_cost [--csv FILE] [--instructions] [repetitions] [extra compiler flags...]
//   repetitions defaults to 5; extra flags come after the build's (so -O0
//   overrides the build's -O level). --csv writes the medians (one row per
//   probe) for docs/results/ (bench/header_cost_run.sh adds the run's header).
//   --instructions also compiles each probe once under valgrind's cachegrind
//   and prints the instructions the compiler ran (the driver and the processes
//   it spawns: cc1plus or clang -cc1, the assembler): unlike times they do not
//   move with the machine's load, so they resolve a ratio near the goal on a
//   shared machine. Slow: vk::raii takes minutes under valgrind.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace {

struct Sample {
    double wall_ms;
    double cpu_ms;
};

struct Probe {
    const char* name;  // the CSV's probe column
    const char* label;
    const char* source;
    std::vector<std::string> args;
    std::vector<Sample> samples;
    double wall_ms;  // medians
    double cpu_ms;
    long long instructions;  // 0: not measured
};

struct Options {
    std::string csv;
    bool instructions = false;
    int repetitions = 5;
    std::vector<std::string> extra_flags;
};

constexpr const char* usage_text =
    "usage: header_cost [--csv FILE] [--instructions] [repetitions] [extra compiler flags...]\n";

double cpu_ms_of_children() {
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    auto ms = [](const timeval& t) { return double(t.tv_sec) * 1e3 + double(t.tv_usec) / 1e3; };
    return ms(usage.ru_utime) + ms(usage.ru_stime);
}

// Splits the build's flag string at spaces (CMake flag strings hold no quoting),
// or PATH at colons.
std::vector<std::string> split(const std::string& text, char separator = ' ') {
    std::vector<std::string> words;
    std::size_t i = 0;
    while (i < text.size()) {
        std::size_t end = text.find(separator, i);
        if (end == std::string::npos) end = text.size();
        if (end > i) words.push_back(text.substr(i, end - i));
        i = end + 1;
    }
    return words;
}

std::string joined(const std::vector<std::string>& args) {
    std::string command;
    for (const std::string& a : args) command += a + ' ';
    return command;
}

// Runs a program (looked up in PATH) and waits for it: whether it exited 0.
bool run(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) {
        std::fprintf(stderr, "header_cost: cannot run %s\n", argv[0]);
        return false;
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// Whether posix_spawnp would find the program: checked before the timed
// compiles, so a missing valgrind does not cost a whole run first.
bool on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    for (const std::string& dir : split(path ? path : "", ':')) {
        if (access((dir + '/' + program).c_str(), X_OK) == 0) return true;
    }
    return false;
}

// Runs the compiler once; exits the benchmark if the compile fails.
Sample compile(const std::vector<std::string>& args) {
    const double cpu_before = cpu_ms_of_children();
    const auto start = std::chrono::steady_clock::now();
    const bool compiled = run(args);
    const auto stop = std::chrono::steady_clock::now();
    if (!compiled) {
        std::fprintf(stderr, "header_cost: compile failed: %s\n", joined(args).c_str());
        std::exit(1);
    }
    return {std::chrono::duration<double, std::milli>(stop - start).count(), cpu_ms_of_children() - cpu_before};
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

// No silent fallback to times: a run asked for instructions fails without them.
[[noreturn]] void fail_instructions(const std::string& dir, const std::string& why) {
    std::fprintf(stderr, "header_cost: --instructions FAILED: %s\n", why.c_str());
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
    std::exit(1);
}

// The first count of a cachegrind file's 'summary:' line: Ir, the only event
// with --cache-sim=no. -1 where there is none (the process did not finish).
long long summary_of(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("summary:", 0) == 0) return std::atoll(line.c_str() + 8);
    }
    return -1;
}

// The files of dir whose names start with prefix.
std::vector<std::filesystem::path> files_named(const std::string& dir, const std::string& prefix) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().filename().string().rfind(prefix, 0) == 0) files.push_back(entry.path());
    }
    return files;
}

// One compile under cachegrind, which follows the driver into every process
// it spawns and writes a file per process into dir (emptied again for the next
// probe); the compile's instructions are their sum. valgrind's own messages
// (a cache-size warning per process, though no cache is simulated) go to log
// files that are shown only when the compile fails.
long long count_instructions(const std::vector<std::string>& compile_args, const std::string& dir) {
    std::vector<std::string> args = {"valgrind",
                                     "--tool=cachegrind",
                                     "--cache-sim=no",
                                     "--trace-children=yes",
                                     "--log-file=" + dir + "/log.%p",
                                     "--cachegrind-out-file=" + dir + "/cg.%p"};
    args.insert(args.end(), compile_args.begin(), compile_args.end());
    if (!run(args)) {
        for (const std::filesystem::path& log : files_named(dir, "log.")) std::cerr << std::ifstream(log).rdbuf();
        fail_instructions(dir, "the compile under valgrind failed: " + joined(args));
    }
    const std::vector<std::filesystem::path> outputs = files_named(dir, "cg.");
    if (outputs.empty()) fail_instructions(dir, "valgrind wrote no cachegrind file into " + dir);
    long long total = 0;
    for (const std::filesystem::path& file : outputs) {
        const long long count = summary_of(file);
        if (count < 0) fail_instructions(dir, "no 'summary:' line in " + file.string());
        total += count;
    }
    std::filesystem::remove_all(dir);
    std::filesystem::create_directory(dir);
    return total;
}

// Each probe once, after the timed compiles (so valgrind does not load the
// machine under them), in a temporary directory of the build removed after.
void measure_instructions(Probe (&probes)[3]) {
    std::string dir = VKRC_BENCH_BINARY_DIR "/cachegrind.XXXXXX";
    if (!mkdtemp(dir.data())) fail_instructions("", "cannot make a directory " + dir);
    for (Probe& p : probes) {
        std::fprintf(stderr, "header_cost: counting the instructions of the %s probe under valgrind...\n", p.name);
        const auto start = std::chrono::steady_clock::now();
        p.instructions = count_instructions(p.args, dir);
        const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
        std::fprintf(stderr, "header_cost: %s: %.0f M instructions (%.0f s)\n", p.name, double(p.instructions) / 1e6,
                     took.count());
    }
    std::filesystem::remove_all(dir);
}

// Options come first, in any order; after them the repetitions, then the
// compiler's flags. False on a usage error.
bool parse(int argc, char** argv, Options& options) {
    int i = 1;
    for (; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--instructions") {
            options.instructions = true;
        } else if (a == "--csv" && i + 1 < argc) {
            options.csv = argv[++i];
        } else {
            break;
        }
    }
    if (i < argc) options.repetitions = std::atoi(argv[i++]);
    for (; i < argc; ++i) options.extra_flags.push_back(argv[i]);
    return options.repetitions >= 1;
}

void take_medians(Probe& p) {
    std::vector<double> w, c;
    for (const Sample& s : p.samples) {
        w.push_back(s.wall_ms);
        c.push_back(s.cpu_ms);
    }
    p.wall_ms = median(w);
    p.cpu_ms = median(c);
}

void print_times(const Probe (&probes)[3]) {
    std::printf("%-34s %10s %10s\n", "translation unit", "wall ms", "cpu ms");
    for (const Probe& p : probes) std::printf("%-34s %10.0f %10.0f\n", p.label, p.wall_ms, p.cpu_ms);
    const Probe &vkrc = probes[0], &raii = probes[1], &floor = probes[2];
    std::printf("%-34s %10.3f %10.3f   (goal: at most 0.080)\n", "ratio vkrc / vk::raii", vkrc.wall_ms / raii.wall_ms,
                vkrc.cpu_ms / raii.cpu_ms);
    std::printf("%-34s %10.3f %10.3f\n", "ratio floor / vk::raii", floor.wall_ms / raii.wall_ms,
                floor.cpu_ms / raii.cpu_ms);
}

double instruction_ratio(const Probe& p, const Probe& raii) {
    return double(p.instructions) / double(raii.instructions);
}

void print_instructions(const Probe (&probes)[3]) {
    std::printf("\n%-34s %10s\n", "compiler instructions, one compile", "millions");
    for (const Probe& p : probes) std::printf("%-34s %10.0f\n", p.label, double(p.instructions) / 1e6);
    std::printf("%-34s %10.3f   (goal: at most 0.080)\n", "instruction ratio vkrc / vk::raii",
                instruction_ratio(probes[0], probes[1]));
    std::printf("%-34s %10.3f\n", "instruction ratio floor / vk::raii", instruction_ratio(probes[2], probes[1]));
}

// The instruction columns come last and stay empty when not measured, so
// readers of the older columns keep working.
bool write_csv(const std::string& path, const Probe (&probes)[3], const std::string& flags, int repetitions) {
    std::ofstream out(path);
    out << "probe,compiler,flags,repetitions,wall_ms,cpu_ms,cpu_ratio_to_raii,wall_ratio_to_raii,instructions,"
           "instruction_ratio_to_raii\n";
    const Probe& raii = probes[1];
    for (const Probe& p : probes) {
        char row[160];
        std::snprintf(row, sizeof row, ",%d,%.0f,%.0f,%.3f,%.3f,", repetitions, p.wall_ms, p.cpu_ms,
                      p.cpu_ms / raii.cpu_ms, p.wall_ms / raii.wall_ms);
        out << p.name << ',' << VKRC_BENCH_CXX_COMPILER << ",\"" << flags << '"' << row;
        if (p.instructions) {
            std::snprintf(row, sizeof row, "%lld,%.3f", p.instructions, instruction_ratio(p, raii));
            out << row;
        } else {
            out << ',';
        }
        out << '\n';
    }
    return bool(out);
}

}  // namespace

int main(int argc, char** argv) {
    Options options;
    if (!parse(argc, argv, options)) {
        std::fputs(usage_text, stderr);
        return 2;
    }
    if (options.instructions && !on_path("valgrind")) {
        std::fprintf(stderr,
                     "header_cost: --instructions FAILED: valgrind not found in PATH (install the Debian "
                     "package valgrind, scripts/install-deps.sh does)\n");
        return 1;
    }
    std::vector<std::string> flags = split(VKRC_BENCH_CXX_FLAGS);
    flags.insert(flags.end(), options.extra_flags.begin(), options.extra_flags.end());

    // vkrc, vk::raii, and the floor: the headers vkrc's API names, no vkrc.
    Probe probes[] = {
        {"vkrc", "<vkrc/vkrc.hpp>, device", VKRC_BENCH_SOURCE_DIR "/vkrc_device.cpp", {}, {}, 0, 0, 0},
        {"vk::raii", "<vulkan/vulkan_raii.hpp>, device", VKRC_BENCH_SOURCE_DIR "/raii_device.cpp", {}, {}, 0, 0, 0},
        {"floor", "floor: std/Vulkan headers of API", VKRC_BENCH_SOURCE_DIR "/api_floor.cpp", {}, {}, 0, 0, 0}};
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
                VKRC_BENCH_CXX_COMPILER, VKRC_BENCH_FLAGS_ORIGIN, shown_flags.c_str(), options.repetitions);
    for (int r = 0; r < options.repetitions; ++r) {
        for (Probe& p : probes) p.samples.push_back(compile(p.args));
    }
    for (Probe& p : probes) take_medians(p);
    print_times(probes);
    if (options.instructions) {
        std::fflush(stdout);  // the times show while valgrind runs
        measure_instructions(probes);
        print_instructions(probes);
    }
    if (!options.csv.empty()) {
        std::string all_flags = shown_flags + " -std=c++20";
        all_flags.erase(0, all_flags.find_first_not_of(' '));
        if (!write_csv(options.csv, probes, all_flags, options.repetitions)) {
            std::fprintf(stderr, "header_cost: cannot write %s\n", options.csv.c_str());
            return 1;
        }
    }
    return 0;
}
