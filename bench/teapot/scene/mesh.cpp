#include "scene/teapot_scene.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace teapot {
namespace {

// Splits text into lines and each line into numbers (commas or blanks).
class Reader {
public:
    explicit Reader(std::string_view text) : text_(text) {}

    std::vector<double> line() {
        while (pos_ < text_.size()) {
            std::size_t end = text_.find('\n', pos_);
            if (end == std::string_view::npos) end = text_.size();
            std::string_view l = text_.substr(pos_, end - pos_);
            pos_ = end + 1;
            ++line_no_;
            std::vector<double> values;
            std::size_t i = 0;
            while (i < l.size()) {
                if (l[i] == ',' || l[i] == ' ' || l[i] == '\t' || l[i] == '\r') {
                    ++i;
                    continue;
                }
                std::size_t j = i;
                while (j < l.size() && l[j] != ',' && l[j] != ' ' && l[j] != '\t' && l[j] != '\r') ++j;
                std::string token(l.substr(i, j - i));
                char* stop = nullptr;
                double value = std::strtod(token.c_str(), &stop);
                if (stop != token.c_str() + token.size() || !std::isfinite(value)) fail("bad number '" + token + "'");
                values.push_back(value);
                i = j;
            }
            if (!values.empty()) return values;
        }
        ++line_no_;
        fail("unexpected end of file");
    }

    [[noreturn]] void fail(const std::string& what) const {
        throw std::runtime_error("teapot::parse_patches: line " + std::to_string(line_no_) + ": " + what);
    }

