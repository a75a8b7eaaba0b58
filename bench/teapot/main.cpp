// The teapot draw-loop benchmark (issue 6): every variant draws the same
// scene; stage times are measured in interleaved blocks, summarized against
// raw with bootstrap intervals, and every variant's image is checked against
// raw's. Run with --help for the options.
#include "harness/plot.hpp"
#include "harness/stats.hpp"
#include "harness/variant.hpp"
#include "harness/window.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace teapot {
namespace {

constexpr const char* stage_names[] = {"preinit", "acquire", "uniform", "command", "submit",
                                       "present", "wait",    "update",  "frame"};
constexpr int stage_count = 9;             // preinit, the seven per-frame stages, their sum
constexpr int frame_stages = 7;            // acquire .. update
constexpr int frame_stage = 8;             // the sum of the seven
constexpr double frame_step = 1.0 / 60.0;  // simulated seconds per frame
constexpr double reference_time = 1.25;    // the image check's fixed time
constexpr int block_frames = 25;           // measured frames per variant per block
constexpr int warmup_frames = 30;          // per variant, before the first block
constexpr int preinit_rounds = 5;          // timed inits per variant
constexpr int finest_tessellation = 32;    // the image error's reference level

struct Options {
    int frames = 2500;
    std::vector<std::string> variants;
    Config config;
    bool sweep = false;
    std::string csv;
    std::string png_dir = "teapot_png";
};

[[noreturn]] void usage(const std::string& problem) {
    std::fprintf(stderr,
                 "teapot: %s\n"
                 "usage: teapot [--frames N] [--variants a,b,...] [--teapots N] [--frames-in-flight N]\n"
                 "              [--uniform-writes N] [--tessellation N] [--sweep] [--csv PATH]\n"
                 "              [--png-dir DIR] [--size WxH] [--validation] [--window]\n"
                 "--window: each variant presents to its own window through a swapchain (needs a display,\n"
                 "          e.g. tests/with_xvfb.sh); the default renders headless into a ring of images\n"
                 "variants:",
                 problem.c_str());
    for (const auto& entry : variant_registry()) std::fprintf(stderr, " %s", std::string(entry.name).c_str());
    std::fprintf(stderr, "\n");
    std::exit(2);
}

int positive(const std::string& option, const std::string& value) {
    char* end = nullptr;
    long v = std::strtol(value.c_str(), &end, 10);
    if (*end != '\0' || v < 1 || v > 1000000) usage(option + " needs a positive integer, not '" + value + "'");
    return int(v);
}

Options parse(int argc, char** argv) {
    Options o;
    for (const auto& entry : variant_registry()) o.variants.emplace_back(entry.name);
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage(a + " needs a value");
            return argv[++i];
        };
        if (a == "--frames") o.frames = positive(a, value());
        else if (a == "--variants") {
            o.variants.clear();
            std::stringstream list(value());
            for (std::string name; std::getline(list, name, ',');) {
                bool known = false;
                for (const auto& entry : variant_registry()) known |= entry.name == name;
                if (!known) usage("unknown variant '" + name + "'");
                if (std::find(o.variants.begin(), o.variants.end(), name) == o.variants.end())
                    o.variants.push_back(name);
            }
            if (o.variants.empty()) usage("--variants is empty");
        } else if (a == "--teapots") o.config.teapots = positive(a, value());
        else if (a == "--frames-in-flight") o.config.frames_in_flight = positive(a, value());
        else if (a == "--uniform-writes") o.config.uniform_writes = positive(a, value());
        else if (a == "--tessellation") o.config.tessellation = positive(a, value());
        else if (a == "--sweep") o.sweep = true;
        else if (a == "--csv") o.csv = value();
        else if (a == "--png-dir") o.png_dir = value();
        else if (a == "--size") {
            std::string v = value();
            auto x = v.find('x');
            if (x == std::string::npos) usage("--size needs WxH");
            o.config.width = std::uint32_t(positive(a, v.substr(0, x)));
            o.config.height = std::uint32_t(positive(a, v.substr(x + 1)));
        } else if (a == "--validation") o.config.validation = true;
        else if (a == "--window") o.config.window = true;
        else if (a == "--help" || a == "-h") usage("help");
        else usage("unknown option '" + a + "'");
    }
    // The reference variant comes first so every ratio has its denominator.
    std::stable_partition(o.variants.begin(), o.variants.end(),
                          [](const std::string& n) { return n == variant_registry().front().name; });
    return o;
}

std::string config_tag(const Config& c) {
    char tag[64];
    std::snprintf(tag, sizeof tag, "t%d_f%d_u%d_s%d", c.teapots, c.frames_in_flight, c.uniform_writes, c.tessellation);
    return tag;
}

