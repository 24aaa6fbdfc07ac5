// Ground truth of one training sample (official notes §6.7): the closest triangle hit of the asset
// along the leaf segment [t_entry, t_exit] of a ray (t_entry may be negative: the segment then starts
// behind the origin, notes §1), traced against the classical BVH of the whole asset.
#pragma once
#include <glm/glm.hpp>

#include "trainer/pcg32.h"
#include "trainer/training_asset.h"

namespace nbvh {

struct GroundTruth {
    bool hit = false;             // visibility > 0
    float visibility = 0.0f;      // target: 0 miss, 1 opaque hit; blended: the probability that the segment stops a ray
    float depth = 0.0f;           // local depth (t_hit - t_entry) / (L + depth_pad), in [0, 1] (neural_query.h)
    glm::vec3 normal{0.0f};       // unit shading normal (interpolated, normal-mapped), not flipped
    glm::vec3 albedo{0.0f};       // linear base colour: factor x texture (sRGB decoded)
    float t_hit = 0.0f;           // ray parameter of the hit
    uint32_t triangle = 0;
};

// Which hits count (ground_truth.cpp alpha_covers; the closest hit and the stop probability use it):
// its material's glTF alphaMode with alpha = base-colour factor x texture alpha (shared/scene_gpu.h
// nb_alpha_covers, the classical traversal's rule); blended surfaces stop a ray with probability alpha,
// drawn from `key`, and the back faces of single-sided blended ones never do (as in the classical
// traversal: the learned probability is then the front face's, not the compound of a thin shell's two
// faces; for opaque materials the ground truth keeps back faces, as the paper's: culling them made thin
// leaves' visibility depend on a direction their encoded points barely show). Departure from the paper
// and the official code, whose ground truth has no alpha: without it a cut-out (MASK) or translucent
// (BLEND) surface is learned opaque.

// Closest hit of the asset's triangles with t in [tmin, tmax] that its material's alpha keeps
// (alpha_covers). Returns false on a miss. `key` draws the stochastic coverage of blended surfaces.
// `blended` (optional): the hit, or with no hit some crossing met on the way, is alpha-blended.
bool closest_triangle_hit(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir, float tmin,
                          float tmax, const SampleSlot& key, float& t, uint32_t& triangle, float& u, float& v,
                          bool* blended = nullptr);

// The probability that a ray on [tmin, tmax] is stopped (1 at an opaque or kept MASK crossing, else
// 1 - prod(1 - alpha) over the blended crossings, whose draws are independent) and the nearest blended
// crossing (nearest_t infinite: none).
struct StopProbability {
    float probability = 0.0f;
    float nearest_t = NB_INF;
    uint32_t triangle = 0;
    float u = 0.0f, v = 0.0f;
};
StopProbability stop_probability(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                                 float tmin, float tmax);

// `key`: the sample's random streams (its slot of the step); only blended surfaces use it. For an
// alpha-tested asset the visibility target is the stop probability and the surface (depth, normal,
// albedo) the one the draws hit, else the nearest blended crossing: a soft target, whose entropy the
// loss leaves out (engine/neural/shared/training_loss.h), so blended leaves carry no loss floor that
// the split ranking would chase (with the draw's 0 / 1 as the target, Flight Helmet's lenses took 449
// of 2,395 nodes).
GroundTruth trace_ground_truth(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                               float t_entry, float t_exit, const SampleSlot& key);

} // namespace nbvh
