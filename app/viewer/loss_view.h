// The loss view (issue 13 "Training live"; the paper's Fig. 4): every N-BVH leaf that a primary ray
// hits, coloured by its training loss, so a user sees where the model is still poor while it trains.
//
// Per pixel the hybrid renderer traces the pixel-centre camera ray (WavefrontRenderer::trace: the same
// neural rounds as a frame, at the view's LoD and leaf budget); a neural hit point is taken into its
// asset's atlas space (the instance transform and the asset's scale/offset, as mark_neural_instances)
// and the leaf of the LoD's cut whose box holds it is the leaf answered (the network's hit lies in the
// queried leaf; boxes of siblings may overlap, then the walk takes the box nearest to the point). The
// leaf's mean loss per trained sample (live_training.h NodeLossSums, the trainer's split statistic) is
// mapped on a log scale between the smallest and largest loss of the leaves seen, blue to red, shaded
// by the predicted normal. Triangle hits are grey, misses black, leaves that never trained white.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "app/viewer/viewer_scene.h"
#include "engine/neural/nbvh_tree.h"
#include "engine/render/wavefront.h"

namespace nbvh::viewer {

struct LossImage {
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> rgba8;   // rows top to bottom, display-pass packing (R in the low byte)
    float lo = 0.0f, hi = 0.0f;     // loss at the blue and the red end (of the leaves seen)
    uint32_t leaves = 0;            // distinct leaves seen
    uint64_t neural_pixels = 0;     // pixels whose primary ray hit a neural instance
    std::vector<uint32_t> leaf_of_pixel; // model node per pixel (UINT32_MAX: not a neural hit)
};

// The leaf of `lod`'s cut under `root` whose box holds atlas-space point `p` (descending into the child
// whose box is nearest to p: distance 0 inside).
uint32_t leaf_containing(const NbvhTree& tree, uint32_t root, uint32_t lod, const glm::vec3& p);

// Blue (t = 0) -> cyan -> green -> yellow -> red (t = 1), packed RGBA8 with alpha 255.
uint32_t loss_colour(float t, float shade = 1.0f);

// The loss view of `hybrid` (a hybrid renderer over `view`, whose model `node_loss` belongs to: one value
// per model node, NaN where none) for `camera` at LoD `lod`, width x height pixels.
LossImage make_loss_image(render::WavefrontRenderer& hybrid, const ViewerScene& view,
                          const std::vector<float>& node_loss, const Camera& camera, uint32_t lod, uint32_t width,
                          uint32_t height);

} // namespace nbvh::viewer
