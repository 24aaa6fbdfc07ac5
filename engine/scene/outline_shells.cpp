#include "engine/scene/outline_shells.h"

#include <cmath>

namespace nbvh {
namespace {

Aabb world_bounds_of(const Scene& scene, const Instance& inst) {
    Aabb b;
    const Aabb local = scene.meshes[inst.mesh].bounds();
    if (local.empty()) return b;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p((corner & 1) ? local.hi.x : local.lo.x, (corner & 2) ? local.hi.y : local.lo.y,
                          (corner & 4) ? local.hi.z : local.lo.z);
        b.grow(glm::vec3(inst.object_to_world * glm::vec4(p, 1.0f)));
    }
    return b;
}

bool all_single_sided(const Scene& scene, const Mesh& mesh) {
    if (mesh.triangle_material.empty()) return false;
    for (uint32_t m : mesh.triangle_material)
        if (m >= scene.materials.size() || scene.materials[m].double_sided) return false;
    return true;
}

} // namespace

float facing_score(const Mesh& mesh) {
    const Aabb b = mesh.bounds();
    if (b.empty()) return 0.0f;
    const glm::dvec3 c(b.center());
    double num = 0.0, den = 0.0;
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
        const uint32_t i0 = mesh.indices[3 * t], i1 = mesh.indices[3 * t + 1], i2 = mesh.indices[3 * t + 2];
        if (i0 >= mesh.positions.size() || i1 >= mesh.positions.size() || i2 >= mesh.positions.size())
            continue;
        const glm::dvec3 a(mesh.positions[i0]), p1(mesh.positions[i1]), p2(mesh.positions[i2]);
        const glm::dvec3 n = glm::cross(p1 - a, p2 - a); // counter-clockwise = front (glTF)
        const glm::dvec3 r = (a + p1 + p2) / 3.0 - c;
        num += glm::dot(n, r);
        den += glm::length(n) * glm::length(r);
    }
    return den > 0.0 && std::isfinite(num / den) ? float(num / den) : 0.0f;
}

std::vector<bool> find_outline_shells(const Scene& scene) {
    const size_t n = scene.instances.size();
    std::vector<bool> candidate(n, false), shell(n, false);
    std::vector<Aabb> bounds(n);
    std::vector<float> score(scene.meshes.size(), 2.0f); // 2: not computed yet
    for (size_t i = 0; i < n; ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh >= scene.meshes.size()) continue;
        bounds[i] = world_bounds_of(scene, inst);
        const Mesh& mesh = scene.meshes[inst.mesh];
        if (bounds[i].empty() || !all_single_sided(scene, mesh)) continue;
        if (score[inst.mesh] > 1.5f) score[inst.mesh] = facing_score(mesh);
        candidate[i] = score[inst.mesh] <= -OUTLINE_INWARD_SCORE;
    }
    for (size_t i = 0; i < n; ++i) {
        if (!candidate[i]) continue;
        const float diag = glm::length(bounds[i].extent());
        const glm::vec3 slack(0.02f * diag);
        for (size_t j = 0; j < n && !shell[i]; ++j) {
            if (j == i || candidate[j] || bounds[j].empty()) continue;
            const bool inside = glm::all(glm::greaterThanEqual(bounds[j].lo, bounds[i].lo - slack)) &&
                                glm::all(glm::lessThanEqual(bounds[j].hi, bounds[i].hi + slack));
            shell[i] = inside && glm::length(bounds[j].extent()) >= OUTLINE_ENCLOSED_FRACTION * diag;
        }
    }
    return shell;
}

} // namespace nbvh
