// The wavefront renderer's passes (engine/render/wavefront.h): their indices into the renderer's
// pipelines and descriptor sets, and the shader that names each pass's timer. Shared by wavefront.cpp
// (pipelines, frames) and wavefront_record.cpp (command recording); not part of the renderer's API.
#ifndef NBVH_RENDER_WAVEFRONT_PASSES_H
#define NBVH_RENDER_WAVEFRONT_PASSES_H
#include <cstddef>

namespace nbvh::render::wavefront_passes {

enum Pass : size_t {
    CAMERA,
    QUEUE_ARGS,
    TRAVERSE,
    SHADE,
    SHADOW,
    ACCUMULATE,
    RESOLVE,
    RAY_SORT,
    NEURAL_TRAVERSE,
    NEURAL_ARGS,
    NEURAL_QUERY,
    NEURAL_SHADOW,
    NEURAL_TAIL, // hybrid renders only (neural_stage.h)
    NEURAL_GATHER,
    NEURAL_MLP, // the split query pass only (NeuralStage::split)
    PASS_COUNT
};
// NEURAL_QUERY's shader depends on the MLP path (NeuralStage::query_shader); this entry names its timer.
inline const char* const PASS_SHADERS[PASS_COUNT] = {
    "passes/camera_rays.comp", "passes/queue_args.comp",    "passes/traverse.comp",
    "passes/shade.comp",       "passes/shadow.comp",        "passes/accumulate.comp",
    "passes/resolve.comp",     "passes/ray_sort.comp",      "passes/neural_traverse.comp",
    "passes/neural_args.comp", "passes/neural_query.comp",  "passes/neural_shadow.comp",
    "passes/neural_tail.comp", "passes/neural_gather.comp", "passes/neural_query_mlp32.comp"};

} // namespace nbvh::render::wavefront_passes

#endif
