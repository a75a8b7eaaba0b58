// A minimal PNG writer and reader for the examples: 8-bit RGBA, zlib "stored"
// (uncompressed) deflate blocks, no dependencies. The reader only reads what
// the writer writes (it is for checking the examples' output in tests).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace vkrc_examples {

struct RgbaImage {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::vector<std::uint8_t> pixels;  // row-major RGBA, 4 bytes per pixel

    const std::uint8_t* at(std::uint32_t x, std::uint32_t y) const { return &pixels[(std::size_t(y) * width + x) * 4]; }
};

// Throws std::runtime_error on I/O failure.
void write_png(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
               std::span<const std::uint8_t> rgba);
// Throws std::runtime_error for files write_png did not write.
RgbaImage read_png(const std::filesystem::path& file);

}  // namespace vkrc_examples
