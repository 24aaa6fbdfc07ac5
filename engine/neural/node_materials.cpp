#include "engine/neural/node_materials.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <glm/glm.hpp>

#include "engine/neural/asset_table.h"
#include "engine/neural/fp16.h"
#include "shaders/shared/neural_gpu.h"

namespace nbvh {

namespace {

// Area-weighted moments of (albedo, metallic, roughness) over a set of triangles, metallic and
// roughness as factor x texture. The normal equations of the fits are sums, so a subtree's moments are
// its children's sum.
struct Moments {
    double w = 0.0;
    glm::dvec3 c{0.0};                             // sum w * albedo
    glm::dmat3 cc{0.0};                            // sum w * albedo albedo^T
    glm::dvec2 y{0.0};                             // sum w * (metallic, roughness)
    glm::dvec3 cy[2] = {glm::dvec3(0.0), glm::dvec3(0.0)}; // sum w * albedo * metallic, ... * roughness
    glm::dvec3 yy{0.0};                            // sum w * (metallic^2, roughness^2, metallic roughness)
    void add(const Moments& o) {
        w += o.w;
        c += o.c;
        cc += o.cc;
        y += o.y;
        cy[0] += o.cy[0];
        cy[1] += o.cy[1];
        yy += o.yy;
    }
};

Moments triangle_moments(const Scene& scene, const Mesh& mesh, uint32_t t) {
    Material fallback; // an out-of-range material: asset_shading's defaults, the ground truth's albedo 0.9
    fallback.metallic = 0.0f;
    fallback.base_color = glm::vec4(0.9f, 0.9f, 0.9f, 1.0f);
    const uint32_t mat = t < mesh.triangle_material.size() ? mesh.triangle_material[t] : 0u;
    const Material& m = mat < scene.materials.size() ? scene.materials[mat] : fallback;
    MaterialPoint points[MATERIAL_POINTS];
    Moments x;
    const double area = triangle_material_points(scene, mesh, m, t, points);
    if (!(area > 0.0)) return x;
    const double w = area / MATERIAL_POINTS;
    for (const MaterialPoint& p : points) {
        const glm::dvec3 c(p.albedo);
        const glm::dvec2 y(double(p.metallic) * m.metallic, double(p.roughness) * m.roughness);
        x.w += w;
        x.c += w * c;
        x.cc += w * glm::outerProduct(c, c);
        x.y += w * y;
        x.cy[0] += (w * y.x) * c;
        x.cy[1] += (w * y.y) * c;
        x.yy += w * glm::dvec3(y.x * y.x, y.y * y.y, y.x * y.y);
    }
    return x;
}

// Moments of the subtrees of the base nodes in `wanted` (children before parents, iterative: only the
// open path's partial sums are kept).
std::unordered_map<uint32_t, Moments> subtree_moments(const Bvh& base, const Mesh& mesh, const Scene& scene,
                                                      const std::unordered_map<uint32_t, Moments>& wanted) {
    std::unordered_map<uint32_t, Moments> out = wanted;
    std::vector<Moments> values;
    std::vector<std::pair<uint32_t, bool>> stack{{0u, false}};
    while (!stack.empty()) {
        const auto [i, children_done] = stack.back();
        stack.pop_back();
        const BvhNode& n = base.nodes[i];
        const bool has_left = n.left < base.nodes.size(), has_right = n.right < base.nodes.size();
        Moments sum;
        if (n.is_leaf()) {
            for (uint32_t k = n.first; k < n.first + n.count && k < base.prim_indices.size(); ++k)
                sum.add(triangle_moments(scene, mesh, base.prim_indices[k]));
        } else if (!children_done) {
            stack.push_back({i, true});
            if (has_left) stack.push_back({n.left, false});
            if (has_right) stack.push_back({n.right, false});
            continue;
        } else {
            for (int k = int(has_left) + int(has_right); k > 0; --k) {
                sum.add(values.back());
                values.pop_back();
            }
        }
        if (auto it = out.find(i); it != out.end()) it->second = sum;
        values.push_back(sum);
    }
    return out;
}

// Metallic (k = 0) or roughness (k = 1) as a0 + a . albedo, ridge-regularised on a (centred least squares).
bool fit_output(const Moments& m, int k, float& a0, glm::vec3& a) {
    const glm::dvec3 cbar = m.c / m.w;
    const double ybar = m.y[k] / m.w;
    const glm::dmat3 cov = m.cc / m.w - glm::outerProduct(cbar, cbar) + glm::dmat3(NODE_MATERIAL_RIDGE);
    const glm::dvec3 b = m.cy[k] / m.w - cbar * ybar;
    const glm::dvec3 slope = glm::inverse(cov) * b;
    const double intercept = ybar - glm::dot(slope, cbar);
    a0 = float(intercept);
    a = glm::vec3(slope);
    // fp16 holds every coefficient (the ridge bounds them); anything else keeps the mean.
    return std::isfinite(intercept) && std::isfinite(slope.x + slope.y + slope.z) && std::abs(intercept) < 60000.0 &&
           std::abs(slope.x) < 60000.0 && std::abs(slope.y) < 60000.0 && std::abs(slope.z) < 60000.0;
}

// Second moments of the fits' residuals, E[(y_k - theta_k . x)(y_l - theta_l . x)] with x = (1, albedo):
// (metallic variance, roughness variance, their covariance).
glm::dvec3 residual_moments(const Moments& m, const glm::dvec4 theta[2]) {
    const glm::dvec3 cbar = m.c / m.w;
    const glm::dmat3 cc = m.cc / m.w;
    glm::dmat4 xx(1.0); // E[x x^T]
    for (int r = 0; r < 3; ++r) {
        xx[0][r + 1] = xx[r + 1][0] = cbar[r];
        for (int c = 0; c < 3; ++c) xx[c + 1][r + 1] = cc[c][r];
    }
    const glm::dvec4 xy[2] = {glm::dvec4(m.y.x / m.w, m.cy[0] / m.w), glm::dvec4(m.y.y / m.w, m.cy[1] / m.w)};
    const double yy[3] = {m.yy.x / m.w, m.yy.y / m.w, m.yy.z / m.w};
    auto second = [&](int k, int l, double ykl) {
        return ykl - glm::dot(theta[l], xy[k]) - glm::dot(theta[k], xy[l]) + glm::dot(theta[k], xx * theta[l]);
    };
    return {second(0, 0, yy[0]), second(1, 1, yy[1]), second(0, 1, yy[2])};
}

void pack_fit(const Moments& m, uint32_t out[NB_NODE_FIT_WORDS]) {
    auto pair = [](float lo, float hi) { return uint32_t(float_to_half_bits(lo)) | (uint32_t(float_to_half_bits(hi)) << 16); };
    glm::dvec4 theta[2];
    for (int k = 0; k < 2; ++k) {
        float a0;
        glm::vec3 a;
        if (!fit_output(m, k, a0, a)) { // the mean, or the defaults when even that is not finite
            const double mean = m.y[k] / m.w;
            a0 = std::isfinite(mean) ? float(std::clamp(mean, 0.0, 1.0)) : (k == 0 ? 0.0f : 1.0f);
            a = glm::vec3(0.0f);
        }
        out[2 * k] = pair(a0, a.x);
        out[2 * k + 1] = pair(a.y, a.z);
        theta[k] = glm::dvec4(a0, a);
    }
    // What the fit leaves: spread +-sigma per output, the roughness's sign that of the covariance (gold
    // trim smooth and metallic: the two move against each other). Non-finite: none.
    const glm::dvec3 r = residual_moments(m, theta);
    const double sm = std::sqrt(std::max(r.x, 0.0)), sr = std::sqrt(std::max(r.y, 0.0));
    const bool ok = std::isfinite(sm) && std::isfinite(sr) && std::isfinite(r.z) && sm < 2.0 && sr < 2.0;
    out[4] = ok ? pair(float(sm), float(r.z < 0.0 ? -sr : sr)) : 0u;
}

} // namespace

NodeMaterialTables build_node_materials(std::span<const NbvhNode> nodes, const Bvh& base, const Mesh& mesh,
                                        const Scene& scene) {
    std::unordered_map<uint32_t, Moments> wanted;
    for (const NbvhNode& n : nodes)
        if (n.base_node < base.nodes.size()) wanted[n.base_node] = Moments{};
    NodeMaterialTables t;
    if (wanted.empty() || base.empty()) return t;
    const std::unordered_map<uint32_t, Moments> moments = subtree_moments(base, mesh, scene, wanted);
    // Parents come before their children (model_file.h): a node without area inherits its parent's words.
    std::vector<uint32_t> parent(nodes.size(), NBVH_NO_CHILD);
    for (uint32_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].has_children() && nodes[i].left + 1 < nodes.size()) parent[nodes[i].left] = parent[nodes[i].left + 1] = i;
    t.means.assign(nodes.size(), nb_pack_node_material(0.0f, 1.0f));
    t.fits.assign(nodes.size() * NB_NODE_FIT_WORDS, 0u);
    const uint32_t one = uint32_t(float_to_half_bits(1.0f)); // roughness intercept 1, everything else 0
    for (uint32_t i = 0; i < nodes.size(); ++i) t.fits[size_t(i) * NB_NODE_FIT_WORDS + 2] = one;
    for (uint32_t i = 0; i < nodes.size(); ++i) {
        uint32_t* fit = &t.fits[size_t(i) * NB_NODE_FIT_WORDS];
        const auto it = moments.find(nodes[i].base_node);
        if (it != moments.end() && it->second.w > 0.0) {
            const Moments& m = it->second;
            t.means[i] = nb_pack_node_material(float(m.y.x / m.w), float(m.y.y / m.w));
            pack_fit(m, fit);
        } else if (parent[i] < i) {
            t.means[i] = t.means[parent[i]];
            for (uint32_t k = 0; k < NB_NODE_FIT_WORDS; ++k) fit[k] = t.fits[size_t(parent[i]) * NB_NODE_FIT_WORDS + k];
        }
    }
    return t;
}

} // namespace nbvh
