#include "trainer/training_asset.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {

uint32_t pick_neural_mesh(const Scene& scene) {
    int64_t best = -1;
    uint32_t best_tris = 0;
    for (const Instance& inst : scene.instances) {
        if (!inst.neural || inst.mesh >= scene.meshes.size()) continue;
        const uint32_t tris = scene.meshes[inst.mesh].triangle_count();
        if (best < 0 || tris > best_tris) {
            best = inst.mesh;
            best_tris = tris;
        }
    }
    if (best < 0) throw Error("the scene has no neural asset (name a glTF scene '*_neural' or pass --neural GLOB)");
    if (best_tris == 0) throw Error(strfmt("neural mesh '%s' has no triangles", scene.meshes[size_t(best)].name.c_str()));
    return uint32_t(best);
}

TrainingAsset make_training_asset(const Scene& scene, uint32_t mesh_index) {
    NBVH_CHECK(mesh_index < scene.meshes.size());
    TrainingAsset a;
    a.scene = &scene;
    a.mesh_index = mesh_index;
    a.mesh = &scene.meshes[mesh_index];
    a.name = a.mesh->name;
    const Mesh& m = *a.mesh;

    // The padding needs the asset size, known only after a first build: build, measure, pad.
    BvhBuildOptions opt = default_blas_options();
    opt.max_leaf_size = 2; // official m_libbvh_max_leaf_size (notes §6.7)
    a.mesh_bvh = build_mesh_bvh(m, opt);
    if (a.mesh_bvh.bvh.empty()) throw Error(strfmt("neural mesh '%s' has no valid triangles", a.name.c_str()));
    const Aabb root = a.mesh_bvh.bvh.nodes[0].bounds;
    const glm::vec3 ext = root.extent();
    const float max_ext = std::max({ext.x, ext.y, ext.z});
    const float max_coord = std::max({std::abs(root.lo.x), std::abs(root.lo.y), std::abs(root.lo.z), std::abs(root.hi.x),
                                      std::abs(root.hi.y), std::abs(root.hi.z)});
    // 1e-4 of the asset size (the official 1e-4 absolute for a ~1-unit asset), but never below 64
    // float ulps at the asset's distance from the origin, nor below a denormal-safe floor.
    a.min_extent = std::max({1e-4f * max_ext, 64.0f * 1.2e-7f * max_coord, 1e-30f});
    a.min_exit = 1e-5f * std::max(max_ext, a.min_extent);

    // Pads thin boxes and regrows parents (bvh.h); the N-BVH and the model file store these boxes.
    pad_node_bounds(a.mesh_bvh.bvh, a.min_extent);
    a.node_boxes.resize(a.bvh().nodes.size());
    for (size_t i = 0; i < a.node_boxes.size(); ++i) a.node_boxes[i] = a.bvh().nodes[i].bounds;
    a.bounds = a.node_boxes[0];
    // Encoding box: the padded root box; the largest training dilation (1.1e-4 relative, notes §1)
    // keeps encoded points in [0,1]. The map is per axis (anisotropic), as in the official code.
    a.encoding = nb_make_encoding_box(a.bounds.lo, a.bounds.hi);
    // depth_pad / fixed_depth_eps keep the official absolute values (1e-3, 1e-5): the model file
    // stores only the box, and the renderer rebuilds the same GpuEncodingBox from it.
    const glm::vec3 c = a.bounds.center(), half = 0.5f * a.bounds.extent();
    a.sampling_box = Aabb{c - 1.5f * half, c + 1.5f * half};
    log_debug("training asset '%s': %u triangles, %zu BVH nodes, padding %g", a.name.c_str(), m.triangle_count(),
              a.bvh().nodes.size(), double(a.min_extent));
    return a;
}

} // namespace nbvh
