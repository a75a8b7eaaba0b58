#include "harness/plot.hpp"

#include "harness/stats.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stb/stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace teapot {
namespace {

struct Colour {
    std::uint8_t r, g, b;
};
constexpr Colour palette[] = {{31, 119, 180}, {255, 127, 14},  {44, 160, 44},
                              {214, 39, 40},  {148, 103, 189}, {140, 86, 75}};
constexpr Colour black{0, 0, 0}, grey{200, 200, 200};

class Canvas {
public:
    Canvas(int width, int height) : width_(width), height_(height), pixels_(std::size_t(width) * height * 4, 255) {}

    void fill(int x0, int y0, int x1, int y1, Colour c) {
        x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, width_), y1 = std::min(y1, height_);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                std::uint8_t* p = &pixels_[(std::size_t(y) * width_ + x) * 4];
                p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = 255;
            }
    }
    void hline(int x0, int x1, int y, Colour c, int thick = 1) {
        fill(std::min(x0, x1), y, std::max(x0, x1) + 1, y + thick, c);
    }
    void vline(int x, int y0, int y1, Colour c, int thick = 1) {
        fill(x, std::min(y0, y1), x + thick, std::max(y0, y1) + 1, c);
    }
    // A straight segment, stepping along its longer axis.
    void line(int x0, int y0, int x1, int y1, Colour c, int thick = 1) {
        const int steps = std::max({std::abs(x1 - x0), std::abs(y1 - y0), 1});
        for (int i = 0; i <= steps; ++i) {
            const int x = x0 + (x1 - x0) * i / steps, y = y0 + (y1 - y0) * i / steps;
            fill(x, y, x + thick, y + thick, c);
        }
    }

    // Text at twice stb_easy_font's size, top-left at (x, y).
    void text(int x, int y, const std::string& s, Colour c) {
        static char buffer[60000];
        std::vector<char> copy(s.begin(), s.end());
        copy.push_back('\0');
        int quads = stb_easy_font_print(0, 0, copy.data(), nullptr, buffer, sizeof buffer);
        for (int q = 0; q < quads; ++q) {
            const float* v = reinterpret_cast<const float*>(buffer + q * 64);
            // Vertices are 16 bytes apart: x, y, z, colour.
            float qx0 = v[0], qy0 = v[1], qx1 = v[8], qy1 = v[9];
            fill(x + int(2 * qx0), y + int(2 * qy0), x + int(2 * qx1), y + int(2 * qy1), c);
        }
    }
    static int text_width(const std::string& s) {
        std::vector<char> copy(s.begin(), s.end());
        copy.push_back('\0');
        return 2 * stb_easy_font_width(copy.data());
    }

    void save(const std::string& path) const {
        write_png(path, std::uint32_t(width_), std::uint32_t(height_), pixels_);
    }

private:
    int width_, height_;
    std::vector<std::uint8_t> pixels_;
};

std::string number(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, std::abs(v) >= 100 ? "%.0f" : std::abs(v) >= 10 ? "%.1f" : "%.2f", v);
    return buffer;
}

}  // namespace

void write_png(const std::string& path, std::uint32_t width, std::uint32_t height,
               const std::vector<std::uint8_t>& rgba) {
    if (!stbi_write_png(path.c_str(), int(width), int(height), 4, rgba.data(), int(width * 4)))
        throw std::runtime_error("cannot write " + path);
}