struct VariantResult {
    std::string name;
    std::vector<double> stage_us[stage_count];  // preinit holds preinit_rounds samples
    std::vector<std::uint8_t> image;
    std::string presentation;
    std::size_t differing_pixels = 0;
    int max_channel_difference = 0;
};

struct ConfigResult {
    Config config;
    int frames = 0;
    std::vector<VariantResult> variants;
    std::optional<GeometricError> geometric;
    double error_pixels = 0;  // geometric max error projected to pixels
    std::optional<std::size_t> image_error_pixels;
    int image_error_channel = 0;
};

std::pair<std::size_t, int> compare_images(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    if (a.size() != b.size()) return {a.size() / 4, 255};
    std::size_t differing = 0;
    int max_difference = 0;
    for (std::size_t p = 0; p < a.size(); p += 4) {
        int d = 0;
        for (int c = 0; c < 4; ++c) d = std::max(d, std::abs(int(a[p + c]) - int(b[p + c])));
        if (d) ++differing;
        max_difference = std::max(max_difference, d);
    }
    return {differing, max_difference};
}

// Pixels per model unit at the teapot nearest the camera, at t = 0: what
// turns a geometric error into an on-screen one.
double pixels_per_unit(const Config& c) {
    CameraUniforms cam = camera(c.teapots, c.width, c.height);
    double nearest = 1e300;
    for (int i = 0; i < c.teapots; ++i) {
        glm::vec4 eye = cam.view * teapot_draw(i, c.teapots, 0.0).world * glm::vec4(0, 0, 1.575f, 1);
        nearest = std::min(nearest, double(-eye.z) - 3.5);  // bounding radius of the teapot
    }
    return 0.5 * c.height * std::abs(cam.proj[1][1]) / std::max(nearest, 1e-3);
}

class Progress {
public:
    explicit Progress(std::string label) : label_(std::move(label)), tty_(isatty(2)) {}
    void show(int done, int total) {
        if (!tty_) return;
        std::fprintf(stderr, "\r%s %3d%%", label_.c_str(), total ? 100 * done / total : 100);
        std::fflush(stderr);
    }
    ~Progress() {
        if (tty_) std::fprintf(stderr, "\r%*s\r", int(label_.size()) + 6, "");
    }

private:
    std::string label_;
    bool tty_;
};

