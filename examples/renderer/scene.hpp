// examples/renderer's scene, free of Vulkan: where the teapots stand, the
// camera, the light and the streamed texture's steps. main.cpp renders it;
// support/renderer_check.cpp computes from it where a shadow must fall in
// the rendered image and which colour the streamed texture gives it.
#pragma once

#include "scene/teapot_scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <cstdint>

namespace renderer {

// The teapot is modelled z up; the scene is y up.
inline glm::mat4 z_up_to_y_up() { return glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), {1.0f, 0.0f, 0.0f}); }

struct Teapot {
    glm::vec3 position;  // of the base's centre, on the ground
    float scale;
    float yaw_degrees;
    std::uint32_t texture;
};
// Near to far, so their tessellation levels differ.
inline constexpr std::array<Teapot, 5> teapots = {{{{-5.0f, 0.0f, 4.0f}, 1.0f, 20.0f, 1},
                                                   {{3.0f, 0.0f, 1.0f}, 0.8f, -40.0f, 2},
                                                   {{-1.5f, 0.0f, -6.0f}, 1.2f, 75.0f, 2},
                                                   {{6.0f, 0.0f, -13.0f}, 1.5f, 160.0f, 1},
                                                   {{-9.0f, 0.0f, -24.0f}, 2.0f, 210.0f, 2}}};
inline constexpr float ground_half_size = 40.0f;  // the ground: a square about the origin, texture 0

// While it renders, the renderer streams material 2's texture out and a new
// one in every stream_every frames: frame n shows step n / stream_every.
// Often enough that a short headless run (the image check's) sees two
// steps, seldom enough that the uploads stay a small part of a frame.
inline constexpr std::uint32_t stream_every = 8, streamed_material = 2;
inline std::uint32_t streamed_step(std::uint32_t frame) { return frame / stream_every; }
// Step s (from 1) is stripes of this colour and a darker shade of it. Its
// strongest channel differs from the last step's (green, red, blue, green,
// ...; the first texture is blue), so the image check can tell which step
// an image shows.
inline std::array<std::uint8_t, 3> streamed_colour(std::uint32_t step) {
    constexpr std::array<std::array<std::uint8_t, 3>, 3> palette = {{{50, 190, 60}, {210, 70, 40}, {90, 60, 210}}};
    return palette[(step - 1) % palette.size()];
}

inline glm::mat4 teapot_world(const Teapot& t) {
    const glm::mat4 placed = glm::rotate(glm::translate(glm::mat4(1.0f), t.position), glm::radians(t.yaw_degrees),
                                         glm::vec3(0.0f, 1.0f, 0.0f));
    return glm::scale(placed, glm::vec3(t.scale)) * z_up_to_y_up();
}

inline const glm::vec3 camera_position{0.0f, 7.0f, 18.0f};
inline const glm::vec3 camera_target{0.0f, 0.0f, -4.0f};
inline constexpr double camera_fov = 0.87;  // radians across the shorter side
inline glm::mat4 view_projection(std::uint32_t width, std::uint32_t height) {
    return teapot::projection_matrix(camera_fov, double(width) / height, 0.5, 150.0) *
           glm::lookAt(camera_position, camera_target, {0.0f, 1.0f, 0.0f});
}

// Towards the light: low (35 degrees) from the left and a little behind, so
// that shadows fall long, to the right and towards the camera.
inline const glm::vec3 light_direction = glm::normalize(glm::vec3(-1.0f, 0.74f, -0.35f));
// An orthographic projection along the light covering the ground, depth 0..1.
inline glm::mat4 light_view_projection() {
    const glm::vec3 centre{0.0f, 0.0f, -8.0f};
    return glm::orthoRH_ZO(-34.0f, 34.0f, -34.0f, 34.0f, 1.0f, 120.0f) *
           glm::lookAt(centre + light_direction * 60.0f, centre, {0.0f, 1.0f, 0.0f});
}

}  // namespace renderer
