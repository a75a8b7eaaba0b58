// The renderer example's image check, a test tool like png_check: checks an image
// written by `renderer --headless --frames FRAMES`:
//     renderer_check FILE.png [FRAMES]   (default 1)
// - the shadow: a ground point whose path to the light passes through the
//   nearest teapot's body is darker than a ground point further along the
//   same direction, beyond any shadow of that teapot (both computed from
//   scene.hpp and projected with the renderer's camera);
// - no NaN/inf pixel (the tone-map writes them magenta) and no black hole;
// - the tone-mapped range: deep shadows and highlights both present;
// - the streamed texture: the teapots of the streamed material show the
//   texture of the last frame's step (its strongest colour channel, which
//   differs from the step before's and the first texture's), so an image
//   that shows an older texture, or none, fails.
// Exit status 0 when every check passes.
#include "renderer/scene.hpp"
#include "support/png.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

namespace {

// The pixel world point p projects to; 2 pixels inside the image, for mean_colour.
glm::ivec2 pixel_of(const vkrc_examples::RgbaImage& image, glm::vec3 p, const char* what) {
    const glm::vec4 clip = renderer::view_projection(image.width, image.height) * glm::vec4(p, 1.0f);
    const int x = int((clip.x / clip.w * 0.5f + 0.5f) * float(image.width));
    const int y = int((clip.y / clip.w * 0.5f + 0.5f) * float(image.height));
    if (x < 2 || y < 2 || x + 2 >= int(image.width) || y + 2 >= int(image.height))
        throw std::runtime_error(std::string(what) + " is outside the image");
    return {x, y};
}

// The mean colour of the 5x5 pixels about pixel.
glm::dvec3 mean_colour(const vkrc_examples::RgbaImage& image, glm::ivec2 pixel) {
    glm::dvec3 sum{};
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
            const std::uint8_t* c = image.at(std::uint32_t(pixel.x + dx), std::uint32_t(pixel.y + dy));
            sum += glm::dvec3(c[0], c[1], c[2]);
        }
    return sum / 25.0;
}

// The mean luminance (0..255) of the 5x5 pixels about world point p.
double luminance_at(const vkrc_examples::RgbaImage& image, glm::vec3 p, const char* what) {
    const glm::ivec2 pixel = pixel_of(image, p, what);
    const double luminance = glm::dot(mean_colour(image, pixel), glm::dvec3(0.2126, 0.7152, 0.0722));
    std::printf("%s: world (%.2f, %.2f, %.2f), pixel (%d, %d), luminance %.1f\n", what, p.x, p.y, p.z, pixel.x, pixel.y,
                luminance);
    return luminance;
}

// Whether the near teapots of the streamed material show step's texture: where their axis 1.5
// model units up is seen (on the body, which hides the axis), the strongest channel must be the
// step's colour's (the first texture's, step 0, is blue) by a margin that lighting keeps.
int check_streamed(const vkrc_examples::RgbaImage& image, std::uint32_t step) {
    int expected = 2;
    if (step > 0) {
        const auto c = renderer::streamed_colour(step);
        expected = c[0] > c[1] && c[0] > c[2] ? 0 : c[1] > c[2] ? 1 : 2;
    }
    int failures = 0;
    for (std::size_t i = 0; i < 3; ++i) {  // the near three: the others are a few pixels
        const auto& t = renderer::teapots[i];
        if (t.texture != renderer::streamed_material) continue;
        const glm::dvec3 c =
            mean_colour(image, pixel_of(image, t.position + glm::vec3(0.0f, 1.5f * t.scale, 0.0f), "a teapot"));
        const double others = std::max(c[(expected + 1) % 3], c[(expected + 2) % 3]);
        const bool shows = c[expected] > 1.3 * others;
        std::printf("teapot %zu (streamed material, step %u): colour %.0f %.0f %.0f, channel %d %s\n", i, step, c.r,
                    c.g, c.b, expected, shows ? "strongest" : "NOT strongest by 1.3x");
        failures += !shows;
    }
    if (failures != 0) std::printf("FAIL: the streamed material does not show step %u's texture\n", step);
    return failures;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2 && argc != 3) {
        std::fprintf(stderr, "usage: %s FILE.png [FRAMES]\n", argv[0]);
        return 2;
    }
    try {
        const auto image = vkrc_examples::read_png(argv[1]);
        const auto frames = argc == 3 ? std::uint32_t(std::stoul(argv[2])) : 1u;
        if (frames == 0) throw std::runtime_error("FRAMES must be at least 1");
        int failures = 0;
        // The nearest teapot's axis at 2 units of its height lies inside its
        // body (radius about 1.5 there); the ground point seen from the light
        // through it is in shadow. Shadows fall along -light_direction; the
        // teapot's silhouette (body, spout, handle, knob) casts at most
        // 3.4 * scale from its axis plus 3.2 * scale of height over the
        // light's slope, so 2 more units of scale beyond that lies in light.
        const auto& t = renderer::teapots[0];
        const glm::vec3 l = renderer::light_direction;
        const glm::vec3 along = glm::normalize(glm::vec3(-l.x, 0.0f, -l.z));
        const float slope = l.y / glm::length(glm::vec2(l.x, l.z));
        const glm::vec3 shadowed = t.position + along * (2.0f * t.scale / slope);
        const glm::vec3 lit = t.position + along * (t.scale * (3.4f + 3.2f / slope + 2.0f));
        const double dark = luminance_at(image, shadowed, "shadowed ground"),
                     bright = luminance_at(image, lit, "lit ground");
        if (!(dark < 0.6 * bright)) {
            std::printf("FAIL: the shadowed point is not clearly darker than the lit one\n");
            ++failures;
        }
        std::size_t holes = 0;
        double low = 255, high = 0;
        for (std::uint32_t y = 0; y < image.height; ++y)
            for (std::uint32_t x = 0; x < image.width; ++x) {
                const std::uint8_t* c = image.at(x, y);
                holes += (c[0] == 255 && c[1] == 0 && c[2] == 255) || (c[0] == 0 && c[1] == 0 && c[2] == 0);
                const double v = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                low = std::min(low, v);
                high = std::max(high, v);
            }
        std::printf("%zu magenta/black pixels; luminance %.1f to %.1f\n", holes, low, high);
        if (holes != 0) {
            std::printf("FAIL: NaN/inf (magenta) or black pixels\n");
            ++failures;
        }
        if (!(low < 60 && high > 200)) {
            std::printf("FAIL: the tone-mapped range should reach below 60 and above 200\n");
            ++failures;
        }
        failures += check_streamed(image, renderer::streamed_step(frames - 1));
        return failures == 0 ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "renderer_check: %s\n", e.what());
        return 1;
    }
}
