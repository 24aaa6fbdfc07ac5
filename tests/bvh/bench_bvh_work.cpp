// Work per ray of the triangle BLAS: the binary GPU layout (to_gpu_layout, traversed as GLSL's
// NB_TRAVERSE_BVH does: nearest child first, the other pushed) against the 4-wide quantized layout
// (to_wide_layout, traversed by NB_TRAVERSE_WIDE itself). Counts, not timings, so any machine gives the
// GPU's numbers: nodes fetched, child boxes tested, leaves and triangles tested per ray. Rays: one camera
// ray per pixel (closest hit), from each hit one random ray back into the viewer's half-space (closest
// hit) and one any-hit ray towards a fixed sun direction. The TLAS is not counted (unchanged); every
// instance's BLAS is traversed with the ray in its object space. Exits non-zero if the layouts disagree.
// Usage: nbvh_bench_bvh_work [default|SCENE.glb] [width=320 height=180]
#include <cstdio>
#include <cstdlib>
#include <random>

#include "assets/default_scene.h"
#include "engine/bvh/scene_accel.h"
#include "engine/bvh/wide_bvh.h"
#include "engine/core/error.h"
#include "engine/scene/camera.h"
#include "engine/scene/gltf_loader.h"
#include "shaders/shared/intersect.h"

using namespace nbvh;

namespace {

struct Work {
    double rays = 0, nodes = 0, boxes = 0, leaves = 0, triangles = 0;
};

struct Blas {
    const MeshBvh* mesh;
    std::vector<GpuBvhNode> binary;
    std::vector<GpuWideNode> wide;
};

// NB_TRAVERSE_WIDE reads NODES[i]: this one counts the fetch and the child boxes it tests.
struct CountedWideNodes {
    const std::vector<GpuWideNode>* nodes;
    Work* work;
    GpuWideNode operator[](uint32_t i) const {
        const GpuWideNode n = (*nodes)[i];
        work->nodes += 1;
        for (uint32_t k = 0; k < NB_WIDE_ARITY; ++k) work->boxes += nb_wide_child(n, k) != NB_CHILD_NONE;
        return n;
    }
};

// One BLAS, closest (any = false) or any hit; narrows tmax. wide selects the layout.
bool trace_blas(const Blas& b, bool wide, glm::vec3 org, glm::vec3 dir, float& tmax, bool any, Work& w) {
    NbRayShear shear;
    if (!nb_ray_shear(dir, shear)) return false;
    const glm::vec3 inv_dir = nb_safe_inv_dir(dir);
    const glm::vec3* v = b.mesh->vertices.data();
    bool found = false, done = false;
    float tmin = 0.0f;
    auto leaf = [&](uint32_t first, uint32_t count) {
        w.leaves += 1;
        for (uint32_t k = first; k < first + count; ++k) {
            w.triangles += 1;
            float t, u, s;
            if (!nb_intersect_triangle_sheared(org, shear, v[3 * k], v[3 * k + 1], v[3 * k + 2], tmin, tmax, t, u, s))
                continue;
            tmax = t;
            found = true;
            if (any) {
                done = true;
                return;
            }
        }
    };
    if (wide) {
        const CountedWideNodes nodes{&b.wide, &w};
        NB_TRAVERSE_WIDE(nodes, 0u, org, inv_dir, tmin, tmax, done, leaf)
        return found;
    }
    uint32_t stack[NB_BVH_MAX_DEPTH + 1];
    uint32_t sp = 0, ref = 0;
    while (!done) {
        if (nb_is_leaf(ref)) {
            leaf(nb_leaf_first(ref), nb_leaf_count(ref));
            if (sp == 0) break;
            ref = stack[--sp];
            continue;
        }
        const GpuBvhNode& n = b.binary[ref];
        w.nodes += 1;
        w.boxes += 1 + (n.right != NB_CHILD_NONE);
        float tl = 0.0f, tr = 0.0f;
        const bool hl = n.left != NB_CHILD_NONE && nb_intersect_aabb(org, inv_dir, n.lmin, n.lmax, tmin, tmax, tl);
        const bool hr = n.right != NB_CHILD_NONE && nb_intersect_aabb(org, inv_dir, n.rmin, n.rmax, tmin, tmax, tr);
        if (hl && hr) {
            const bool left_first = tl <= tr;
            if (sp <= NB_BVH_MAX_DEPTH) stack[sp++] = left_first ? n.right : n.left;
            ref = left_first ? n.left : n.right;
        } else if (hl || hr) {
            ref = hl ? n.left : n.right;
        } else {
            if (sp == 0) break;
            ref = stack[--sp];
        }
    }
    return found;
}

} // namespace

