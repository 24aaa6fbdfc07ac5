#include "trainer/evaluation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/core/error.h"
#include "shaders/shared/neural_query.h"
#include "trainer/ground_truth.h"

namespace nbvh {

EvalStats evaluate_network(const TrainingAsset& asset, const TrainingCut& cut, const neural::NetworkWeights& weights,
                           uint32_t rays, uint64_t seed, int32_t part) {
    EvalStats e;
    uint32_t agree = 0;
    std::vector<double> depth_err;
    double depth_abs_sum = 0.0, normal_sum = 0.0, albedo_sum = 0.0;
    NBVH_CHECK(part < int32_t(asset.parts.size()));
    // Seeds far from the training streams (which use `seed` ^ step hashes with slot streams).
    Pcg32 rng(seed ^ 0xD1B54A32D192ED03ull, 0x5EED);
    for (uint64_t attempt = 0; e.rays < rays && attempt < uint64_t(rays) * 1000u; ++attempt) {
        const TrainingPart& p = asset.parts[part >= 0                ? uint32_t(part)
                                            : asset.parts.size() > 1 ? pick_part(asset, rng.next_float())
                                                                     : 0u];
        const float diag = glm::length(p.bounds.extent());
        const glm::vec3 lo = p.sampling_box.lo, ext = p.sampling_box.extent();
        const glm::vec3 o = lo + ext * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
        const glm::vec3 d = uniform_sphere_direction(rng.next_float(), rng.next_float());
        const FirstLeaf f = first_leaf_of_cut(asset.bvh(), asset.node_boxes, cut, o, d, 1e-5f, asset.min_exit, p.root);
        if (f.leaf < 0) continue;
        // Whole forward segment of the leaf (as trained; the renderer's inside-origin reversal is a
        // decode rule on top of the same network).
        const glm::vec3 so = o + d * f.t_entry;
        const float len = std::max(f.t_exit - f.t_entry, 0.0f);
        const GroundTruth gt = trace_ground_truth(asset, so, d, 0.0f, len, SampleSlot{seed, ~0u, uint32_t(attempt)});
        neural::SegmentQuery q;
        nb_segment_points(asset.encoding, so, d, 0.0f, len, q.points[0], q.points[1], q.points[2]);
        const neural::Outputs y = neural::forward(weights, q, neural::Precision::fp32);
        e.rays++;
        const bool hit = nb_decode_visibility(y[NB_OUT_VISIBILITY], NB_VISIBILITY_THRESHOLD);
        if (hit == (gt.visibility > 0.5f)) agree++; // blended surfaces: the stop probability's majority
        if (hit && gt.hit) {
            e.both_hit++;
            float t_pred;
            nb_decode_depth(asset.encoding, y[NB_OUT_DEPTH], 0.0f, len, glm::length(d), t_pred);
            const double err = std::abs(double(t_pred) - double(gt.t_hit));
            depth_err.push_back(len > 0.0f ? err / double(len) : 0.0);
            depth_abs_sum += diag > 0.0f ? err / double(diag) : 0.0;
            const glm::vec3 n = nb_decode_normal(y[NB_OUT_NORMAL], y[NB_OUT_NORMAL + 1], y[NB_OUT_NORMAL + 2]);
            const float c = std::clamp(glm::dot(n, gt.normal), -1.0f, 1.0f);
            normal_sum += double(std::acos(c)) * 180.0 / std::numbers::pi;
            albedo_sum += (std::abs(y[NB_OUT_ALBEDO] - gt.albedo.x) + std::abs(y[NB_OUT_ALBEDO + 1] - gt.albedo.y) +
                           std::abs(y[NB_OUT_ALBEDO + 2] - gt.albedo.z)) /
                          3.0;
        }
    }
    if (e.rays) e.visibility_agreement = double(agree) / double(e.rays);
    if (e.both_hit) {
        double s = 0.0;
        for (double x : depth_err) s += x;
        e.depth_mae = s / double(e.both_hit);
        std::sort(depth_err.begin(), depth_err.end());
        e.depth_p90 = depth_err[std::min(depth_err.size() - 1, size_t(0.9 * double(depth_err.size())))];
        e.depth_mae_rel_asset = depth_abs_sum / double(e.both_hit);
        e.normal_mean_deg = normal_sum / double(e.both_hit);
        e.albedo_mae = albedo_sum / double(e.both_hit);
    }
    return e;
}

} // namespace nbvh
