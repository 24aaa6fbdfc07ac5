// Per-node metallic and roughness of a model's N-BVH: what a neural hit is shaded with. A neural hit
// has no uv, so the textured metallic-roughness of the triangles it stands for is summarised per N-BVH
// node over the triangles of its base-BVH subtree (area-weighted, 4 points per triangle,
// asset_table.h triangle_material_points), two ways:
//  - means: factor x texture averaged (one word per node, section MATL, format 4);
//  - fits: factor x texture as a linear function of the albedo the network learned (4 fp16 per output,
//    ridge-regularised least squares, section MFIT, format 5), evaluated at the hit's predicted albedo,
//    and the spread of what the fit leaves (residual standard deviations, the roughness's sign that of
//    their covariance): with --neural-materials mix (default) a hit takes fit +- spread, a random sign
//    (a two-point mixture with the texels' mean and variance: a polished texel's highlight survives).
//    Chess's pieces are wood with gold trim and white or black paint in one texture: within one leaf
//    the mean blends them, the albedo tells them apart (scripts/bench/material_fit.py: RMS error of
//    metallic+roughness 0.09-0.24 per leaf mean -> 0.03-0.14 per leaf fit).
// The paper and the official code shade every hit with global constants; averaging over a whole asset
// (asset_table.h asset_shading) turns Chess's gold crowns into the pieces' wood. Built at the end of
// training, read by the shade pass (lib/neural_surface.glsl) as --neural-materials mix|fit|node|asset says.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/neural/nbvh_tree.h"
#include "engine/scene/scene.h"

namespace nbvh {

// Ridge weight of the fits, in albedo units squared (a node whose albedo varies by less than ~0.03 gets
// slopes near 0, i.e. its mean): keeps every coefficient within fp16 (|c| <= ~6 on Chess) and the fit
// robust to the network's albedo error (material_fit.py with noise 0.05 added to the albedo).
inline constexpr double NODE_MATERIAL_RIDGE = 1.0e-3;

struct NodeMaterialTables {
    std::vector<uint32_t> means; // one word per node (shared/neural_gpu.h nb_pack_node_material)
    std::vector<uint32_t> fits;  // NB_NODE_FIT_WORDS per node (shared/neural_gpu.h nb_node_fit_eval, _spread)
};

// Both tables for `nodes`, whose base_node index `base` (a BVH over the triangles of `mesh`, the
// training asset's mesh); `scene` holds its materials and textures. A node without a base node or
// whose triangles have no area takes its parent's values (the root: metallic 0, roughness 1). Both
// empty when no node has a base node (an imported official tree).
NodeMaterialTables build_node_materials(std::span<const NbvhNode> nodes, const Bvh& base, const Mesh& mesh,
                                        const Scene& scene);

} // namespace nbvh
