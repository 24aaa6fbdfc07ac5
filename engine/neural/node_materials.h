// Per-node metallic and roughness of a model's N-BVH: what a neural hit is shaded with. A neural hit
// has no uv, so the textured metallic-roughness of the triangles it stands for is averaged; the paper
// and the official code shade every hit with global constants, and averaging over a whole asset (our
// earlier form, asset_table.h asset_shading) turns Chess's gold crowns into the pieces' wood. Here the
// mean is taken over the triangles of each N-BVH node's base-BVH subtree (area-weighted, the texture
// sampled at 4 points per triangle), so a hit answered by a leaf gets its region's material. Built at
// the end of training, stored in the model (section MATL, MODEL_FORMAT.md), read by the shade pass
// (lib/neural_surface.glsl) unless --neural-materials asset.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/neural/nbvh_tree.h"
#include "engine/scene/scene.h"

namespace nbvh {

// One word per N-BVH node (shared/neural_gpu.h nb_pack_node_material). `base` is the BVH the nodes'
// base_node index (over the triangles of `mesh`, the training asset's mesh); `scene` holds its
// materials and textures. A node without a base node or whose triangles have no area takes its
// parent's value (the root: metallic 0, roughness 1). Empty when no node has a base node.
std::vector<uint32_t> build_node_materials(std::span<const NbvhNode> nodes, const Bvh& base, const Mesh& mesh,
                                           const Scene& scene);

} // namespace nbvh
