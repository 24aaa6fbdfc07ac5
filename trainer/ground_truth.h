// Ground truth of one training sample (official notes §6.7): the closest triangle hit of the asset
// along the leaf segment [t_entry, t_exit] of a ray (t_entry may be negative: the segment then starts
// behind the origin, notes §1), traced against the classical BVH of the whole asset.
#pragma once
#include <glm/glm.hpp>

#include "trainer/pcg32.h"
#include "trainer/training_asset.h"

namespace nbvh {

struct GroundTruth {
    bool hit = false;
    float depth = 0.0f;           // local depth (t_hit - t_entry) / (L + depth_pad), in [0, 1] (neural_query.h)
    glm::vec3 normal{0.0f};       // unit shading normal (interpolated, normal-mapped), not flipped
    glm::vec3 albedo{0.0f};       // linear base colour: factor x texture (sRGB decoded)
    float t_hit = 0.0f;           // ray parameter of the hit
    uint32_t triangle = 0;
};

// Closest hit of the asset's triangles with t in [tmin, tmax] that its material's alpha keeps
// (alpha_covers). Returns false on a miss. `key` draws the stochastic coverage of blended surfaces.
bool closest_triangle_hit(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir, float tmin,
                          float tmax, const SampleSlot& key, float& t, uint32_t& triangle, float& u, float& v);

// Whether a hit at barycentrics (u, v) of triangle `tri` (original index), on a ray along `dir`, counts:
// its material's glTF alphaMode with alpha = base-colour factor x texture alpha (shared/scene_gpu.h
// nb_alpha_covers, the classical traversal's rule); blended surfaces stop a ray with probability alpha,
// drawn from `key`, and the back faces of single-sided blended ones never do (as in the classical
// traversal: the learned probability is then the front face's, not the compound of a thin shell's two
// faces; for opaque materials the ground truth keeps back faces, as the paper's: culling them made thin
// leaves' visibility depend on a direction their encoded points barely show). Departure from the paper
// and the official code, whose ground truth has no alpha: without it a cut-out (MASK) or translucent
// (BLEND) surface is learned opaque.
bool alpha_covers(const TrainingAsset& asset, uint32_t tri, float u, float v, const glm::vec3& dir,
                  const SampleSlot& key);

// `key`: the sample's random streams (its slot of the step); only blended surfaces use it.
GroundTruth trace_ground_truth(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                               float t_entry, float t_exit, const SampleSlot& key);

} // namespace nbvh
