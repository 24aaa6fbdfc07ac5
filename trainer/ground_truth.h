// Ground truth of one training sample (official notes §6.7): the closest triangle hit of the asset
// along the leaf segment [t_entry, t_exit] of a ray (t_entry may be negative: the segment then starts
// behind the origin, notes §1), traced against the classical BVH of the whole asset.
#pragma once
#include <glm/glm.hpp>

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

// Closest hit of the asset's triangles with t in [tmin, tmax]. Returns false on a miss.
bool closest_triangle_hit(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir, float tmin,
                          float tmax, float& t, uint32_t& triangle, float& u, float& v);

GroundTruth trace_ground_truth(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                               float t_entry, float t_exit);

} // namespace nbvh
