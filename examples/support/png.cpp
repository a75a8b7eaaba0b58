#include "png.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

namespace vkrc_examples {
namespace {

std::uint32_t crc32(std::span<const std::uint8_t> data, std::uint32_t crc = 0) {
    static const auto table = [] {
        std::array<std::uint32_t, 256> t{};
        for (std::uint32_t n = 0; n < 256; ++n) {
            std::uint32_t c = n;
            for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            t[n] = c;
        }
        return t;
    }();
    crc = ~crc;
    for (auto b : data) crc = table[(crc ^ b) & 0xFF] ^ (crc >> 8);
    return ~crc;
}

std::uint32_t adler32(std::span<const std::uint8_t> data) {
    std::uint32_t a = 1, b = 0;
    for (auto byte : data) {
        a = (a + byte) % 65521;
        b = (b + a) % 65521;
    }
    return (b << 16) | a;
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}
std::uint32_t get32(const std::uint8_t* p) {
    return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) | p[3];
}

void chunk(std::vector<std::uint8_t>& out, const char* type, std::span<const std::uint8_t> data) {
    put32(out, static_cast<std::uint32_t>(data.size()));
    std::size_t start = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    put32(out, crc32(std::span(out).subspan(start)));
}

constexpr std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

}  // namespace

void write_png(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
               std::span<const std::uint8_t> rgba) {
    if (rgba.size() != std::size_t(width) * height * 4) throw std::runtime_error("write_png: wrong pixel count");
    // Scanlines, each prefixed with filter type 0 (none).
    std::vector<std::uint8_t> raw;
    for (std::uint32_t y = 0; y < height; ++y) {
        raw.push_back(0);
        auto row = rgba.subspan(std::size_t(y) * width * 4, std::size_t(width) * 4);
        raw.insert(raw.end(), row.begin(), row.end());
    }
    // zlib stream of stored deflate blocks (at most 65535 bytes each).
    std::vector<std::uint8_t> z{0x78, 0x01};
    for (std::size_t pos = 0; pos < raw.size() || pos == 0; pos += 65535) {
        std::size_t n = std::min<std::size_t>(65535, raw.size() - pos);
        bool last = pos + n >= raw.size();
        z.push_back(last ? 1 : 0);
        z.push_back(static_cast<std::uint8_t>(n));
        z.push_back(static_cast<std::uint8_t>(n >> 8));
        z.push_back(static_cast<std::uint8_t>(~n));
        z.push_back(static_cast<std::uint8_t>(~n >> 8));
        z.insert(z.end(), raw.begin() + static_cast<std::ptrdiff_t>(pos), raw.begin() + static_cast<std::ptrdiff_t>(pos + n));
        if (last) break;
    }
    put32(z, adler32(raw));

    std::vector<std::uint8_t> png(signature, signature + 8);
    std::vector<std::uint8_t> header;
    put32(header, width);
    put32(header, height);
    header.insert(header.end(), {8, 6, 0, 0, 0});  // 8-bit RGBA, deflate, no filter variants, no interlace
    chunk(png, "IHDR", header);
    chunk(png, "IDAT", z);
    chunk(png, "IEND", {});
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
    if (!out) throw std::runtime_error("write_png: cannot write " + file.string());
}

RgbaImage read_png(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw std::runtime_error("read_png: cannot open " + file.string());
    std::vector<std::uint8_t> png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto fail = [&](const char* why) { return std::runtime_error("read_png: " + file.string() + ": " + why); };
    if (png.size() < 8 || std::memcmp(png.data(), signature, 8) != 0) throw fail("not a PNG");
    RgbaImage image;
    std::vector<std::uint8_t> z;
    for (std::size_t pos = 8; pos + 12 <= png.size();) {
        std::uint32_t length = get32(&png[pos]);
        if (pos + 12 + length > png.size()) throw fail("truncated chunk");
        std::string type(reinterpret_cast<const char*>(&png[pos + 4]), 4);
        const std::uint8_t* data = &png[pos + 8];
        if (crc32(std::span(&png[pos + 4], length + 4)) != get32(data + length)) throw fail("bad chunk CRC");
        if (type == "IHDR") {
            image.width = get32(data);
            image.height = get32(data + 4);
            if (data[8] != 8 || data[9] != 6 || data[12] != 0) throw fail("not 8-bit RGBA without interlace");
        } else if (type == "IDAT") {
            z.insert(z.end(), data, data + length);
        }
        pos += 12 + length;
    }
    // Undo the stored deflate blocks.
    std::vector<std::uint8_t> raw;
    std::size_t pos = 2;
    for (bool last = false; !last;) {
        if (pos + 5 > z.size()) throw fail("truncated deflate stream");
        if ((z[pos] & 0x06) != 0) throw fail("compressed deflate blocks are not supported");
        last = z[pos] & 1;
        std::size_t n = z[pos + 1] | (z[pos + 2] << 8);
        pos += 5;
        if (pos + n > z.size()) throw fail("truncated deflate block");
        raw.insert(raw.end(), z.begin() + static_cast<std::ptrdiff_t>(pos), z.begin() + static_cast<std::ptrdiff_t>(pos + n));
        pos += n;
    }
    std::size_t stride = std::size_t(image.width) * 4;
    if (raw.size() != (stride + 1) * image.height) throw fail("wrong image data size");
    for (std::uint32_t y = 0; y < image.height; ++y) {
        if (raw[y * (stride + 1)] != 0) throw fail("filtered scanlines are not supported");
        auto row = raw.begin() + static_cast<std::ptrdiff_t>(y * (stride + 1) + 1);
        image.pixels.insert(image.pixels.end(), row, row + static_cast<std::ptrdiff_t>(stride));
    }
    return image;
}

}  // namespace vkrc_examples
