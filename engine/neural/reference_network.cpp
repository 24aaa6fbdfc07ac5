// CPU reference forward/backward of the N-BVH network (see reference_network.h).
#include "engine/neural/reference_network.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <thread>

#include "engine/core/error.h"
#include "engine/neural/fp16.h"

namespace nbvh::neural {
namespace {

constexpr uint32_t kMatrices = NB_MLP_MATRICES;

// Rounding step of the fp16-emulated path (identity for fp32 / double).
template <class T>
T rnd(T x, Precision p) {
    if (p == Precision::fp16_emulated) return T(round_to_half(float(x)));
    return x;
}

template <class T>
T sigmoid(T x) {
    if (x >= T(0)) return T(1) / (T(1) + std::exp(-x));
    const T e = std::exp(x);
    return e / (T(1) + e);
}

// y = relu?(W_m x) for matrix m (rows = outputs of m, only the first `rows` computed).
template <class T>
void matvec(const NetworkWeightsT<T>& w, uint32_t m, const T* x, uint32_t rows, Precision p, T* y) {
    const uint32_t cols = nb_mlp_layer_inputs(m);
    for (uint32_t r = 0; r < rows; ++r) {
        const T* row = w.mlp.data() + nb_mlp_weight_index(m, r, 0);
        T acc = T(0);
        if (p == Precision::fp16_emulated) {
            // R2/R3: fp16 weights and inputs, fp32 accumulation in column order.
            float a = 0.0f;
            for (uint32_t c = 0; c < cols; ++c) a += round_to_half(float(row[c])) * float(x[c]);
            acc = T(a);
        } else {
            for (uint32_t c = 0; c < cols; ++c) acc += row[c] * x[c];
        }
        y[r] = acc;
    }
}

} // namespace

NetworkWeights create_network(const NeuralConfig& cfg, uint64_t seed) {
    NetworkWeights w;
    w.cfg = cfg;
    if (cfg.segment_points != NB_SEGMENT_POINTS || cfg.mlp_width != NB_MLP_WIDTH ||
        cfg.mlp_hidden_layers != NB_MLP_HIDDEN_LAYERS || cfg.mlp_outputs != NB_MLP_OUTPUTS)
        throw Error("neural config: MLP shape differs from the compiled " + std::to_string(NB_MLP_INPUTS) + "->" +
                    std::to_string(NB_MLP_WIDTH) + "x" + std::to_string(NB_MLP_HIDDEN_LAYERS) + "->" +
                    std::to_string(NB_MLP_OUTPUTS) + " network");
    w.levels = make_level_table(cfg);
    w.grid.resize(level_table_entries(w.levels) * NB_GRID_FEATURES);
    w.mlp.assign(NB_MLP_WEIGHT_COUNT, 0.0f);
    std::mt19937_64 rng(seed);
    // Grid: U(-1e-4, 1e-4) (tcnn GridEncoding::initialize_params).
    std::uniform_real_distribution<float> ug(-1e-4f, 1e-4f);
    for (float& v : w.grid) v = ug(rng);
    // MLP: Xavier uniform per matrix, fan_out of the last matrix = padded width (tcnn).
    for (uint32_t m = 0; m < kMatrices; ++m) {
        const uint32_t in = nb_mlp_layer_inputs(m), out = nb_mlp_layer_outputs(m);
        const float s = std::sqrt(6.0f / float(in + out));
        std::uniform_real_distribution<float> um(-s, s);
        for (uint32_t r = 0; r < out; ++r)
            for (uint32_t c = 0; c < in; ++c) {
                const float v = um(rng);
                w.mlp[nb_mlp_weight_index(m, r, c)] = (m == kMatrices - 1 && r >= NB_MLP_OUTPUTS) ? 0.0f : v;
            }
    }
    return w;
}

void validate_network(const NetworkWeights& w) {
    validate_level_table(w.levels);
    const uint64_t values = level_table_entries(w.levels) * NB_GRID_FEATURES;
    if (w.grid.size() != values)
        throw Error("network: grid has " + std::to_string(w.grid.size()) + " values, level table needs " +
                    std::to_string(values));
    if (w.mlp.size() != NB_MLP_WEIGHT_COUNT)
        throw Error("network: MLP has " + std::to_string(w.mlp.size()) + " weights, expected " +
                    std::to_string(NB_MLP_WEIGHT_COUNT));
    for (size_t i = 0; i < w.mlp.size(); ++i)
        if (!std::isfinite(w.mlp[i])) throw Error("network: MLP weight " + std::to_string(i) + " is not finite");
    for (size_t i = 0; i < w.grid.size(); ++i)
        if (!std::isfinite(w.grid[i])) throw Error("network: grid value " + std::to_string(i) + " is not finite");
}

std::vector<uint16_t> mlp_to_fp16(const NetworkWeights& w) {
    std::vector<uint16_t> out(w.mlp.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = float_to_half_bits(w.mlp[i]);
    return out;
}

std::vector<uint16_t> grid_to_fp16(const NetworkWeights& w) {
    std::vector<uint16_t> out(w.grid.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = float_to_half_bits(w.grid[i]);
    return out;
}

NetworkWeightsT<double> to_double(const NetworkWeights& w) {
    NetworkWeightsT<double> d;
    d.cfg = w.cfg;
    d.levels = w.levels;
    d.grid.assign(w.grid.begin(), w.grid.end());
    d.mlp.assign(w.mlp.begin(), w.mlp.end());
    return d;
}

template <class T>
void encode_point(const NetworkWeightsT<T>& w, vec3 p, Precision prec, T* out32) {
    for (uint32_t l = 0; l < NB_GRID_MAX_LEVELS; ++l) {
        const GpuHashLevel& lv = w.levels[l];
        uvec3 cell;
        vec3 frac;
        nb_grid_position(lv, p, cell, frac);
        T acc[NB_GRID_FEATURES] = {};
        for (uint32_t c = 0; c < NB_GRID_CORNERS; ++c) {
            const T wt = T(nb_grid_corner_weight(frac, c)); // fp32 weight (R1)
            const size_t e = size_t(nb_grid_corner_entry(lv, cell, c)) * NB_GRID_FEATURES;
            for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) acc[f] += wt * rnd(w.grid[e + f], prec);
        }
        for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) out32[l * NB_GRID_FEATURES + f] = rnd(acc[f], prec);
    }
}

template <class T>
OutputsT<T> forward(const NetworkWeightsT<T>& w, const SegmentQuery& q, Precision prec, ForwardCacheT<T>* cache) {
    NBVH_CHECK(w.levels.size() == NB_GRID_MAX_LEVELS && w.mlp.size() == NB_MLP_WEIGHT_COUNT);
    ForwardCacheT<T> local;
    ForwardCacheT<T>& c = cache ? *cache : local;
    c.query = q;
    for (uint32_t k = 0; k < NB_SEGMENT_POINTS; ++k)
        encode_point(w, q.points[k], prec, c.features.data() + nb_feature_slot(k, 0, 0));
    const T* x = c.features.data();
    for (uint32_t m = 0; m < NB_MLP_HIDDEN_LAYERS; ++m) {
        T* h = c.hidden[m].data();
        matvec(w, m, x, NB_MLP_WIDTH, prec, h);
        for (uint32_t r = 0; r < NB_MLP_WIDTH; ++r) h[r] = rnd(std::max(h[r], T(0)), prec); // R3
        x = h;
    }
    T z[NB_MLP_OUTPUTS];
    matvec(w, NB_MLP_HIDDEN_LAYERS, x, NB_MLP_OUTPUTS, prec, z); // R4: fp32 pre-activation
    for (uint32_t r = 0; r < NB_MLP_OUTPUTS; ++r) c.outputs[r] = sigmoid(z[r]);
    return c.outputs;
}

template <class T>
void backward(const NetworkWeightsT<T>& w, const ForwardCacheT<T>& c, const OutputsT<T>& dl_dy, GradientsT<T>& g,
              std::array<T, NB_MLP_INPUTS>* dl_dfeatures) {
    if (g.mlp.size() != NB_MLP_WEIGHT_COUNT) g.mlp.assign(NB_MLP_WEIGHT_COUNT, T(0));
    // Output layer: dz = dL/dy * y (1 - y); padding rows 8..15 get no gradient.
    T dz[NB_MLP_WIDTH] = {};
    for (uint32_t r = 0; r < NB_MLP_OUTPUTS; ++r) dz[r] = dl_dy[r] * c.outputs[r] * (T(1) - c.outputs[r]);
    uint32_t rows = NB_MLP_OUTPUTS;
    for (int m = int(NB_MLP_HIDDEN_LAYERS); m >= 0; --m) {
        const uint32_t cols = nb_mlp_layer_inputs(uint32_t(m));
        const T* x = m == 0 ? c.features.data() : c.hidden[m - 1].data();
        T dx[NB_MLP_INPUTS] = {};
        for (uint32_t r = 0; r < rows; ++r) {
            if (dz[r] == T(0)) continue;
            const size_t base = nb_mlp_weight_index(uint32_t(m), r, 0);
            for (uint32_t col = 0; col < cols; ++col) {
                g.mlp[base + col] += dz[r] * x[col];
                dx[col] += w.mlp[base + col] * dz[r];
            }
        }
        if (m == 0) {
            // Grid: scatter dL/dfeature to the 8 corners of every level of every point.
            for (uint32_t k = 0; k < NB_SEGMENT_POINTS; ++k)
                for (uint32_t l = 0; l < NB_GRID_MAX_LEVELS; ++l) {
                    const GpuHashLevel& lv = w.levels[l];
                    uvec3 cell;
                    vec3 frac;
                    nb_grid_position(lv, c.query.points[k], cell, frac);
                    const T* df = dx + nb_feature_slot(k, l, 0);
                    for (uint32_t corner = 0; corner < NB_GRID_CORNERS; ++corner) {
                        const T wt = T(nb_grid_corner_weight(frac, corner));
                        const uint32_t e = nb_grid_corner_entry(lv, cell, corner) * NB_GRID_FEATURES;
                        for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) g.grid.push_back({e + f, wt * df[f]});
                    }
                }
            if (dl_dfeatures)
                for (uint32_t i = 0; i < NB_MLP_INPUTS; ++i) (*dl_dfeatures)[i] = dx[i];
        } else {
            // Through the ReLU of hidden layer m-1 (derivative 0 at 0, as tcnn).
            for (uint32_t col = 0; col < cols; ++col) dz[col] = x[col] > T(0) ? dx[col] : T(0);
            rows = NB_MLP_WIDTH;
        }
    }
}

