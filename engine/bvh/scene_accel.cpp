// Two-level scene acceleration structure (see scene_accel.h).
#include "engine/bvh/scene_accel.h"

#include <cmath>

#include "engine/bvh/aabb_ops.h"
#include "shaders/shared/intersect.h"

namespace nbvh {
namespace {

bool is_finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

// Inverse of an object->world matrix; false when singular or not finite.
bool safe_inverse(const glm::mat4& m, glm::mat4& inv) {
    if (!is_finite(m)) return false;
    const float det = glm::determinant(glm::mat3(m));
    if (!std::isfinite(det) || det == 0.0f) return false;
    inv = glm::inverse(m);
    return is_finite(inv);
}

Ray to_object(const glm::mat4& w2o, const Ray& ray) {
    return Ray{glm::vec3(w2o * glm::vec4(ray.org, 1.0f)), glm::vec3(w2o * glm::vec4(ray.dir, 0.0f))};
}

template <bool any>
bool intersect(const SceneAccel& accel, const Ray& ray, float tmin, float tmax, SceneHit& hit) {
    bool found = false;
    const Bvh& tlas = accel.tlas;
    traverse(tlas, ray, tmin, tmax, [&](uint32_t ni, float, float& t_max) {
        const BvhNode& n = tlas.nodes[ni];
        for (uint32_t k = n.first; k < n.first + n.count; ++k) {
            const uint32_t inst = tlas.prim_indices[k];
            const MeshBvh& blas = accel.meshes[accel.instance_mesh[inst]];
            const Ray local = to_object(accel.world_to_object[inst], ray);
            if (any) {
                if (intersect_any(blas, local, tmin, t_max)) {
                    found = true;
                    return true;
                }
            } else {
                Hit h;
                if (intersect_closest(blas, local, tmin, t_max, h)) {
                    found = true;
                    t_max = h.t;
                    hit = SceneHit{h.t, inst, h.triangle, h.u, h.v};
                }
            }
        }
        return false;
    });
    return found;
}

} // namespace

BvhBuildOptions default_tlas_options() {
    BvhBuildOptions o;
    o.max_leaf_size = 1;
    o.bin_count = 16;
    o.traversal_cost = 1.0f;
    return o;
}

namespace {

SceneAccel build(const Scene& scene, const BvhBuildOptions& blas_options, const BvhBuildOptions& tlas_options,
                 const std::vector<bool>& bounds_only) {
    SceneAccel accel;
    accel.meshes.reserve(scene.meshes.size());
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        if (m < bounds_only.size() && bounds_only[m]) {
            accel.meshes.push_back(bounds_only_mesh_bvh(mesh));
            continue;
        }
        accel.meshes.push_back(build_mesh_bvh(mesh, blas_options));
        accel.meshes.back().single_sided = single_sided_flags(mesh, accel.meshes.back(), scene.materials);
    }

    const size_t n = scene.instances.size();
    accel.object_to_world.resize(n);
    accel.world_to_object.assign(n, glm::mat4(0.0f));
    accel.instance_bounds.assign(n, Aabb{});
    accel.instance_mesh.assign(n, 0);
    for (size_t i = 0; i < n; ++i) {
        const Instance& inst = scene.instances[i];
        accel.object_to_world[i] = inst.object_to_world;
        accel.instance_mesh[i] = inst.mesh;
        if (inst.mesh >= accel.meshes.size() || accel.meshes[inst.mesh].empty()) continue;
        glm::mat4 inv;
        if (!safe_inverse(inst.object_to_world, inv)) continue;
        accel.world_to_object[i] = inv;
        Aabb wb = transform_bounds(inst.object_to_world, accel.meshes[inst.mesh].bounds());
        if (is_valid(wb)) accel.instance_bounds[i] = wb; // overflowing transforms are skipped
    }
    accel.tlas = build_bvh(accel.instance_bounds, tlas_options);
    return accel;
}

} // namespace

SceneAccel build_scene_accel(const Scene& scene, const BvhBuildOptions& blas_options,
                             const BvhBuildOptions& tlas_options) {
    return build(scene, blas_options, tlas_options, {});
}

SceneAccel build_scene_accel_bounds_only(const Scene& scene, const std::vector<bool>& bounds_only) {
    return build(scene, default_blas_options(), default_tlas_options(), bounds_only);
}

bool intersect_closest(const SceneAccel& accel, const Ray& ray, float tmin, float tmax, SceneHit& hit) {
    return intersect<false>(accel, ray, tmin, tmax, hit);
}

bool intersect_any(const SceneAccel& accel, const Ray& ray, float tmin, float tmax) {
    SceneHit h;
    return intersect<true>(accel, ray, tmin, tmax, h);
}

bool intersect_closest_brute_force(const Scene& scene, const Ray& ray, float tmin, float tmax, SceneHit& hit) {
    bool found = false;
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        glm::mat4 inv;
        if (inst.mesh >= scene.meshes.size() || !safe_inverse(inst.object_to_world, inv)) continue;
        Hit h;
        // Same object-space ray as the TLAS path, so both agree bit for bit.
        if (intersect_closest_brute_force(scene.meshes[inst.mesh], to_object(inv, ray), tmin, tmax, h, &scene.materials)) {
            found = true;
            tmax = h.t;
            hit = SceneHit{h.t, i, h.triangle, h.u, h.v};
        }
    }
    return found;
}

} // namespace nbvh
