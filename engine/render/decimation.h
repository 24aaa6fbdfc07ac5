// The paper's decimation baseline at equal memory (issue 11): the scene's neural meshes simplified with
// meshoptimizer (engine/scene/simplify.h) until the simplified meshes + their BLAS occupy what the neural
// model occupies on the GPU (gpu_memory.h), rendered classically.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "engine/scene/scene.h"

namespace nbvh::render {

struct Decimation {
    Scene scene;               // the input scene with the meshes replaced (instances unchanged)
    uint64_t budget_bytes = 0; // asked for
    uint64_t bytes = 0;        // simplified meshes + BLAS (mesh_gpu_bytes), summed
    uint64_t source_bytes = 0; // the full meshes + BLAS
    uint64_t source_triangles = 0, triangles = 0;
    bool sloppy = false;            // some mesh needed vertex clustering (simplify.h)
    bool fits_unsimplified = false; // the full meshes already fit the budget: nothing was simplified
    uint32_t iterations = 0;
    double relative_error() const { return budget_bytes ? double(bytes) / double(budget_bytes) - 1.0 : 0.0; }
};

// Simplifies `meshes` (indices into scene.meshes) by one common triangle ratio so that their GPU bytes
// come within `tolerance` (relative) of `budget_bytes`: the ratio is rescaled by budget / bytes until
// then (bytes are about proportional to the triangle count), at most 12 times; the closest result is
// kept. Budgets below what one triangle per material group costs give that.
Decimation decimate_to_budget(const Scene& scene, std::span<const uint32_t> meshes, uint64_t budget_bytes,
                              double tolerance = 0.02);

} // namespace nbvh::render
