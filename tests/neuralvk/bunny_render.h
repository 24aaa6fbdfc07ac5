// The bunny renders of the lavapipe end-to-end tests (hybrid_render_test.cpp, leaf_budget_test.cpp): the
// fixture's model (trained_bunny.h) or the triangles at 64x64, 4 spp, 3 path segments, validation on.
#pragma once

#include "engine/core/image.h"
#include "engine/render/wavefront.h"
#include "tests/neuralvk/trained_bunny.h"

#include <functional>

namespace nbvh::test {

using Fixture = TrainedBunny; // trained_bunny.h: trained once per executable

struct Rendered {
    Image image;
    render::RenderStats stats;
    int validation = 0;
};

using Tweak = std::function<void(render::RenderOptions&)>;

// 64x64, 4 spp, 3 segments, the scalar MLP, the renderer's defaults otherwise; `tweak` changes options
// after these (a hybrid render uses the fixture's model unless tweak sets another).
Rendered render_bunny(const Fixture& f, bool hybrid, const Tweak& tweak = nullptr);

// Batched rounds, leaves per round and the per-ray leaf budget (of every ray: the secondary budget 0).
Tweak rounds(uint32_t batched, uint32_t leaves_per_round,
             uint32_t max_leaves = render::NeuralRenderOptions{}.max_rounds);

// The mean of an image's channels.
double image_mean(const Image& image);

} // namespace nbvh::test
