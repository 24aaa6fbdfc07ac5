// Packs a finished training run into the model file's NeuralModel (engine/neural/model_file.h):
// hyperparameters, level table, encoding box, the frozen N-BVH with its LoDs, fp16 weights and grid,
// and the training metadata.
#pragma once
#include <string>

#include "engine/neural/model_file.h"
#include "trainer/trainer.h"

namespace nbvh {

// `source` is the scene as given on the command line ("default" for the built-in one); `source_hash`
// the hash of its file (0 when not a file). `occupancy_masks`: build the nodes' occupancy masks from the
// asset's triangles (engine/neural/occupancy.h; off for the viewer's live previews, which are rebuilt
// every few hundred steps; without masks they render the same surfaces, only slower).
NeuralModel make_neural_model(const TrainingAsset& asset, const TrainResult& result, const TrainOptions& options,
                              const std::string& source, uint64_t source_hash, bool occupancy_masks = true);

} // namespace nbvh
