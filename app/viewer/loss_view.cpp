#include "app/viewer/loss_view.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "engine/core/error.h"
#include "engine/render/neural_stage.h"
#include "engine/scene/camera.h"

namespace nbvh::viewer {

namespace {

float box_distance2(const Aabb& b, const glm::vec3& p) {
    const glm::vec3 d = glm::max(glm::max(b.lo - p, p - b.hi), glm::vec3(0.0f));
    return glm::dot(d, d);
}

uint32_t pack(float r, float g, float b) {
    auto byte = [](float v) { return uint32_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
    return byte(r) | (byte(g) << 8) | (byte(b) << 16) | 0xFF000000u;
}

} // namespace

uint32_t leaf_containing(const NbvhTree& tree, uint32_t root, uint32_t lod, const glm::vec3& p) {
    uint32_t n = root;
    while (!tree.is_leaf_at(n, lod)) {
        const uint32_t l = tree.node(n).left, r = l + 1;
        n = box_distance2(tree.node(l).bounds, p) <= box_distance2(tree.node(r).bounds, p) ? l : r;
    }
    return n;
}

uint32_t loss_colour(float t, float shade) {
    t = std::clamp(std::isfinite(t) ? t : 0.5f, 0.0f, 1.0f);
    // Piecewise linear through blue, cyan, green, yellow, red.
    static const glm::vec3 stops[5] = {{0.10f, 0.20f, 0.95f}, {0.05f, 0.85f, 0.95f}, {0.15f, 0.85f, 0.15f},
                                       {0.95f, 0.90f, 0.10f}, {0.95f, 0.10f, 0.05f}};
    const float x = t * 4.0f;
    const int i = std::min(3, int(x));
    const glm::vec3 c = glm::mix(stops[i], stops[i + 1], x - float(i)) * std::clamp(shade, 0.0f, 1.0f);
    return pack(c.r, c.g, c.b);
}

LossImage make_loss_image(render::WavefrontRenderer& hybrid, const ViewerScene& view,
                          const std::vector<float>& node_loss, const Camera& camera, uint32_t lod, uint32_t width,
                          uint32_t height) {
    NBVH_CHECK(view.model && node_loss.size() == view.model->nodes.size() && width > 0 && height > 0);
    const NeuralModel& model = *view.model;
    const NbvhTree tree = model.tree();
    lod = std::min(lod, std::max(1u, model.lod_count) - 1);
    // Pixel-centre rays, as passes/camera_rays.comp without the jitter.
    const CameraBasis basis = camera_basis(camera);
    const float tan_half = std::tan(0.5f * std::clamp(camera.yfov, 1.0e-3f, 3.1f));
    const float aspect = float(width) / float(height);
    const size_t pixels = size_t(width) * height;
    std::vector<glm::vec3> origins(pixels, camera.eye), dirs(pixels);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            const float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * aspect * tan_half;
            const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * tan_half;
            dirs[size_t(y) * width + x] = glm::normalize(basis.forward + sx * basis.right + sy * basis.up);
        }
    const std::vector<render::TraceHit> hits = hybrid.trace(origins, dirs);

    LossImage out;
    out.width = width;
    out.height = height;
    out.leaf_of_pixel.assign(pixels, UINT32_MAX);
    std::vector<float> shade(pixels, 1.0f);
    for (size_t i = 0; i < pixels; ++i) {
        const render::TraceHit& h = hits[i];
        if (!h.neural || h.instance >= view.scene.instances.size()) continue;
        const Instance& inst = view.scene.instances[h.instance];
        const int32_t a = render::asset_of_mesh(model, view.scene, inst.mesh);
        if (a < 0) continue;
        const ModelAsset& asset = model.assets[size_t(a)];
        const glm::vec3 world = origins[i] + h.t * dirs[i];
        const glm::vec3 object = glm::vec3(view.accel.world_to_object[h.instance] * glm::vec4(world, 1.0f));
        out.leaf_of_pixel[i] = leaf_containing(tree, asset.root, lod, object * asset.scale + asset.offset);
        shade[i] = 0.35f + 0.65f * std::fabs(glm::dot(h.normal, dirs[i]));
        out.neural_pixels++;
    }
    // The colour scale: log loss between the extremes of the leaves seen.
    std::set<uint32_t> seen(out.leaf_of_pixel.begin(), out.leaf_of_pixel.end());
    seen.erase(UINT32_MAX);
    out.leaves = uint32_t(seen.size());
    float lo = INFINITY, hi = -INFINITY;
    for (uint32_t n : seen)
        if (std::isfinite(node_loss[n]) && node_loss[n] > 0.0f) {
            lo = std::min(lo, node_loss[n]);
            hi = std::max(hi, node_loss[n]);
        }
    const bool any = lo <= hi;
    out.lo = any ? lo : 0.0f;
    out.hi = any ? hi : 0.0f;
    const float span = any && hi > lo ? std::log(hi / lo) : 0.0f;
    out.rgba8.assign(pixels, 0xFF000000u);
    for (size_t i = 0; i < pixels; ++i) {
        const uint32_t n = out.leaf_of_pixel[i];
        if (n == UINT32_MAX) {
            if (hits[i].instance != 0xFFFFFFFFu) out.rgba8[i] = pack(0.22f, 0.22f, 0.22f); // triangles
            continue;
        }
        const float l = node_loss[n];
        if (!(std::isfinite(l) && l > 0.0f)) {
            out.rgba8[i] = pack(0.9f * shade[i], 0.9f * shade[i], 0.9f * shade[i]); // never trained
            continue;
        }
        out.rgba8[i] = loss_colour(span > 0.0f ? std::log(l / lo) / span : 0.5f, shade[i]);
    }
    return out;
}

} // namespace nbvh::viewer
