#include "png.hpp"

#include <stdexcept>
#include <string>

// The implementations are compiled here, once, for every example.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace vkrc_examples {

void write_png(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
               std::span<const std::uint8_t> rgba) {
    if (rgba.size() != std::size_t(width) * height * 4) {
        throw std::runtime_error("write_png: " + std::to_string(rgba.size()) + " bytes for a " + std::to_string(width) +
                                 "x" + std::to_string(height) + " RGBA image");
    }
    if (!stbi_write_png(file.string().c_str(), int(width), int(height), 4, rgba.data(), int(width * 4))) {
        throw std::runtime_error("write_png: cannot write " + file.string());
    }
}

RgbaImage read_png(const std::filesystem::path& file) {
    int width = 0, height = 0, channels = 0;
    stbi_uc* data = stbi_load(file.string().c_str(), &width, &height, &channels, 4);
    if (!data) throw std::runtime_error("read_png: " + file.string() + ": " + stbi_failure_reason());
    RgbaImage image{std::uint32_t(width), std::uint32_t(height), {data, data + std::size_t(width) * height * 4}};
    stbi_image_free(data);
    return image;
}

}  // namespace vkrc_examples