ConfigResult run_configuration(const Options& options, const Config& config, int frames, std::map<int, Mesh>& meshes,
                               int index, int total) {
    using clock = std::chrono::steady_clock;
    auto mesh_it = meshes.find(config.tessellation);
    if (mesh_it == meshes.end())
        mesh_it = meshes.emplace(config.tessellation, tessellate(newell_teapot(), config.tessellation)).first;
    SceneData scene{&mesh_it->second, camera(config.teapots, config.width, config.height)};

    ConfigResult result;
    result.config = config;
    result.frames = frames;
    std::vector<std::unique_ptr<Variant>> variants(options.variants.size());
    std::vector<std::uint64_t> frame_counters(options.variants.size(), 0);
    for (const std::string& name : options.variants) {
        VariantResult r;
        r.name = name;
        result.variants.push_back(std::move(r));
    }
    // preinit: an untimed round first (the process's first instance pays for
    // loading the driver), then preinit_rounds timed ones in rotating order,
    // tearing down all but the last round's variants.
    for (int round = 0; round <= preinit_rounds; ++round)
        for (std::size_t k = 0; k < variants.size(); ++k) {
            std::size_t v = (k + std::size_t(round)) % variants.size();
            variants[v].reset();
            for (const auto& entry : variant_registry())
                if (entry.name == options.variants[v]) variants[v] = entry.make();
            auto start = clock::now();
            variants[v]->init(config, scene);
            double us = std::chrono::duration<double, std::micro>(clock::now() - start).count();
            if (round > 0) result.variants[v].stage_us[0].push_back(us);
        }

    // One frame of variant v; records its stages unless discarded.
    auto run_frame = [&](std::size_t v, bool record) {
        Variant& variant = *variants[v];
        double t_next = double(++frame_counters[v]) * frame_step;
        clock::time_point marks[frame_stages + 1];
        marks[0] = clock::now();
        variant.acquire();
        marks[1] = clock::now();
        variant.uniform();
        marks[2] = clock::now();
        variant.command();
        marks[3] = clock::now();
        variant.submit();
        marks[4] = clock::now();
        variant.present();
        marks[5] = clock::now();
        variant.wait();
        marks[6] = clock::now();
        variant.update(t_next);
        marks[7] = clock::now();
        if (!record) return;
        auto& stages = result.variants[v].stage_us;
        for (int s = 0; s < frame_stages; ++s)
            stages[s + 1].push_back(std::chrono::duration<double, std::micro>(marks[s + 1] - marks[s]).count());
        stages[frame_stage].push_back(std::chrono::duration<double, std::micro>(marks[7] - marks[0]).count());
    };

    // Windowed: the variant about to run goes on top (harness/window.hpp says why).
    auto bring_to_front = [&](std::size_t v) {
        if (!config.window) return;
        variants[v]->window()->raise();
        poll_window_events();
    };

    Progress progress("[" + std::to_string(index + 1) + "/" + std::to_string(total) + "] " + config_tag(config));
    for (std::size_t v = 0; v < variants.size(); ++v) {
        bring_to_front(v);
        variants[v]->update(0.0);
        for (int f = 0; f < warmup_frames; ++f) run_frame(v, false);
        variants[v]->drain();
    }
    // Interleaved blocks, the starting variant rotating from block to block
    // so that no variant always follows the same one. Each block begins on
    // an idle device, so its first frames_in_flight frames (refilling the
    // queue) are discarded too.
    int blocks = (frames + block_frames - 1) / block_frames;
    for (int b = 0; b < blocks; ++b) {
        int in_block = std::min(block_frames, frames - b * block_frames);
        for (std::size_t k = 0; k < variants.size(); ++k) {
            std::size_t v = (k + std::size_t(b)) % variants.size();
            bring_to_front(v);  // untimed, between blocks
            for (int f = 0; f < config.frames_in_flight; ++f) run_frame(v, false);
            for (int f = 0; f < in_block; ++f) run_frame(v, true);
            variants[v]->drain();
        }
        progress.show(b + 1, blocks);
    }

    for (std::size_t v = 0; v < variants.size(); ++v) {
        result.variants[v].presentation = variants[v]->presentation();
        result.variants[v].image = variants[v]->render_reference_frame(reference_time);
        auto [differing, channel] = compare_images(result.variants[v].image, result.variants[0].image);
        result.variants[v].differing_pixels = differing;
        result.variants[v].max_channel_difference = channel;
    }
    if (index == 0) std::printf("device: %s\n", variants[0]->device_name().c_str());
    variants.clear();  // teardown, inside the validation check
    return result;
}

void print_table(const ConfigResult& r) {
    const Config& c = r.config;
    std::printf(
        "\nteapots %d, frames in flight %d, uniform writes %d, tessellation %d (%zu triangles), %ux%u, "
        "%d frames per variant\n",
        c.teapots, c.frames_in_flight, c.uniform_writes, c.tessellation,
        std::size_t(2) * 32 * c.tessellation * c.tessellation, c.width, c.height, r.frames);
    std::printf("presentation: %s\n", r.variants[0].presentation.c_str());
    for (const VariantResult& v : r.variants)
        if (v.presentation != r.variants[0].presentation)
            std::printf("presentation of %s DIFFERS: %s\n", v.name.c_str(), v.presentation.c_str());
    std::printf("%-8s %-11s %11s %11s %11s %8s %19s\n", "stage", "variant", "median_us", "p5_us", "p95_us", "ratio",
                "95% CI");
    for (int s = 0; s < stage_count; ++s)
        for (const VariantResult& v : r.variants) {
            Summary sum = summarize(v.stage_us[s]);
            Ratio ratio = bootstrap_ratio(v.stage_us[s], r.variants[0].stage_us[s]);
            std::printf("%-8s %-11s %11.2f %11.2f %11.2f %8.3f   [%6.3f, %6.3f]\n", stage_names[s], v.name.c_str(),
                        sum.median, sum.p5, sum.p95, ratio.ratio, ratio.low, ratio.high);
        }
    for (const VariantResult& v : r.variants)
        std::printf("image    %-11s %s (%zu pixels differ from %s, max channel difference %d)\n", v.name.c_str(),
                    v.differing_pixels == 0 ? "identical" : "DIFFERS", v.differing_pixels, r.variants[0].name.c_str(),
                    v.max_channel_difference);
    if (r.geometric)
        std::printf("geometric error: max %.3g, rms %.3g model units; max %.3g pixels at the nearest teapot\n",
                    r.geometric->max, r.geometric->rms, r.error_pixels);
}

