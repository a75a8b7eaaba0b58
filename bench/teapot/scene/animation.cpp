#include "scene/teapot_scene.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace teapot {
namespace {

constexpr double pi = 3.14159265358979323846;
// Model space: Newell's teapot is z up, about 6.4 wide, 3.15 high; the
// world is y up. Each teapot sits in a cell this wide on a square grid.
constexpr double cell_size = 8.0;
constexpr double teapot_centre_z = 1.575;
constexpr double bob_amplitude = 1.0;

int grid_side(int count) {
    int side = 1;
    while (side * side < count) ++side;
    return side;
}

}  // namespace

double wrap_time(double t) {
    // fmod is exact, so the wrapped time carries no error of its own.
    double w = std::fmod(t, animation_period);
    return w < 0 ? w + animation_period : w;
}

glm::dmat3 teapot_rotation(int index, double t) {
    double w = wrap_time(t);
    // Spin about the vertical axis at (1 + index % 3) / 2 rad/s, plus a
    // rocking tilt about x: both harmonics of the 4 pi period.
    double spin = 0.5 * (1 + index % 3) * w + 0.7 * index;
    double tilt = 0.25 * std::sin(0.5 * w + index);
    double cs = std::cos(spin), ss = std::sin(spin), ct = std::cos(tilt), st = std::sin(tilt);
    glm::dmat3 spin_y(cs, 0, -ss, 0, 1, 0, ss, 0, cs);  // columns
    glm::dmat3 tilt_x(1, 0, 0, 0, ct, st, 0, -st, ct);
    glm::dmat3 z_up_to_y_up(1, 0, 0, 0, 0, -1, 0, 1, 0);  // model z -> world y
    return tilt_x * spin_y * z_up_to_y_up;
}

PushConstants teapot_draw(int index, int count, double t) {
    double w = wrap_time(t);
    int side = grid_side(count);
    int row = index / side, column = index % side;
    double offset = 0.5 * (side - 1) * cell_size;
    double bob = (index % 2 == 0 ? 1.0 : -1.0) * bob_amplitude * std::sin(w);
    glm::dvec3 position(column * cell_size - offset, offset - row * cell_size + bob, 0.0);
    glm::dmat3 r = teapot_rotation(index, t);
    // Rotate about the teapot's middle, not its base.
    glm::dvec3 translation = position - r * glm::dvec3(0, 0, teapot_centre_z);
    glm::dmat4 world(1.0);
    for (int c = 0; c < 3; ++c) world[c] = glm::dvec4(r[c], 0.0);
    world[3] = glm::dvec4(translation, 1.0);
    glm::dvec4 colour(0.55 + 0.45 * std::sin(0.5 * w + 0.9 * index),
                      0.55 + 0.45 * std::sin(1.0 * w + 2.1 * index + 2.0),
                      0.55 + 0.45 * std::sin(1.5 * w + 3.3 * index + 4.0), 1.0);
    return {glm::mat4(world), glm::vec4(colour)};
}

void animate(int count, double t, std::span<PushConstants> out) {
    for (int i = 0; i < count && std::size_t(i) < out.size(); ++i) out[i] = teapot_draw(i, count, t);
}

glm::mat4 view_matrix(int count) {
    int side = grid_side(count);
    double extent = side * cell_size;
    // Far enough that the grid's extent fits a 45 degree view, with room for
    // the bobbing and the teapots' depth.
    double distance = 0.55 * extent / std::tan(pi / 8.0) + 6.0;
    glm::dvec3 eye(0.0, 0.15 * distance, distance), target(0.0), up(0, 1, 0);
    glm::dvec3 f = glm::normalize(target - eye);
    glm::dvec3 s = glm::normalize(glm::cross(f, up));
    glm::dvec3 u = glm::cross(s, f);
    glm::dmat4 view(1.0);
    view[0] = glm::dvec4(s.x, u.x, -f.x, 0);
    view[1] = glm::dvec4(s.y, u.y, -f.y, 0);
    view[2] = glm::dvec4(s.z, u.z, -f.z, 0);
    view[3] = glm::dvec4(-glm::dot(s, eye), -glm::dot(u, eye), glm::dot(f, eye), 1);
    return glm::mat4(view);
}

glm::mat4 projection_matrix(double fov_short, double aspect, double near_plane, double far_plane) {
    if (!std::isfinite(aspect) || !(aspect > 0))
        throw std::invalid_argument("teapot::projection_matrix: aspect is " + std::to_string(aspect));
    if (!(fov_short > 0 && fov_short < pi))
        throw std::invalid_argument("teapot::projection_matrix: fov is " + std::to_string(fov_short));
    if (!std::isfinite(far_plane) || !(near_plane > 0 && near_plane < far_plane))
        throw std::invalid_argument("teapot::projection_matrix: need 0 < near < far");
    double f = 1.0 / std::tan(0.5 * fov_short);
    // The shorter side gets fov_short, the longer one a wider view, so both
    // scales stay at most f whatever the aspect.
    double sx = aspect >= 1 ? f / aspect : f;
    double sy = aspect >= 1 ? f : f * aspect;
    // Depth from range / (near - far) written as 1 / (near/far - 1): no
    // cancellation or overflow for near/far ratios down to the double limit.
    double a = far_plane / (near_plane - far_plane);
    double b = near_plane * a;
    glm::dmat4 p(0.0);
    p[0][0] = sx;
    p[1][1] = -sy;  // Vulkan's y points down
    p[2][2] = a;
    p[2][3] = -1.0;
    p[3][2] = b;
    return glm::mat4(p);
}

CameraUniforms camera(int count, std::uint32_t width, std::uint32_t height) {
    double aspect = double(width) / double(height);
    int side = grid_side(count);
    double far_plane = 4.0 * side * cell_size + 100.0;
    return {view_matrix(count), projection_matrix(pi / 4.0, aspect, 0.5, far_plane)};
}

CameraUniforms camera(int count, std::uint32_t width, std::uint32_t height, double t) {
    CameraUniforms c = camera(count, width, height);
    const double angle = 0.08 * std::sin(2.0 * pi * wrap_time(t) / animation_period);
    const double cs = std::cos(angle), sn = std::sin(angle);
    glm::dmat4 sway(1.0);  // rotation about the vertical axis through the grid's centre
    sway[0] = glm::dvec4(cs, 0, -sn, 0);
    sway[2] = glm::dvec4(sn, 0, cs, 0);
    c.view = glm::mat4(glm::dmat4(c.view) * sway);
    return c;
}

}  // namespace teapot
