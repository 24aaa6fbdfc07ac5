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

std::vector<uint32_t> neural_meshes(const Scene& scene) {
    std::vector<uint32_t> out;
    std::vector<bool> seen(scene.meshes.size(), false);
    for (const Instance& inst : scene.instances)
        if (inst.neural && inst.mesh < seen.size() && !seen[inst.mesh]) {
            seen[inst.mesh] = true;
            out.push_back(inst.mesh);
        }
    return out;
}

namespace {

// Side of an atlas cell relative to a part's largest extent (1): a gap of a quarter between parts.
constexpr float ATLAS_CELL = 1.25f;

// Thin-axis padding and segment epsilon for parts whose largest extent is max_ext, at max_coord from
// the origin: 1e-4 of the size (the official 1e-4 absolute for a ~1-unit asset), but never below 64
// float ulps at the distance from the origin, nor below a denormal-safe floor.
void set_epsilons(TrainingAsset& a, float max_ext, float max_coord) {
    a.min_extent = std::max({1e-4f * max_ext, 64.0f * 1.2e-7f * max_coord, 1e-30f});
    a.min_exit = 1e-5f * std::max(max_ext, a.min_extent);
}

float largest(const glm::vec3& v) { return std::max({v.x, v.y, v.z}); }
float largest_abs(const Aabb& b) { return std::max(largest(glm::abs(b.lo)), largest(glm::abs(b.hi))); }

// Part `mesh` moved into the atlas (positions only; normals and tangents keep their directions under a
// uniform scale).
Mesh atlas_mesh(const Mesh& m, float scale, const glm::vec3& offset) {
    Mesh out = m;
    for (glm::vec3& p : out.positions) p = p * scale + offset;
    return out;
}

template <class T> void append_attr(std::vector<T>& dst, const std::vector<T>& src, size_t vertices, bool wanted) {
    if (!wanted) return;
    if (src.size() == vertices) dst.insert(dst.end(), src.begin(), src.end());
    else dst.resize(dst.size() + vertices, T(0.0f));
}

} // namespace

TrainingAsset make_training_asset(const Scene& scene, uint32_t mesh_index) {
    const uint32_t one[1] = {mesh_index};
    return make_training_asset(scene, one);
}

