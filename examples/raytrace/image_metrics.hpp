// How far one 8-bit RGBA image is from another, free of Vulkan: what
// examples/raytrace reports for each render path against the rasterised
// reference. Only red, green and blue count (alpha is not shown).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>

namespace raytrace {

struct ImageDifference {
    std::size_t pixels = 0;                                    // compared
    std::size_t differing_pixels = 0;                          // with any of R, G, B different
    int max_channel_difference = 0;                            // 0..255
    double mean_squared_error = 0;                             // over every R, G and B value
    double psnr_db = std::numeric_limits<double>::infinity();  // 10 log10(255^2 / MSE); infinite when equal
};

// a and b: row-major RGBA, 4 bytes a pixel, the same size. Throws
// std::invalid_argument when the sizes differ or are not whole pixels.
inline ImageDifference compare_images(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
    if (a.size() != b.size() || a.size() % 4 != 0)
        throw std::invalid_argument("raytrace::compare_images: images of " + std::to_string(a.size()) + " and " +
                                    std::to_string(b.size()) + " bytes (want the same size, 4 bytes a pixel)");
    ImageDifference d;
    d.pixels = a.size() / 4;
    double squares = 0;
    for (std::size_t p = 0; p < a.size(); p += 4) {
        bool differs = false;
        for (std::size_t c = 0; c < 3; ++c) {
            const int delta = std::abs(int(a[p + c]) - int(b[p + c]));
            differs |= delta != 0;
            d.max_channel_difference = std::max(d.max_channel_difference, delta);
            squares += double(delta) * delta;
        }
        d.differing_pixels += differs;
    }
    if (d.pixels == 0) return d;
    d.mean_squared_error = squares / double(3 * d.pixels);
    if (d.mean_squared_error > 0) d.psnr_db = 10.0 * std::log10(255.0 * 255.0 / d.mean_squared_error);
    return d;
}

// The largest difference a render path may have from the reference and still match it
// (the defaults: none). Differing pixels as a percentage of those compared, so that it holds
// for any extent.
struct ImageTolerance {
    double differing_percent = 0;
    int max_channel_difference = 0;
    double min_psnr_db = std::numeric_limits<double>::infinity();  // equal images have an infinite PSNR
};
inline bool within(const ImageDifference& d, const ImageTolerance& t) {
    return double(d.differing_pixels) <= t.differing_percent / 100.0 * double(d.pixels) &&
           d.max_channel_difference <= t.max_channel_difference && d.psnr_db >= t.min_psnr_db;
}

}  // namespace raytrace