void write_histogram_png(const std::string& path, const std::string& title,
                         const std::vector<HistogramSeries>& series) {
    const int width = 900, height = 500, left = 70, right = 20, top = 50, bottom = 60;
    Canvas canvas(width, height);
    std::vector<double> all;
    for (const auto& s : series) all.insert(all.end(), s.samples.begin(), s.samples.end());
    double lo = quantile(all, 0.005), hi = quantile(all, 0.995);
    if (!(hi > lo)) hi = lo + 1.0;
    const int bins = 60;
    std::vector<std::vector<int>> counts(series.size(), std::vector<int>(bins, 0));
    int peak = 1;
    for (std::size_t s = 0; s < series.size(); ++s)
        for (double x : series[s].samples) {
            int b = int((x - lo) / (hi - lo) * bins);
            if (b < 0 || b >= bins) continue;
            peak = std::max(peak, ++counts[s][b]);
        }
    int plot_w = width - left - right, plot_h = height - top - bottom;
    canvas.text(left, 12, title, black);
    canvas.hline(left, left + plot_w, top + plot_h, black);
    canvas.vline(left, top, top + plot_h, black);
    for (int t = 0; t <= 4; ++t) {
        int x = left + plot_w * t / 4;
        canvas.vline(x, top + plot_h, top + plot_h + 5, black);
        std::string label = number(lo + (hi - lo) * t / 4);
        canvas.text(x - Canvas::text_width(label) / 2, top + plot_h + 10, label, black);
    }
    canvas.text(left + plot_w / 2 - 60, height - 22, "microseconds", black);
    canvas.text(4, top - 4, std::to_string(peak), black);
    canvas.text(4, top + plot_h - 14, "0", black);
    for (std::size_t s = 0; s < series.size(); ++s) {
        Colour c = palette[s % std::size(palette)];
        int previous_y = top + plot_h;
        for (int b = 0; b < bins; ++b) {
            int x0 = left + plot_w * b / bins, x1 = left + plot_w * (b + 1) / bins;
            int y = top + plot_h - int(double(counts[s][b]) / peak * plot_h);
            canvas.vline(x0, previous_y, y, c, 2);
            canvas.hline(x0, x1, y, c, 2);
            previous_y = y;
        }
        canvas.vline(left + plot_w, previous_y, top + plot_h, c, 2);
        int lx = width - right - 200, ly = top + 4 + int(s) * 18;
        canvas.fill(lx, ly + 2, lx + 14, ly + 12, c);
        canvas.text(lx + 20, ly, series[s].name, black);
    }
    canvas.save(path);
}

void write_ratio_png(const std::string& path, const std::string& title, const std::vector<std::string>& variants,
                     const std::vector<RatioBar>& bars) {
    std::vector<std::string> groups;
    for (const auto& bar : bars)
        if (std::find(groups.begin(), groups.end(), bar.group) == groups.end()) groups.push_back(bar.group);
    const int width = 1000, height = 500, left = 60, right = 20, top = 50, bottom = 60;
    Canvas canvas(width, height);
    double top_value = 1.2;
    for (const auto& bar : bars) top_value = std::max(top_value, std::max(bar.high, bar.ratio) * 1.1);
    int plot_w = width - left - right, plot_h = height - top - bottom;
    auto y_of = [&](double v) { return top + plot_h - int(std::clamp(v / top_value, 0.0, 1.0) * plot_h); };
    canvas.text(left, 12, title, black);
    for (int t = 0; t <= 4; ++t) {
        double v = top_value * t / 4;
        canvas.hline(left, left + plot_w, y_of(v), grey);
        canvas.text(4, y_of(v) - 7, number(v), black);
    }
    canvas.hline(left, left + plot_w, y_of(1.0), black, 2);
    canvas.vline(left, top, top + plot_h, black);
    int group_w = groups.empty() ? plot_w : plot_w / int(groups.size());
    int bar_w = std::max(4, (group_w - 16) / std::max<int>(1, int(variants.size())));
    for (std::size_t g = 0; g < groups.size(); ++g) {
        int gx = left + int(g) * group_w + 8;
        canvas.text(gx + (group_w - 16) / 2 - Canvas::text_width(groups[g]) / 2, top + plot_h + 10, groups[g], black);
        for (const auto& bar : bars) {
            if (bar.group != groups[g]) continue;
            auto v = std::find(variants.begin(), variants.end(), bar.variant) - variants.begin();
            Colour c = palette[std::size_t(v) % std::size(palette)];
            int x0 = gx + int(v) * bar_w, x1 = x0 + bar_w - 3;
            canvas.fill(x0, y_of(bar.ratio), x1, top + plot_h, c);
            int mid = (x0 + x1) / 2;
            canvas.vline(mid, y_of(bar.high), y_of(bar.low), black);
            canvas.hline(mid - 3, mid + 3, y_of(bar.high), black);
            canvas.hline(mid - 3, mid + 3, y_of(bar.low), black);
        }
    }
    for (std::size_t v = 0; v < variants.size(); ++v) {
        int lx = left + 10 + int(v) * 160, ly = height - 22;
        canvas.fill(lx, ly + 2, lx + 14, ly + 12, palette[v % std::size(palette)]);
        canvas.text(lx + 20, ly, variants[v], black);
    }
    canvas.save(path);
}