TrainingAsset make_training_asset(const Scene& scene, std::span<const uint32_t> meshes) {
    if (meshes.empty()) throw Error("no neural mesh to train");
    for (uint32_t m : meshes) NBVH_CHECK(m < scene.meshes.size());
    TrainingAsset a;
    a.scene = &scene;
    BvhBuildOptions opt = default_blas_options();
    opt.max_leaf_size = 2; // official m_libbvh_max_leaf_size (notes §6.7)

    if (meshes.size() == 1) {
        // One asset: its own object space. The padding needs the asset size, known only after a first
        // build: build, measure, pad.
        a.mesh = &scene.meshes[meshes[0]];
        a.name = a.mesh->name;
        a.mesh_bvh = build_mesh_bvh(*a.mesh, opt);
        if (a.mesh_bvh.bvh.empty()) throw Error(strfmt("neural mesh '%s' has no valid triangles", a.name.c_str()));
        const Aabb root = a.mesh_bvh.bvh.nodes[0].bounds;
        set_epsilons(a, largest(root.extent()), largest_abs(root));
        TrainingPart p;
        p.name = a.name;
        p.mesh_index = meshes[0];
        p.triangle_count = a.mesh->triangle_count();
        a.parts.push_back(p);
    } else {
        // Several assets: each scaled to a unit largest extent, centred in its own atlas cell.
        const uint32_t n = uint32_t(meshes.size());
        const uint32_t g = uint32_t(std::ceil(std::cbrt(double(n)) - 1e-9));
        auto combined = std::make_shared<Mesh>();
        combined->name = "atlas";
        bool want_uv0 = false, want_uv1 = false, want_tangents = false;
        for (uint32_t m : meshes) {
            const Mesh& mesh = scene.meshes[m];
            want_uv0 = want_uv0 || !mesh.uv0.empty();
            want_uv1 = want_uv1 || !mesh.uv1.empty();
            want_tangents = want_tangents || !mesh.tangents.empty();
        }
        std::vector<Bvh> part_bvhs;
        std::vector<uint32_t> prim_offsets;
        for (uint32_t i = 0; i < n; ++i) {
            const Mesh& mesh = scene.meshes[meshes[i]];
            TrainingPart p;
            p.name = mesh.name;
            p.mesh_index = meshes[i];
            // Bounds of the valid triangles (what the BVH will hold).
            const MeshBvh probe = build_mesh_bvh(mesh, opt);
            if (probe.bvh.empty()) throw Error(strfmt("neural mesh '%s' has no valid triangles", mesh.name.c_str()));
            const Aabb b = probe.bvh.nodes[0].bounds;
            const float ext = largest(b.extent());
            p.scale = ext > 0.0f && std::isfinite(1.0f / ext) ? 1.0f / ext : 1.0f;
            const glm::vec3 cell(float(i % g), float((i / g) % g), float(i / (g * g)));
            p.offset = (cell + 0.5f) * ATLAS_CELL - b.center() * p.scale;
            const Mesh placed = atlas_mesh(mesh, p.scale, p.offset);
            MeshBvh mb = build_mesh_bvh(placed, opt);
            // Append the part to the combined mesh.
            const uint32_t vbase = uint32_t(combined->positions.size());
            p.first_triangle = combined->triangle_count();
            p.triangle_count = placed.triangle_count();
            const size_t nv = placed.positions.size();
            combined->positions.insert(combined->positions.end(), placed.positions.begin(), placed.positions.end());
            append_attr(combined->normals, placed.normals, nv, true);
            append_attr(combined->uv0, placed.uv0, nv, want_uv0);
            append_attr(combined->uv1, placed.uv1, nv, want_uv1);
            append_attr(combined->tangents, placed.tangents, nv, want_tangents);
            for (uint32_t idx : placed.indices) combined->indices.push_back(idx + vbase);
            for (uint32_t t = 0; t < placed.triangle_count(); ++t)
                combined->triangle_material.push_back(t < placed.triangle_material.size() ? placed.triangle_material[t] : 0u);
            prim_offsets.push_back(p.first_triangle);
            part_bvhs.push_back(std::move(mb.bvh));
            a.parts.push_back(p);
        }
        Aabb atlas;
        for (const Bvh& b : part_bvhs) atlas.grow(b.nodes[0].bounds);
        set_epsilons(a, 1.0f, largest_abs(atlas));
        for (Bvh& b : part_bvhs) pad_node_bounds(b, a.min_extent);
        std::vector<uint32_t> roots;
        a.mesh_bvh.bvh = join_bvhs(part_bvhs, prim_offsets, &roots);
        // Triangle vertices in the joined leaf order (the parts' ranges follow the top tree's order).
        for (uint32_t t : a.mesh_bvh.bvh.prim_indices)
            for (int k = 0; k < 3; ++k) a.mesh_bvh.vertices.push_back(combined->positions[combined->indices[3 * t + k]]);
        for (uint32_t i = 0; i < n; ++i) a.parts[i].root = roots[i];
        a.owned_mesh = combined;
        a.mesh = combined.get();
        a.name = strfmt("%u assets", n);
    }

    // Pads thin boxes and regrows parents (bvh.h); the N-BVH and the model file store these boxes.
    pad_node_bounds(a.mesh_bvh.bvh, a.min_extent);
    a.node_boxes.resize(a.bvh().nodes.size());
    for (size_t i = 0; i < a.node_boxes.size(); ++i) a.node_boxes[i] = a.bvh().nodes[i].bounds;
    a.above_parts.assign(a.node_boxes.size(), 0);
    std::vector<uint8_t> is_root(a.node_boxes.size(), 0);
    for (const TrainingPart& p : a.parts) is_root[p.root] = 1;
    for (size_t i = 0; i < a.node_boxes.size(); ++i) {
        const uint32_t parent = a.bvh().nodes[i].parent;
        a.above_parts[i] = !is_root[i] && (parent == BVH_INVALID || a.above_parts[parent]);
    }
    a.bounds = a.node_boxes[0];
    // Triangles without a material entry use material 0 (ground_truth.cpp material_of).
    auto tested = [&](uint32_t mat) { return mat < scene.materials.size() && scene.materials[mat].alpha_mode != AlphaMode::opaque; };
    a.alpha_tested = a.mesh->triangle_material.size() < a.triangle_count() && tested(0u);
    for (uint32_t mat : a.mesh->triangle_material) a.alpha_tested = a.alpha_tested || tested(mat);
    // Encoding box: the padded root box; the largest training dilation (1.1e-4 relative, notes §1)
    // keeps encoded points in [0,1]. The map is per axis (anisotropic), as in the official code.
    a.encoding = nb_make_encoding_box(a.bounds.lo, a.bounds.hi);
    // depth_pad / fixed_depth_eps keep the official absolute values (1e-3, 1e-5): the model file
    // stores only the box, and the renderer rebuilds the same GpuEncodingBox from it.
    for (TrainingPart& p : a.parts) {
        p.bounds = a.node_boxes[p.root];
        const glm::vec3 c = p.bounds.center(), half = 0.5f * p.bounds.extent();
        p.sampling_box = Aabb{c - 1.5f * half, c + 1.5f * half};
    }
    log_debug("training asset '%s': %zu part(s), %u triangles, %zu BVH nodes, padding %g", a.name.c_str(),
              a.parts.size(), a.triangle_count(), a.bvh().nodes.size(), double(a.min_extent));
    return a;
}

} // namespace nbvh
