#include "assets/rope_knot.h"

#include <cmath>

#include "assets/procedural_mesh.h"
#include "engine/core/error.h"

namespace nbvh::assets {
namespace {

constexpr double TAU = 6.283185307179586;

// (2,3) torus knot, canonical units: r = cos 3φ + 2, P = (r cos 2φ, r sin 2φ, −sin 3φ).
// Minimum self-distance ≈ 1.66 and minimum radius of curvature ≈ 1.43, so any tube radius below
// ~0.8 cannot self-intersect.
glm::dvec3 knot_point(double phi) {
    const double r = std::cos(3.0 * phi) + 2.0;
    return {r * std::cos(2.0 * phi), r * std::sin(2.0 * phi), -std::sin(3.0 * phi)};
}

glm::dvec3 knot_tangent(double phi) {
    const double r = std::cos(3.0 * phi) + 2.0, dr = -3.0 * std::sin(3.0 * phi);
    return glm::normalize(glm::dvec3(dr * std::cos(2.0 * phi) - 2.0 * r * std::sin(2.0 * phi),
                                     dr * std::sin(2.0 * phi) + 2.0 * r * std::cos(2.0 * phi),
                                     -3.0 * std::cos(3.0 * phi)));
}

} // namespace

Mesh make_rope_knot(const RopeKnotParams& p, uint32_t material) {
    NBVH_CHECK(p.segments_along >= 8 && p.segments_around >= 4 && p.tube_radius > 0.0f && p.tube_radius < 0.8f);
    const uint32_t na = p.segments_along, nr = p.segments_around;
    Mesh m;
    m.name = "neural_rope_knot";
    m.positions.resize(size_t(na) * nr);
    m.uv0.resize(m.positions.size());
    for (uint32_t i = 0; i < na; ++i) {
        const double u = double(i) / double(na);
        const double phi = TAU * u;
        const glm::dvec3 c = knot_point(phi);
        const glm::dvec3 t = knot_tangent(phi);
        // The knot's tangent always has an xy component (|d(xy)/dφ| ≥ 2), so T × z is a smooth, periodic
        // frame with no Frenet flips.
        const glm::dvec3 n = glm::normalize(glm::cross(t, glm::dvec3(0, 0, 1)));
        const glm::dvec3 b = glm::cross(n, t);
        for (uint32_t j = 0; j < nr; ++j) {
            const double v = double(j) / double(nr);
            const double ang = TAU * v;
            // Rope profile: `strands` rounded lobes with V grooves, wound `twists` times along the loop,
            // plus fibre grooves running the other way (integer frequencies keep both seams closed).
            const double s = double(p.strands) * v + double(p.twists) * u;
            const double lobe = std::fabs(std::cos(3.141592653589793 * s));
            const double fibre = std::sin(TAU * (24.0 * v - 180.0 * u));
            const double radius = double(p.tube_radius) * (0.80 + 0.20 * std::sqrt(lobe) + 0.025 * fibre * lobe);
            const glm::dvec3 pos = c + radius * (std::cos(ang) * n + std::sin(ang) * b);
            m.positions[size_t(i) * nr + j] = glm::vec3(pos * double(p.scale));
            m.uv0[size_t(i) * nr + j] = glm::vec2(float(u), float(v));
        }
    }
    m.indices.reserve(size_t(na) * nr * 6);
    for (uint32_t i = 0; i < na; ++i) {
        const uint32_t i1 = (i + 1) % na;
        for (uint32_t j = 0; j < nr; ++j) {
            const uint32_t j1 = (j + 1) % nr;
            const uint32_t a = i * nr + j, b = i1 * nr + j, c = i1 * nr + j1, d = i * nr + j1;
            // Outward winding: (along) × (around) is the outward radial direction (t × b = n, t × n = −b).
            m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
        }
    }
    m.triangle_material.assign(m.indices.size() / 3, material);
    compute_smooth_normals(m);
    return m;
}

} // namespace nbvh::assets