int main(int argc, char** argv) try {
    const std::string name = argc > 1 ? argv[1] : "default";
    const int width = argc > 2 ? std::atoi(argv[2]) : 320, height = argc > 3 ? std::atoi(argv[3]) : 180;
    if (width <= 0 || height <= 0) throw Error("width and height must be positive");
    const Scene scene = name == "default" ? assets::make_default_scene() : load_gltf(name);
    const SceneAccel accel = build_scene_accel(scene);
    std::vector<Blas> blas(accel.meshes.size());
    for (size_t m = 0; m < blas.size(); ++m) {
        blas[m] = Blas{&accel.meshes[m], to_gpu_layout(accel.meshes[m].bvh), to_wide_layout(accel.meshes[m].bvh)};
        if (accel.meshes[m].triangle_count() >= 1000)
            std::printf("mesh %zu: %u triangles, %zu binary nodes, %zu wide nodes (%.2f)\n", m,
                        accel.meshes[m].triangle_count(), blas[m].binary.size(), blas[m].wide.size(),
                        double(blas[m].wide.size()) / double(blas[m].binary.size()));
    }
    const Camera cam = scene.has_camera ? scene.camera : auto_frame(scene, float(width) / float(height));
    const CameraBasis basis = camera_basis(cam);
    const float tan_half = std::tan(0.5f * cam.yfov), extent = glm::length(scene.world_bounds().extent());
    const glm::vec3 sun = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
    Work work[2][3]; // [binary, wide][camera, bounce, sun]
    size_t mismatches = 0;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    // Both layouts over every instance; returns the closest t (or -1) of the binary one.
    auto trace = [&](int kind, glm::vec3 o, glm::vec3 d, bool any) {
        float t[2] = {NB_INF, NB_INF};
        bool hit[2] = {false, false};
        for (int l = 0; l < 2; ++l) {
            work[l][kind].rays += 1;
            for (size_t i = 0; i < scene.instances.size() && !(any && hit[l]); ++i) {
                const uint32_t m = scene.instances[i].mesh;
                if (m >= blas.size() || accel.meshes[m].triangle_count() == 0) continue;
                const glm::vec3 oo(accel.world_to_object[i] * glm::vec4(o, 1.0f));
                const glm::vec3 od(accel.world_to_object[i] * glm::vec4(d, 0.0f));
                hit[l] |= trace_blas(blas[m], l == 1, oo, od, t[l], any, work[l][kind]);
            }
        }
        mismatches += hit[0] != hit[1] || (!any && t[0] != t[1]);
        return hit[0] ? t[0] : -1.0f;
    };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float px = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * tan_half * float(width) / float(height);
            const float py = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * tan_half;
            const glm::vec3 d = glm::normalize(basis.forward + px * basis.right + py * basis.up);
            const float t = trace(0, cam.eye, d, false);
            if (t < 0.0f) continue;
            const glm::vec3 p = cam.eye + t * d - d * (1e-5f * extent);
            glm::vec3 r;
            do r = glm::vec3(u(rng), u(rng), u(rng)); while (glm::dot(r, r) > 1.0f || glm::dot(r, r) < 1e-3f);
            r = glm::normalize(r);
            trace(1, p, glm::dot(r, d) > 0.0f ? -r : r, false);
            trace(2, p, sun, true);
        }
    const char* kinds[3] = {"camera (closest)", "bounce (closest)", "sun (any hit)"};
    std::printf("%s, %dx%d, per ray: nodes fetched | child boxes tested | leaves | triangles | node bytes\n", name.c_str(),
                width, height);
    for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 2; ++l) {
            const Work& w = work[l][k];
            const double n = std::max(w.rays, 1.0);
            std::printf("  %-17s %-6s %8.0f rays  %6.2f | %6.2f | %5.2f | %5.2f | %6.0f\n", kinds[k], l ? "wide" : "binary",
                        w.rays, w.nodes / n, w.boxes / n, w.leaves / n, w.triangles / n, 64.0 * w.nodes / n);
        }
    if (mismatches) {
        std::fprintf(stderr, "nbvh_bench_bvh_work: %zu rays differ between the layouts\n", mismatches);
        return 1;
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "nbvh_bench_bvh_work: %s\n", e.what());
    return 1;
}
