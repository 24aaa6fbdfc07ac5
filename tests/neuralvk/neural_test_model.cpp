#include "tests/neuralvk/neural_test_model.h"

#include "engine/neural/fp16.h"
#include "engine/neural/level_table.h"

namespace nbvh::test {

TestModel make_test_model(uint64_t seed, glm::vec3 lo, glm::vec3 hi, uint32_t log2_hash, float grid_amplitude,
                          float mlp_gain) {
    TestModel t;
    NeuralConfig cfg;
    cfg.log2_hash_size = log2_hash;
    t.weights = neural::create_network(cfg, seed);
    std::mt19937_64 rng(seed ^ 0x5eedu);
    std::uniform_real_distribution<float> u(-grid_amplitude, grid_amplitude);
    for (float& g : t.weights.grid) g = round_to_half(u(rng));
    for (float& w : t.weights.mlp) w = round_to_half(w * mlp_gain);
    t.model.cfg = cfg;
    t.model.levels = t.weights.levels;
    t.model.mlp = neural::mlp_to_fp16(t.weights);
    t.model.grid = neural::grid_to_fp16(t.weights);
    t.model.encoding_box.lo = lo;
    t.model.encoding_box.hi = hi;
    NbvhNode root;
    root.bounds.lo = lo;
    root.bounds.hi = hi;
    root.lod = 0;
    root.final_leaf = true;
    t.model.nodes = {root};
    t.model.lod_count = 1;
    t.model.lod_node_counts = {1};
    t.box = nb_make_encoding_box(lo, hi);
    return t;
}

neural::Outputs reference_outputs(const TestModel& m, const GpuNeuralQuery& q) {
    neural::SegmentQuery s;
    nb_segment_points(m.box, q.origin, q.dir, q.t_entry, q.t_exit, s.points[0], s.points[1], s.points[2]);
    return neural::forward(m.weights, s, neural::Precision::fp16_emulated);
}

} // namespace nbvh::test