// The columns first, then the speed-against-error columns (filled
// for the configurations that vary only the tessellation). frames is the
// number of samples behind the row: preinit_rounds for preinit.
void write_csv(const std::string& path, const std::vector<ConfigResult>& results) {
    std::ofstream out(path);
    if (!out) throw std::runtime_error("cannot write " + path);
    out << "variant,stage,teapots,frames_in_flight,uniform_writes,tessellation,frames,median_us,p5_us,p95_us,"
           "ratio_to_raw,ratio_ci_low,ratio_ci_high,geometric_max_error,geometric_rms_error,geometric_max_error_px,"
           "image_error_pixels,image_error_max_channel\n";
    char line[512];
    for (const ConfigResult& r : results) {
        const Config& c = r.config;
        std::string extra = ",,,,,";
        if (r.geometric) {
            std::snprintf(line, sizeof line, ",%.6g,%.6g,%.6g,", r.geometric->max, r.geometric->rms, r.error_pixels);
            extra = line;
            extra += r.image_error_pixels
                         ? std::to_string(*r.image_error_pixels) + "," + std::to_string(r.image_error_channel)
                         : ",";
        }
        for (const VariantResult& v : r.variants) {
            for (int s = 0; s < stage_count; ++s) {
                Summary sum = summarize(v.stage_us[s]);
                Ratio ratio = bootstrap_ratio(v.stage_us[s], r.variants[0].stage_us[s]);
                std::snprintf(line, sizeof line, "%s,%s,%d,%d,%d,%d,%zu,%.3f,%.3f,%.3f,%.4f,%.4f,%.4f", v.name.c_str(),
                              stage_names[s], c.teapots, c.frames_in_flight, c.uniform_writes, c.tessellation,
                              v.stage_us[s].size(), sum.median, sum.p5, sum.p95, ratio.ratio, ratio.low, ratio.high);
                out << line << extra << "\n";
            }
            // The image check: median_us holds the number of differing pixels.
            std::snprintf(line, sizeof line, "%s,image,%d,%d,%d,%d,1,%zu,,,,,", v.name.c_str(), c.teapots,
                          c.frames_in_flight, c.uniform_writes, c.tessellation, v.differing_pixels);
            out << line << extra << "\n";
        }
    }
}

void write_plots(const std::string& dir, const ConfigResult& r) {
    std::string tag = config_tag(r.config);
    for (int s = 1; s < stage_count; ++s) {
        std::vector<HistogramSeries> series;
        for (const VariantResult& v : r.variants) series.push_back({v.name, v.stage_us[s]});
        write_histogram_png(dir + "/hist_" + tag + "_" + stage_names[s] + ".png",
                            std::string(stage_names[s]) + " stage, " + tag + " (microseconds per frame)", series);
    }
    std::vector<std::string> names;
    std::vector<RatioBar> bars;
    for (const VariantResult& v : r.variants) names.push_back(v.name);
    for (int s = 0; s < stage_count; ++s)
        for (const VariantResult& v : r.variants) {
            Ratio ratio = bootstrap_ratio(v.stage_us[s], r.variants[0].stage_us[s]);
            bars.push_back({stage_names[s], v.name, ratio.ratio, ratio.low, ratio.high});
        }
    write_ratio_png(dir + "/ratios_" + tag + ".png",
                    "median stage time / " + r.variants[0].name + ", 95% bootstrap CI, " + tag, names, bars);
    for (const VariantResult& v : r.variants)
        write_png(dir + "/frame_" + tag + "_" + v.name + ".png", r.config.width, r.config.height, v.image);
}

