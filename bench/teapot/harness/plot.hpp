// PNG output of the benchmark: images, histograms and ratio bar charts drawn
// into an RGBA buffer (stb_image_write writes the file, stb_easy_font the
// labels).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace teapot {

// Writes width x height RGBA8 pixels, top row first. Throws on failure.
void write_png(const std::string& path, std::uint32_t width, std::uint32_t height,
               const std::vector<std::uint8_t>& rgba);

struct HistogramSeries {
    std::string name;
    std::vector<double> samples;  // microseconds
};
// Overlaid histograms (one outline per series) over a shared range from the
// 0.5% to the 99.5% quantile of all samples.
void write_histogram_png(const std::string& path, const std::string& title, const std::vector<HistogramSeries>& series);

struct RatioBar {
    std::string group;  // stage
    std::string variant;
    double ratio = 0, low = 0, high = 0;
};
// Grouped bars of ratios to raw with CI whiskers and a line at 1.
void write_ratio_png(const std::string& path, const std::string& title, const std::vector<std::string>& variants,
                     const std::vector<RatioBar>& bars);

struct SpeedupPoint {
    int threads = 1;
    double ratio = 1, low = 1, high = 1;
};
struct SpeedupSeries {
    std::string variant;
    std::vector<SpeedupPoint> points;  // by increasing thread count
};
// Speed-up against thread count (log2 axis), one line per variant with CI
// whiskers, and the ideal (speed-up = threads) in grey.
void write_speedup_png(const std::string& path, const std::string& title, const std::vector<SpeedupSeries>& series);

}  // namespace teapot