    std::size_t count(const std::vector<double>& values) const {
        if (values.size() != 1 || values[0] < 1 || values[0] != std::floor(values[0]) || values[0] > 1e6)
            fail("expected a positive count");
        return static_cast<std::size_t>(values[0]);
    }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    int line_no_ = 0;
};

// Bernstein basis of degree 3 and its first derivative.
std::array<double, 4> bernstein(double t) {
    double s = 1.0 - t;
    return {s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t};
}
std::array<double, 4> bernstein_derivative(double t) {
    double s = 1.0 - t;
    return {-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t};
}

glm::dvec3 combine(const Patch& patch, const std::array<double, 4>& bu, const std::array<double, 4>& bv) {
    glm::dvec3 sum(0.0);
    for (int i = 0; i < 4; ++i) {
        glm::dvec3 row(0.0);
        for (int j = 0; j < 4; ++j) row += bv[j] * patch.p[i * 4 + j];
        sum += bu[i] * row;
    }
    return sum;
}

double patch_size(const Patch& patch) {
    glm::dvec3 lo = patch.p[0], hi = patch.p[0];
    for (const auto& q : patch.p) {
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    return glm::length(hi - lo);
}

}  // namespace

std::vector<Patch> parse_patches(std::string_view text) {
    Reader reader(text);
    std::size_t patch_count = reader.count(reader.line());
    std::vector<std::array<std::size_t, 16>> indices(patch_count);
    for (auto& patch : indices) {
        std::vector<double> values = reader.line();
        if (values.size() != 16) reader.fail("expected 16 control point indices");
        for (int k = 0; k < 16; ++k) {
            if (values[k] < 1 || values[k] != std::floor(values[k])) reader.fail("bad control point index");
            patch[k] = static_cast<std::size_t>(values[k]) - 1;
        }
    }
    std::size_t point_count = reader.count(reader.line());
    std::vector<glm::dvec3> points(point_count);
    for (auto& point : points) {
        std::vector<double> values = reader.line();
        if (values.size() != 3) reader.fail("expected x,y,z");
        point = {values[0], values[1], values[2]};
    }
    std::vector<Patch> patches(patch_count);
    for (std::size_t n = 0; n < patch_count; ++n) {
        for (int k = 0; k < 16; ++k) {
            if (indices[n][k] >= point_count)
                throw std::runtime_error("teapot::parse_patches: patch " + std::to_string(n + 1) + " uses point " +
                                         std::to_string(indices[n][k] + 1) + " of " + std::to_string(point_count));
            patches[n].p[k] = points[indices[n][k]];
        }
    }
    return patches;
}

const std::vector<Patch>& newell_teapot() {
    static const std::vector<Patch> patches = parse_patches(newell_teapot_text());
    return patches;
}

glm::dvec3 evaluate(const Patch& patch, double u, double v) { return combine(patch, bernstein(u), bernstein(v)); }

SurfacePoint evaluate_point(const Patch& patch, double u, double v) {
    auto bu = bernstein(u), bv = bernstein(v);
    auto du = bernstein_derivative(u), dv = bernstein_derivative(v);
    SurfacePoint s;
    s.position = combine(patch, bu, bv);
    s.du = combine(patch, du, bv);
    s.dv = combine(patch, bu, dv);
    glm::dvec3 n = glm::cross(s.du, s.dv);
    double scale = patch_size(patch);
    double tiny = 1e-9 * scale;
    if (glm::length(n) <= 1e-12 * scale * scale) {
        // One tangent vanishes along a collapsed edge. Near the edge at u0 the
        // vanishing tangent grows like (u - u0) * d2P/dudv, so the normal's
        // limit from inside the patch is the cross with the mixed derivative,
        // signed by the side the inside lies on.
        glm::dvec3 duv = combine(patch, du, dv);
        if (glm::length(s.dv) <= tiny) n = glm::cross(s.du, duv) * (u < 0.5 ? 1.0 : -1.0);
        else if (glm::length(s.du) <= tiny) n = glm::cross(duv, s.dv) * (v < 0.5 ? 1.0 : -1.0);
    }
    double length = glm::length(n);
    if (!(length > 0.0) || !std::isfinite(length)) {
        // Both tangents vanish (no such point on the teapot): step inside.
        SurfacePoint inner = evaluate_point(patch, u + (0.5 - u) * 1e-6, v + (0.5 - v) * 1e-6);
        s.normal = inner.normal;
        return s;
    }
    // Newell's patches are oriented so that dP/dv x dP/du points outwards.
    s.normal = -n / length;
    return s;
}

Mesh tessellate(std::span<const Patch> patches, int quads_per_edge) {
    if (quads_per_edge < 1)
        throw std::invalid_argument("teapot::tessellate: quads_per_edge is " + std::to_string(quads_per_edge));
    const int n = quads_per_edge;
    Mesh mesh;
    // Welding: cells of the tolerance's size; a vertex joins the first
    // earlier vertex within the tolerance in its own or a neighbouring cell,
    // so the result depends only on generation order.
    struct Key {
        std::int64_t x, y, z;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        std::size_t operator()(const Key& k) const {
            std::uint64_t h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ull;
            h ^= static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
            h ^= static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
            return static_cast<std::size_t>(h);
        }
    };
    std::unordered_map<Key, std::vector<std::uint32_t>, KeyHash> cells;
    std::vector<glm::dvec3> positions;
    std::vector<glm::dvec3> normal_sums;
    auto key_of = [](const glm::dvec3& p) {
        return Key{std::llround(p.x / weld_tolerance), std::llround(p.y / weld_tolerance),
                   std::llround(p.z / weld_tolerance)};
    };
    auto weld = [&](const glm::dvec3& p, const glm::dvec3& normal) -> std::uint32_t {
        Key k = key_of(p);
        std::uint32_t found = std::numeric_limits<std::uint32_t>::max();
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    auto it = cells.find(Key{k.x + dx, k.y + dy, k.z + dz});
                    if (it == cells.end()) continue;
                    for (std::uint32_t index : it->second)
                        if (index < found && glm::length(positions[index] - p) <= weld_tolerance) found = index;
                }
        if (found != std::numeric_limits<std::uint32_t>::max()) {
            normal_sums[found] += normal;
            return found;
        }
        auto index = static_cast<std::uint32_t>(positions.size());
        positions.push_back(p);
        normal_sums.push_back(normal);
        cells[k].push_back(index);
        return index;
    };

    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> grid((n + 1) * (n + 1));
    for (std::uint32_t patch_index = 0; patch_index < patches.size(); ++patch_index) {
        const Patch& patch = patches[patch_index];
        for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n; ++j) {
                SurfacePoint s = evaluate_point(patch, double(i) / n, double(j) / n);
                grid[i * (n + 1) + j] = weld(s.position, s.normal);
            }
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                // Corners in (u, v) order; wound so the outward side is
                // counter-clockwise seen from outside.
                std::uint32_t a = grid[i * (n + 1) + j], b = grid[(i + 1) * (n + 1) + j];
                std::uint32_t c = grid[(i + 1) * (n + 1) + j + 1], d = grid[i * (n + 1) + j + 1];
                glm::dvec2 ua(double(i) / n, double(j) / n), ub(double(i + 1) / n, double(j) / n);
                glm::dvec2 uc(double(i + 1) / n, double(j + 1) / n), ud(double(i) / n, double(j + 1) / n);
                indices.insert(indices.end(), {a, d, c, a, c, b});
                mesh.triangle_sources.push_back({patch_index, {ua, ud, uc}});
                mesh.triangle_sources.push_back({patch_index, {ua, uc, ub}});
            }
    }
    if (positions.size() > 65536)
        throw std::length_error("teapot::tessellate: " + std::to_string(positions.size()) +
                                " welded vertices do not fit 16-bit indices");
    mesh.positions.reserve(positions.size());
    mesh.normals.reserve(positions.size());
    for (std::size_t k = 0; k < positions.size(); ++k) {
        mesh.positions.emplace_back(positions[k]);
        // Seams between smooth patches average to the shared normal; the
        // sum cannot cancel on the teapot (no two welded samples face apart).
        mesh.normals.emplace_back(glm::normalize(normal_sums[k]));
    }
    mesh.indices.assign(indices.begin(), indices.end());
    return mesh;
}

GeometricError geometric_error(std::span<const Patch> patches, const Mesh& mesh, int samples_per_edge) {
    if (samples_per_edge < 1)
        throw std::invalid_argument("teapot::geometric_error: samples_per_edge is " + std::to_string(samples_per_edge));
    GeometricError error;
    double sum_squares = 0;
    const int s = samples_per_edge;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const auto& source = mesh.triangle_sources[t];
        glm::dvec3 corner[3];
        for (int k = 0; k < 3; ++k) corner[k] = glm::dvec3(mesh.positions[mesh.indices[3 * t + k]]);
        for (int i = 0; i <= s; ++i)
            for (int j = 0; j <= s - i; ++j) {
                double b1 = double(i) / s, b2 = double(j) / s, b0 = 1.0 - b1 - b2;
                glm::dvec3 on_mesh = b0 * corner[0] + b1 * corner[1] + b2 * corner[2];
                glm::dvec2 uv = b0 * source.uv[0] + b1 * source.uv[1] + b2 * source.uv[2];
                double d = glm::length(on_mesh - evaluate(patches[source.patch], uv.x, uv.y));
                error.max = std::max(error.max, d);
                sum_squares += d * d;
                ++error.samples;
            }
    }
    error.rms = error.samples ? std::sqrt(sum_squares / double(error.samples)) : 0.0;
    return error;
}

}  // namespace teapot