int run(int argc, char** argv) {
    Options options = parse(argc, argv);
    std::filesystem::create_directories(options.png_dir);
    // GLFW for every window of the run (harness/window.hpp says why here).
    std::optional<GlfwSession> glfw;
    if (options.config.window) glfw.emplace();

    // The configurations: the one given, or the sweep, varying one setting
    // at a time from the given one. Larger scenes get proportionally fewer
    // frames (at least 40) so a sweep stays within minutes.
    std::vector<std::pair<Config, int>> plan;
    plan.push_back({options.config, options.frames});
    std::vector<int> tessellation_levels{options.config.tessellation};
    if (options.sweep) {
        auto add = [&](Config c) {
            for (const auto& [existing, f] : plan)
                if (config_tag(existing) == config_tag(c)) return;
            int scaled = std::max(40, int(std::int64_t(options.frames) * 25 / std::max(25, c.teapots)));
            plan.push_back({c, std::min(options.frames, scaled)});
        };
        for (int teapots : {25, 250, 2500}) {
            Config c = options.config;
            c.teapots = teapots;
            add(c);
        }
        for (int fif : {1, 2}) {
            Config c = options.config;
            c.frames_in_flight = fif;
            add(c);
        }
        for (int writes : {1, 1000}) {
            Config c = options.config;
            c.uniform_writes = writes;
            add(c);
        }
        tessellation_levels = {2, 4, 8, 16, 32};
        for (int level : tessellation_levels) {
            Config c = options.config;
            c.tessellation = level;
            add(c);
        }
    }

    std::map<int, Mesh> meshes;
    std::vector<ConfigResult> results;
    bool images_ok = true;
    bool presentation_ok = true;
    for (std::size_t i = 0; i < plan.size(); ++i) {
        results.push_back(run_configuration(options, plan[i].first, plan[i].second, meshes, int(i), int(plan.size())));
        for (const VariantResult& v : results.back().variants) {
            images_ok &= v.differing_pixels == 0;
            presentation_ok &= v.presentation == results.back().variants[0].presentation;
        }
    }

    // Speed against error: geometric error of every level run, and the image
    // error against the finest level's frame where that level was run.
    const ConfigResult* finest = nullptr;
    for (const ConfigResult& r : results)
        if (r.config.tessellation == finest_tessellation && config_tag(r.config) == [&] {
                Config c = options.config;
                c.tessellation = finest_tessellation;
                return config_tag(c);
            }())
            finest = &r;
    for (ConfigResult& r : results) {
        if (r.config.teapots != options.config.teapots ||
            r.config.frames_in_flight != options.config.frames_in_flight ||
            r.config.uniform_writes != options.config.uniform_writes)
            continue;
        r.geometric = geometric_error(newell_teapot(), meshes.at(r.config.tessellation));
        r.error_pixels = r.geometric->max * pixels_per_unit(r.config);
        if (finest) {
            auto [differing, channel] = compare_images(r.variants[0].image, finest->variants[0].image);
            r.image_error_pixels = differing;
            r.image_error_channel = channel;
        }
    }

    for (const ConfigResult& r : results) print_table(r);
    if (options.sweep) {
        std::printf("\nspeed against error (variant %s, %dx%d):\n", results[0].variants[0].name.c_str(),
                    options.config.width, options.config.height);
        std::printf("%5s %10s %12s %12s %12s %10s %14s %12s\n", "level", "triangles", "frame_us", "geom_max",
                    "geom_rms", "max_px", "pixels_differ", "max_channel");
        std::optional<int> budget_level;
        std::vector<const ConfigResult*> levels;
        for (const ConfigResult& r : results)
            if (r.geometric) levels.push_back(&r);
        std::sort(levels.begin(), levels.end(), [](const ConfigResult* a, const ConfigResult* b) {
            return a->config.tessellation < b->config.tessellation;
        });
        for (const ConfigResult* level : levels) {
            const ConfigResult& r = *level;
            Summary frame = summarize(r.variants[0].stage_us[frame_stage]);
            std::printf("%5d %10d %12.1f %12.3g %12.3g %10.3g %14zu %12d\n", r.config.tessellation,
                        64 * r.config.tessellation * r.config.tessellation, frame.median, r.geometric->max,
                        r.geometric->rms, r.error_pixels, r.image_error_pixels.value_or(0), r.image_error_channel);
            if (r.error_pixels <= 1.0 && (!budget_level || r.config.tessellation < *budget_level))
                budget_level = r.config.tessellation;
        }
        if (budget_level)
            std::printf(
                "a 1-pixel error budget at %ux%u needs tessellation %d (max geometric error <= 1 pixel at the "
                "nearest teapot)\n",
                options.config.width, options.config.height, *budget_level);
        else
            std::printf("no level run meets a 1-pixel error budget at %ux%u\n", options.config.width,
                        options.config.height);
    }

    if (!options.csv.empty()) write_csv(options.csv, results);
    for (const ConfigResult& r : results) write_plots(options.png_dir, r);
    std::printf("\nplots and frames in %s%s%s\n", options.png_dir.c_str(), options.csv.empty() ? "" : ", CSV in ",
                options.csv.c_str());

    int status = 0;
    if (!images_ok) {
        std::fprintf(stderr, "teapot: FAILED: a variant's image differs from %s's\n",
                     results[0].variants[0].name.c_str());
        status = 1;
    }
    if (!presentation_ok) {
        std::fprintf(stderr,
                     "teapot: FAILED: the variants present differently (format, mode, image count or extent)\n");
        status = 1;
    }
    if (validation_messages > 0) {
        std::fprintf(stderr, "teapot: FAILED: %d validation messages\n", validation_messages.load());
        status = 1;
    }
    return status;
}

}  // namespace
}  // namespace teapot

int main(int argc, char** argv) {
    try {
        return teapot::run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "teapot: error: %s\n", e.what());
        return 1;
    }
}
