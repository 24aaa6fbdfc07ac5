#include "tests/neuralvk/neural_test_model.h"

#include "engine/neural/fp16.h"
#include "engine/neural/level_table.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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

std::vector<GpuNeuralQuery> random_queries(uint64_t seed, size_t n, glm::vec3 lo, glm::vec3 hi) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<GpuNeuralQuery> out;
    while (out.size() < n) {
        glm::vec3 a = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 b = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 llo = glm::min(a, b), lhi = glm::max(a, b);
        glm::vec3 target = llo + (lhi - llo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + 1e-6f);
        const bool inside = out.size() % 4 == 0;
        glm::vec3 org = inside ? target : target - dir * (0.5f + 3.0f * u(rng));
        GpuNeuralQuery q;
        q.origin = org;
        q.dir = dir;
        if (!nb_neural_leaf_interval(org, nb_safe_inv_dir(dir), llo, lhi, q.t_entry, q.t_exit)) continue;
        if (q.t_exit <= 0.0f) continue;
        out.push_back(q);
    }
    return out;
}

CrossCheck cross_check(const TestModel& m, const std::vector<GpuNeuralQuery>& qs,
                       const std::vector<GpuNeuralHit>& hits, float vis_margin) {
    CrossCheck c;
    for (size_t i = 0; i < qs.size() && i < hits.size(); ++i) {
        const neural::Outputs y = reference_outputs(m, qs[i]);
        const GpuNeuralHit& h = hits[i];
        if (!std::isfinite(h.visibility) || !std::isfinite(h.depth) || !std::isfinite(h.t)) {
            ++c.non_finite;
            continue;
        }
        c.max_out = std::max({c.max_out, std::abs(h.visibility - y[NB_OUT_VISIBILITY]), std::abs(h.depth - y[NB_OUT_DEPTH])});
        for (int k = 0; k < 3; ++k) c.max_out = std::max(c.max_out, std::abs(h.albedo[k] - y[NB_OUT_ALBEDO + k]));
        const bool ref_vis = nb_decode_visibility(y[NB_OUT_VISIBILITY], NB_VISIBILITY_THRESHOLD);
        if (std::abs(y[NB_OUT_VISIBILITY] - NB_VISIBILITY_THRESHOLD) < vis_margin) {
            ++c.near_threshold;
        } else {
            ++c.decisions;
            c.decision_errors += ((h.flags & NB_NEURAL_VISIBLE) != 0) != ref_vis;
        }
        c.visible += ref_vis;
        float t_ref;
        const bool acc_ref = nb_decode_depth(m.box, y[NB_OUT_DEPTH], qs[i].t_entry, qs[i].t_exit, glm::length(qs[i].dir), t_ref);
        c.reversed += nb_query_reversed(qs[i].t_entry);
        const float to_t = 1.0f / glm::length(qs[i].dir); // object lengths -> ray parameter (nb_decode_depth)
        const float len = std::max(qs[i].t_exit - qs[i].t_entry, 0.0f) + m.box.depth_pad * to_t;
        c.max_t = std::max(c.max_t, std::abs(h.t - t_ref) / len);
        if (std::abs(t_ref - qs[i].t_exit + NB_DEPTH_EPSILON * (len - m.box.depth_pad * to_t) +
                     m.box.fixed_depth_eps * to_t) >
            vis_margin * len)
            c.acceptance_errors += ((h.flags & NB_NEURAL_ACCEPTED) != 0) != acc_ref;
        const glm::vec3 nraw(2 * y[2] - 1, 2 * y[3] - 1, 2 * y[4] - 1);
        if (glm::length(nraw) > 0.05f) c.max_n = std::max(c.max_n, glm::length(h.normal - nb_decode_normal(y[2], y[3], y[4])));
    }
    return c;
}

size_t differing_hits(const std::vector<GpuNeuralHit>& a, const std::vector<GpuNeuralHit>& b) {
    size_t n = 0;
    for (size_t i = 0; i < b.size() && i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(GpuNeuralHit)) != 0;
    return n;
}

} // namespace nbvh::test