void write_speedup_png(const std::string& path, const std::string& title, const std::vector<SpeedupSeries>& series) {
    const int width = 1000, height = 560, left = 60, right = 240, top = 50, bottom = 60;
    Canvas canvas(width, height);
    int max_threads = 2;
    double top_value = 2;
    for (const SpeedupSeries& s : series)
        for (const SpeedupPoint& p : s.points) {
            max_threads = std::max(max_threads, p.threads);
            top_value = std::max(top_value, p.high * 1.1);
        }
    top_value = std::min(top_value, double(max_threads) * 1.2);  // the ideal bounds what is worth showing
    const int plot_w = width - left - right, plot_h = height - top - bottom;
    const double log_max = std::log2(double(max_threads));
    auto x_of = [&](int threads) { return left + int(std::log2(double(threads)) / log_max * plot_w); };
    auto y_of = [&](double v) { return top + plot_h - int(std::clamp(v / top_value, 0.0, 1.0) * plot_h); };
    canvas.text(left, 12, title, black);
    for (int t = 0; t <= 4; ++t) {
        const double v = top_value * t / 4;
        canvas.hline(left, left + plot_w, y_of(v), grey);
        canvas.text(4, y_of(v) - 7, number(v), black);
    }
    for (int n = 1; n <= max_threads; n *= 2) {
        canvas.vline(x_of(n), top + plot_h, top + plot_h + 5, black);
        canvas.text(x_of(n) - Canvas::text_width(std::to_string(n)) / 2, top + plot_h + 10, std::to_string(n), black);
    }
    canvas.text(left + plot_w / 2 - 30, height - 22, "threads", black);
    canvas.hline(left, left + plot_w, top + plot_h, black);
    canvas.vline(left, top, top + plot_h, black);
    for (int n = 1; n < max_threads; n *= 2)  // the ideal, speed-up = threads
        canvas.line(x_of(n), y_of(n), x_of(2 * n), y_of(std::min(2 * n, max_threads)), grey, 2);
    for (std::size_t s = 0; s < series.size(); ++s) {
        const Colour c = palette[s % std::size(palette)];
        const std::vector<SpeedupPoint>& points = series[s].points;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const int x = x_of(points[i].threads) + int(s) * 3 - int(series.size());  // whiskers side by side
            canvas.vline(x, y_of(points[i].high), y_of(points[i].low), c);
            canvas.fill(x - 3, y_of(points[i].ratio) - 3, x + 4, y_of(points[i].ratio) + 4, c);
            if (i)
                canvas.line(x_of(points[i - 1].threads), y_of(points[i - 1].ratio), x_of(points[i].threads),
                            y_of(points[i].ratio), c, 2);
        }
        const int lx = width - right + 20, ly = top + 4 + int(s) * 18;
        canvas.fill(lx, ly + 2, lx + 14, ly + 12, c);
        canvas.text(lx + 20, ly, series[s].variant, black);
    }
    canvas.save(path);
}

}  // namespace teapot
