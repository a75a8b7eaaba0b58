// PNG files for the examples: 8-bit RGBA, written and read with stb
// (stb_image_write.h and stb_image.h from Debian's libstb-dev).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <vector>

namespace vkrc_examples {

struct RgbaImage {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::vector<std::uint8_t> pixels;  // row-major RGBA, 4 bytes per pixel

    const std::uint8_t* at(std::uint32_t x, std::uint32_t y) const { return &pixels[(std::size_t(y) * width + x) * 4]; }
};

// Throws std::runtime_error on I/O failure or when rgba is not width * height * 4 bytes.
void write_png(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
               std::span<const std::uint8_t> rgba);
// Any PNG, converted to RGBA. Throws std::runtime_error when it cannot be read.
RgbaImage read_png(const std::filesystem::path& file);

}  // namespace vkrc_examples