namespace {
unsigned pick_threads(unsigned threads, size_t n) {
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    return unsigned(std::max<size_t>(1, std::min<size_t>(threads, (n + 63) / 64)));
}

template <class F>
void parallel_chunks(size_t n, unsigned threads, F&& fn) {
    threads = pick_threads(threads, n);
    if (threads == 1) {
        fn(0u, size_t(0), n);
        return;
    }
    std::vector<std::thread> pool;
    const size_t chunk = (n + threads - 1) / threads;
    for (unsigned t = 0; t < threads; ++t) {
        const size_t b = std::min(n, t * chunk), e = std::min(n, b + chunk);
        pool.emplace_back([&fn, t, b, e] { fn(t, b, e); });
    }
    for (auto& th : pool) th.join();
}
} // namespace

void forward_batch(const NetworkWeights& w, std::span<const SegmentQuery> queries, Precision prec,
                   std::span<Outputs> out, unsigned threads) {
    NBVH_CHECK(out.size() == queries.size());
    parallel_chunks(queries.size(), threads, [&](unsigned, size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) out[i] = forward(w, queries[i], prec);
    });
}

void backward_batch(const NetworkWeights& w, std::span<const SegmentQuery> queries, std::span<const Outputs> dl_dy,
                    std::vector<float>& mlp_grad, std::vector<float>& grid_grad, unsigned threads) {
    NBVH_CHECK(dl_dy.size() == queries.size());
    const unsigned n_threads = pick_threads(threads, queries.size());
    std::vector<Gradients> per_thread(n_threads);
    parallel_chunks(queries.size(), n_threads, [&](unsigned t, size_t b, size_t e) {
        Gradients& g = per_thread[t];
        g.reset();
        g.grid.reserve((e - b) * NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS * NB_GRID_CORNERS * NB_GRID_FEATURES);
        ForwardCache cache;
        for (size_t i = b; i < e; ++i) {
            forward(w, queries[i], Precision::fp32, &cache);
            backward(w, cache, dl_dy[i], g);
        }
    });
    mlp_grad.assign(NB_MLP_WEIGHT_COUNT, 0.0f);
    grid_grad.assign(w.grid.size(), 0.0f);
    for (const Gradients& g : per_thread) {
        if (g.mlp.empty()) continue;
        for (size_t i = 0; i < NB_MLP_WEIGHT_COUNT; ++i) mlp_grad[i] += g.mlp[i];
        for (const GridGrad<float>& gg : g.grid) grid_grad[gg.index] += gg.grad;
    }
}

template void encode_point<float>(const NetworkWeightsT<float>&, vec3, Precision, float*);
template void encode_point<double>(const NetworkWeightsT<double>&, vec3, Precision, double*);
template OutputsT<float> forward<float>(const NetworkWeightsT<float>&, const SegmentQuery&, Precision,
                                        ForwardCacheT<float>*);
template OutputsT<double> forward<double>(const NetworkWeightsT<double>&, const SegmentQuery&, Precision,
                                          ForwardCacheT<double>*);
template void backward<float>(const NetworkWeightsT<float>&, const ForwardCacheT<float>&, const OutputsT<float>&,
                              GradientsT<float>&, std::array<float, NB_MLP_INPUTS>*);
template void backward<double>(const NetworkWeightsT<double>&, const ForwardCacheT<double>&,
                               const OutputsT<double>&, GradientsT<double>&, std::array<double, NB_MLP_INPUTS>*);

} // namespace nbvh::neural
