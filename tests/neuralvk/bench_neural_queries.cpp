// Benchmark of the neural query kernels (issue 4, not a test): neural queries per second of the scalar
// and the cooperative-matrix path on the same random queries, and how far the two paths agree.
//   nbvh_bench_neural [--model M.nbvh] [--queries N] [--reps R] [--device auto|gpu|cpu] [--json out.json]
//                     [--coherent]   (camera-ray ordered queries instead of random ones)
//                     [--pipeline C:G,...]  (more rows of the pipelined split query: C chunks, gather grids
//                                            of G workgroups)
// Without --model a random network with varied outputs (tests/neuralvk/neural_test_model.h, hash 2^18,
// the paper's size) is used: the kernels' cost does not depend on the weights' values.
// Queries: random rays through random leaf-sized boxes of the asset, a quarter starting inside.
#include "engine/core/error.h"
#include "engine/render/neural_model_gpu.h"
#include "engine/vk/context.h"
#include "tests/neuralvk/neural_test_model.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

using namespace nbvh;
using namespace nbvh::render;

namespace {

std::vector<GpuNeuralQuery> make_queries(size_t n, glm::vec3 lo, glm::vec3 hi, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<GpuNeuralQuery> out;
    out.reserve(n);
    const glm::vec3 ext = hi - lo;
    while (out.size() < n) {
        // Leaf-sized boxes (1/16 of the asset per axis), as a cut of ~1000 nodes gives.
        glm::vec3 c = lo + ext * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 llo = c - ext * (1.0f / 32.0f), lhi = c + ext * (1.0f / 32.0f);
        glm::vec3 dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + 1e-6f);
        glm::vec3 org = (out.size() % 4 == 0) ? c : c - dir * glm::length(ext) * u(rng);
        GpuNeuralQuery q;
        q.origin = org;
        q.dir = dir;
        if (!nb_neural_leaf_interval(org, nb_safe_inv_dir(dir), llo, lhi, q.t_entry, q.t_exit)) continue;
        out.push_back(q);
    }
    return out;
}

// Coherent queries, as camera rays produce them: a pinhole camera looking at the asset, one ray per
// pixel of a square image in row order, each against the cell of a 16^3 grid over the asset box
// (leaf-sized) that contains its entry point.
std::vector<GpuNeuralQuery> make_coherent_queries(size_t n, glm::vec3 lo, glm::vec3 hi) {
    const uint32_t side = uint32_t(std::sqrt(double(n)));
    const glm::vec3 c = 0.5f * (lo + hi), ext = hi - lo;
    const float diag = glm::length(ext);
    const glm::vec3 eye = c + glm::normalize(glm::vec3(0.3f, 0.4f, 1.0f)) * (1.5f * diag);
    const glm::vec3 fwd = glm::normalize(c - eye);
    const glm::vec3 right = glm::normalize(glm::cross(fwd, glm::vec3(0, 1, 0)));
    const glm::vec3 up = glm::cross(right, fwd);
    std::vector<GpuNeuralQuery> out;
    out.reserve(size_t(side) * side);
    const glm::vec3 cell = ext / 16.0f;
    for (uint32_t y = 0; y < side; ++y)
        for (uint32_t x = 0; x < side; ++x) {
            const float u = (x + 0.5f) / side * 2 - 1, v = (y + 0.5f) / side * 2 - 1;
            const glm::vec3 d = glm::normalize(fwd + 0.35f * (u * right + v * up));
            const glm::vec3 inv = nb_safe_inv_dir(d);
            float t0, t1;
            if (!nb_intersect_aabb_interval(eye, inv, lo, hi, -NB_INF, NB_INF, t0, t1)) continue;
            const glm::vec3 p = eye + d * (t0 + 1e-4f * diag);
            const glm::vec3 k = glm::clamp(glm::floor((p - lo) / cell), glm::vec3(0), glm::vec3(15));
            GpuNeuralQuery q;
            q.origin = eye;
            q.dir = d;
            if (!nb_neural_leaf_interval(eye, inv, lo + k * cell, lo + (k + 1.0f) * cell, q.t_entry, q.t_exit)) continue;
            out.push_back(q);
        }
    return out;
}

} // namespace

