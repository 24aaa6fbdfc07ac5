// The .nbvh model file: the only contract between trainer and renderer (ARCHITECTURE.md "The model
// file"). Our own format, not the official one (the official .nbvh is a bare madmann91 node dump, notes
// §10). Little-endian, versioned, sectioned, checksummed; layout table in engine/neural/README.md.
//
// The reader trusts nothing: every count is bounded by the section size before anything is allocated,
// every index and float is checked, the level table is validated against the hyperparameters, and
// every failure is one nbvh::Error line that names the file and the problem.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "engine/neural/nbvh_tree.h"
#include "engine/neural/neural_config.h"
#include "engine/scene/scene.h"
#include "shaders/shared/hashgrid.h"

namespace nbvh {

inline constexpr uint32_t MODEL_FORMAT_VERSION = 5; // written; versions 1 (one unnamed asset), 2 (no OCCU), 3 (no MATL) and 4 (no MFIT) still read
inline constexpr uint32_t MODEL_MAX_ASSETS = 65536;
inline constexpr size_t MODEL_MAX_STRING = 4096; // bytes of a name in the file

struct TrainingMetadata {
    uint64_t steps = 0;
    float final_loss = 0.0f;
    double seconds = 0.0;            // wall-clock training time
    uint32_t batch_size = 0;         // rays per step
    std::string backend;             // "cpu", "cuda", ...
    std::string source;              // scene file it was trained from (as given)
    uint64_t source_hash = 0;        // fnv1a64 of the glTF file bytes (or of the mesh data)
    uint64_t source_triangles = 0;   // triangles of the asset the model replaces (0: unknown)
    uint64_t source_vertices = 0;    // its vertices (0: unknown)
    int64_t created_unix = 0;        // seconds since 1970 (UTC)
    // The split schedule that made the cut (trainer/split_scheduler.h SplitSchedule).
    uint32_t splitting_interval = 0, last_split_iteration = 0, start_split_num = 0;
    float split_scaling = 0.0f, split_interval_scaling = 0.0f;
};

// One neural asset of the model (ARCHITECTURE.md "Which assets are neural"): a unique (mesh, material)
// of the scene, its own subtree of the N-BVH, placed in the shared encoding ("atlas") space by a
// uniform scale and an offset (trainer/training_asset.h TrainingPart). Instances share it.
struct ModelAsset {
    std::string name;                    // the scene mesh it answers (after the split by material)
    std::string mesh;                    // glTF mesh it comes from
    std::string material;                // glTF material name ("" in version-1 files)
    std::vector<std::string> node_paths; // glTF nodes it was trained for (information)
    uint64_t geometry_hash = 0;          // asset_table.h geometry_fingerprint; 0 = unknown (version 1)
    uint64_t material_hash = 0;          // asset_table.h material_fingerprint; 0 = unknown
    uint32_t root = 0;                   // N-BVH node of its subtree
    uint32_t triangles = 0;
    float scale = 1.0f;                  // atlas = object * scale + offset
    glm::vec3 offset{0.0f};
};

struct NeuralModel {
    NeuralConfig cfg;
    std::vector<GpuHashLevel> levels;    // as stored: readers use this table, never recompute it
    std::vector<ModelAsset> assets;      // at least one; subtrees disjoint
    Aabb encoding_box;                   // atlas-space box the encoding normalises by (extent > 0)
    uint32_t lod_count = 1;
    std::vector<NbvhNode> nodes;         // stored fields: bounds, left, base_node, lod, final_leaf
    std::vector<uint32_t> lod_node_counts; // nodes reached walking LoD l (index l), lod_count entries
    std::vector<uint16_t> mlp;           // fp16 bits, NB_MLP_WEIGHT_COUNT (shaders/shared/mlp.h order)
    std::vector<uint16_t> grid;          // fp16 bits, level_table_entries(levels) * grid_features
    // Occupancy masks (engine/neural/occupancy.h): NB_OCC_WORDS per node, or empty (files before
    // version 3, or models built without the triangles): every leaf is then queried.
    std::vector<uint32_t> occupancy;
    // Per-node metallic and roughness (engine/neural/node_materials.h): one word per node, or empty
    // (files before version 4, or models built without the triangles): hits take their asset's.
    std::vector<uint32_t> node_materials;
    // Per-node metallic and roughness as linear functions of the predicted albedo (node_materials.h):
    // NB_NODE_FIT_WORDS per node, or empty (files before version 5, or models built without the triangles).
    std::vector<uint32_t> material_fits;
    TrainingMetadata meta;
    uint32_t file_version = 0;           // format version of the file it was read from (0: not read)

    // The tree (parent/depth derived). The nodes must be valid (they are after load_model).
    NbvhTree tree() const { return NbvhTree::from_nodes(nodes, lod_count); }
};

// Fills nodes, lod_count and lod_node_counts from a finished tree (finish_lods() called).
void set_tree(NeuralModel& model, const NbvhTree& tree);

// FNV-1a 64 (the model's checksums, and the source scene hash).
inline constexpr uint64_t FNV1A64_OFFSET = 0xcbf29ce484222325ull;
uint64_t fnv1a64(const void* data, size_t size, uint64_t hash = FNV1A64_OFFSET);
uint64_t fnv1a64_file(const std::filesystem::path& path); // throws nbvh::Error when unreadable

// Serialises (after validating: an invalid model throws nbvh::Error, nothing is written).
std::vector<uint8_t> serialize_model(const NeuralModel& model);
// Writes atomically: a temporary file beside `path`, then rename; an existing file is replaced.
void save_model(const std::filesystem::path& path, const NeuralModel& model);

// Parses and validates; `name` prefixes error messages (the path, or "<memory>").
NeuralModel parse_model(std::span<const uint8_t> bytes, const std::string& name = "<memory>");
NeuralModel load_model(const std::filesystem::path& path);

// Memory of the neural part as the renderer holds it (nodes as GpuBvhNode of LoD 0, fp16 weights and
// grid, level table, occupancy masks, node materials), in bytes.
uint64_t model_gpu_bytes(const NeuralModel& model);

// The classical representation of a mesh as the renderer holds it: positions, normals and one UV set
// per vertex (32 B), 3 indices per triangle (12 B), and a BLAS of ~one 64-byte node per triangle
// (two-child nodes over leaves of up to 2 triangles, rounded up).
inline uint64_t mesh_and_blas_bytes(uint64_t triangles, uint64_t vertices) {
    return vertices * 32 + triangles * 12 + triangles * sizeof(GpuBvhNode);
}

// The official implementation's tree file (madmann91 bvh v2 dump, notes §10): detection and import of
// its node list. Imported nodes have lod_count 1 (childless nodes are leaves, code 1 = final leaf);
// base_node is BVH_INVALID. Throws nbvh::Error on anything malformed.
bool looks_like_official_tree(std::span<const uint8_t> bytes);
std::vector<NbvhNode> import_official_tree(std::span<const uint8_t> bytes, const std::string& name = "<memory>");
std::vector<NbvhNode> import_official_tree(const std::filesystem::path& path);

// Whole file, refusing files over max_bytes (throws nbvh::Error).
std::vector<uint8_t> read_model_file_bytes(const std::filesystem::path& path, uint64_t max_bytes);

} // namespace nbvh