int main(int argc, char** argv) try {
    std::string model_path, json_path, device = "auto";
    size_t n = size_t(1) << 22;
    int reps = 10;
    bool coherent = false;
    std::vector<NeuralEvaluator::Pipeline> pipelines;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) throw Error(a + " needs a value");
            return argv[++i];
        };
        if (a == "--model") model_path = next();
        else if (a == "--queries") n = std::stoull(next());
        else if (a == "--reps") reps = std::stoi(next());
        else if (a == "--device") device = next();
        else if (a == "--json") json_path = next();
        else if (a == "--coherent") coherent = true;
        else if (a == "--pipeline") {
            const std::string v = next();
            for (size_t at = 0; at < v.size();) {
                size_t end = v.find(',', at);
                if (end == std::string::npos) end = v.size();
                const std::string item = v.substr(at, end - at);
                const size_t colon = item.find(':');
                if (colon == std::string::npos) throw Error("--pipeline wants C:G items, got " + item);
                NeuralEvaluator::Pipeline pl;
                pl.chunks = uint32_t(std::stoul(item.substr(0, colon)));
                pl.groups = uint32_t(std::stoul(item.substr(colon + 1)));
                if (pl.chunks == 0 || pl.groups == 0) throw Error("--pipeline wants C, G >= 1, got " + item);
                pipelines.push_back(pl);
                at = end + 1;
            }
        }
        else throw Error("unknown option " + a);
    }
    vk::ContextOptions o;
    o.set_device(device); // auto, gpu, gpu:N or cpu, as the CLI
    vk::Context ctx(o);
    const vk::DeviceFeatures& dev = ctx.features();
    std::printf("device: %s (%s %s)\n", dev.device_name.c_str(), dev.driver_name.c_str(), dev.driver_info.c_str());
    for (const auto& s : dev.coop_matrix_shapes) std::printf("  coopmat shape %s\n", s.describe().c_str());

    test::TestModel tm = test::make_test_model(42, glm::vec3(-1.0f), glm::vec3(1.0f), 18);
    NeuralModel model = tm.model;
    if (!model_path.empty()) model = load_model(model_path);
    NeuralModelGpu gpu(ctx, model);
    const std::vector<GpuNeuralQuery> qs =
        coherent ? make_coherent_queries(n, model.encoding_box.lo, model.encoding_box.hi)
                 : make_queries(n, model.encoding_box.lo, model.encoding_box.hi, 1234);
    std::printf("%zu %s queries\n", qs.size(), coherent ? "coherent (camera-ray order)" : "random incoherent");

    struct Row { std::string path; double ms = 0; double qps = 0; std::vector<GpuNeuralHit> hits; };
    std::vector<Row> rows;
    const std::string why = coopmat_unavailable_reason(dev);
    if (!why.empty()) std::printf("cooperative-matrix path unavailable: %s\n", why.c_str());
    // Scalar, then every cooperative-matrix kernel (where the device has both, the fp16-accumulator
    // fallback too, so that it is checked on real hardware).
    std::vector<NeuralKernelChoice> choices = {choose_neural_kernel(dev, NeuralPath::scalar)};
    for (const NeuralKernelChoice& c : coopmat_kernels(dev)) choices.push_back(c);
    for (const NeuralKernelChoice& choice : choices) {
        NeuralEvaluator ev(ctx, gpu, choice);
        Row r;
        r.path = ev.choice().describe();
        r.hits = ev.evaluate(qs); // also warms up
        r.ms = ev.time_dispatch(uint32_t(qs.size()), reps);
        r.qps = r.ms > 0 ? double(qs.size()) / (r.ms * 1e-3) : 0.0;
        std::printf("%-70s %9.3f ms / %zu queries = %.3f G queries/s\n", r.path.c_str(), r.ms, qs.size(), r.qps * 1e-9);
        rows.push_back(std::move(r));
    }
    // The split query: a gather kernel writes the features, an MLP kernel reads them (prototype).
    double ms_split_gather = 0, ms_split_mlp = 0;
    size_t split_differs = 0;
    const bool can_split = why.empty() && choose_neural_kernel(dev, NeuralPath::coopmat).fp32_accumulate;
    if (can_split) {
        const NeuralKernelChoice c = choose_neural_kernel(dev, NeuralPath::coopmat);
        NeuralEvaluator ev(ctx, gpu, c, 3);
        Row r;
        r.path = "split: gather kernel + MLP kernel (fp32 accumulators)";
        r.hits = ev.evaluate(qs);
        r.ms = ev.time_dispatch(uint32_t(qs.size()), reps);
        r.qps = r.ms > 0 ? double(qs.size()) / (r.ms * 1e-3) : 0.0;
        std::printf("%-70s %9.3f ms / %zu queries = %.3f G queries/s\n", r.path.c_str(), r.ms, qs.size(),
                    r.qps * 1e-9);
        split_differs = test::differing_hits(rows[1].hits, r.hits);
        std::printf("split vs fused coopmat: %zu of %zu hits differ (bitwise)\n", split_differs, qs.size());
        const size_t split_row = rows.size();
        rows.push_back(std::move(r));
        // The pipelined split query: the device's default (a row of the JSON), then any --pipeline rows.
        pipelines.insert(pipelines.begin(), NeuralEvaluator::pipeline_for(dev));
        for (size_t k = 0; k < pipelines.size(); ++k) {
            const NeuralEvaluator::Pipeline& pl = pipelines[k];
            NeuralEvaluator pe(ctx, gpu, c, 6);
            pe.set_pipeline(pl);
            Row p;
            p.path = std::string(k == 0 ? "split pipelined (default): " : "split pipelined: ") +
                     std::to_string(pl.chunks) + " chunks, gather grids of " +
                     (pl.groups == ~0u ? std::string("any size") : std::to_string(pl.groups));
            p.hits = pe.evaluate(qs);
            // The plain split query timed right before and after, in the same state of the GPU.
            const double before = ev.time_dispatch(uint32_t(qs.size()), reps);
            p.ms = pe.time_dispatch(uint32_t(qs.size()), reps);
            const double after = ev.time_dispatch(uint32_t(qs.size()), reps);
            p.qps = p.ms > 0 ? double(qs.size()) / (p.ms * 1e-3) : 0.0;
            const size_t differs = test::differing_hits(rows[split_row].hits, p.hits);
            std::printf("%-70s %9.3f ms / %zu queries = %.3f G queries/s (%zu hits differ from the split query; "
                        "the split query right before / after %.3f / %.3f ms)\n",
                        p.path.c_str(), p.ms, qs.size(), p.qps * 1e-9, differs, before, after);
            if (k == 0) rows.push_back(std::move(p));
        }
        NeuralEvaluator ge(ctx, gpu, c, 4);
        ge.evaluate(qs);
        ms_split_gather = ge.time_dispatch(uint32_t(qs.size()), reps);
        NeuralEvaluator me(ctx, gpu, c, 5);
        me.evaluate(qs);
        ms_split_mlp = me.time_dispatch(uint32_t(qs.size()), reps);
        std::printf("split breakdown: gather kernel %.3f ms (%.3f G/s), MLP kernel %.3f ms (%.3f G/s)\n",
                    ms_split_gather, qs.size() / (ms_split_gather * 1e6), ms_split_mlp,
                    qs.size() / (ms_split_mlp * 1e6));
    }
    // Where the cooperative-matrix query's time goes: features only, MLP only.
    double ms_features = 0, ms_mlp = 0;
    if (why.empty()) {
        NeuralEvaluator fe(ctx, gpu, choose_neural_kernel(dev, NeuralPath::coopmat), 1);
        fe.evaluate(qs);
        ms_features = fe.time_dispatch(uint32_t(qs.size()), reps);
        NeuralEvaluator me(ctx, gpu, choose_neural_kernel(dev, NeuralPath::coopmat), 2);
        me.evaluate(qs);
        ms_mlp = me.time_dispatch(uint32_t(qs.size()), reps);
        std::printf("coopmat breakdown: hash-grid features only %.3f ms (%.3f G/s), MLP only %.3f ms (%.3f G/s)\n",
                    ms_features, qs.size() / (ms_features * 1e6), ms_mlp, qs.size() / (ms_mlp * 1e6));
    }
    std::string agree = "[";
    for (size_t k = 1; k < rows.size(); ++k) {
        double max_dy = 0, sum_dy = 0;
        size_t vis_diff = 0, vis_diff_outside_margin = 0, nonfinite = 0;
        for (size_t i = 0; i < qs.size(); ++i) {
            const GpuNeuralHit& a = rows[0].hits[i];
            const GpuNeuralHit& b = rows[k].hits[i];
            if (!std::isfinite(b.visibility) || !std::isfinite(b.t) || !std::isfinite(b.normal.x)) ++nonfinite;
            double d = std::max({std::abs(a.visibility - b.visibility), std::abs(a.depth - b.depth),
                                 std::abs(a.albedo.x - b.albedo.x), std::abs(a.albedo.y - b.albedo.y),
                                 std::abs(a.albedo.z - b.albedo.z)});
            max_dy = std::max(max_dy, d);
            sum_dy += d;
            if ((a.flags & NB_NEURAL_VISIBLE) != (b.flags & NB_NEURAL_VISIBLE)) {
                ++vis_diff;
                if (std::abs(a.visibility - NB_VISIBILITY_THRESHOLD) > 2e-3f) ++vis_diff_outside_margin;
            }
        }
        const char* label = rows[k].path.rfind("split pipelined", 0) == 0 ? "split pipelined"
                            : rows[k].path.rfind("split", 0) == 0         ? "split"
                            : k == 1                                      ? "coopmat"
                                                                          : "coopmat fp16-acc";
        std::printf("scalar vs %s: max |dy| %.3g, mean |dy| %.3g, visibility differs on %zu of %zu (%zu with "
                    "|y0 - 0.5| > 2e-3), non-finite coopmat outputs %zu\n",
                    label, max_dy, sum_dy / double(qs.size()), vis_diff, qs.size(), vis_diff_outside_margin, nonfinite);
        char buf[512];
        std::snprintf(buf, sizeof buf,
                      "%s{\"path\": \"%s\", \"max_abs_dy\": %.6g, \"mean_abs_dy\": %.6g, \"visibility_differs\": %zu, "
                      "\"visibility_differs_outside_2e-3\": %zu, \"nonfinite\": %zu}",
                      k > 1 ? ", " : "", rows[k].path.c_str(), max_dy, sum_dy / double(qs.size()), vis_diff,
                      vis_diff_outside_margin, nonfinite);
        agree += buf;
    }
    agree += "]";
    if (!json_path.empty()) {
        std::ofstream f(json_path);
        f << "{\n  \"device\": \"" << dev.device_name << "\",\n  \"driver\": \"" << dev.driver_name << " "
          << dev.driver_info << "\",\n  \"queries\": " << qs.size() << ",\n  \"query_order\": \"" << (coherent ? "coherent" : "random") << "\",\n  \"reps\": " << reps
          << ",\n  \"model\": \"" << (model_path.empty() ? "random (hash 2^18)" : model_path) << "\",\n  \"paths\": [";
        for (size_t i = 0; i < rows.size(); ++i)
            f << (i ? ", " : "") << "{\"path\": \"" << rows[i].path << "\", \"ms\": " << rows[i].ms
              << ", \"queries_per_s\": " << rows[i].qps << "}";
        f << "],\n  \"coopmat_features_only_ms\": " << ms_features
          << ",\n  \"coopmat_mlp_only_ms\": " << ms_mlp << ",\n  \"split_gather_ms\": " << ms_split_gather
          << ",\n  \"split_mlp_ms\": " << ms_split_mlp << ",\n  \"split_vs_fused_differs\": " << split_differs
          << ",\n  \"scalar_vs_coopmat\": " << agree << "\n}\n";
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
}
