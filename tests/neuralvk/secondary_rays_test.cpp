// Secondary rays leaving a neural surface (issue 4), on lavapipe with validation on: no self-hits,
// and no light leaking through the asset beyond what the network's visibility accuracy allows.
//
// Tests (1) and (2) walk the renderer's neural loop on the host with the same pieces (engine/render/
// NEURAL.md), which allows a negative control the renderer has no switch for; test (3) checks that
// the renderer's own rounds give the same hits. The pieces: the LoD-0 N-BVH cut of the model, leaf intervals from nb_neural_leaf_interval (dilated box, tmin = -inf: an origin inside
// a leaf gives a reversed query), leaves in increasing key max(t_entry, tmin) while the key is in front
// of the best hit, at most 8 leaves per ray; each round's queries go through the GPU scalar query
// kernel (NeuralEvaluator: shared encode + network + decode, incl. the reversed-query margin
// depth_eps * L + fixed_eps); a hit counts when visible, accepted, t > tmin and closer than the best.
// Everything is in the asset's object space (the network's space); the secondary-ray offset is
// shade.comp's (shared nb_ray_offset) with the scene extent taken as the asset diagonal.
#include "engine/bvh/mesh_bvh.h"
#include "engine/bvh/scene_accel.h"
#include "engine/neural/nbvh_tree.h"
#include "engine/render/neural_model_gpu.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "tests/neuralvk/trained_bunny.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

using namespace nbvh;
using namespace nbvh::render;

namespace {

constexpr uint32_t MAX_LEAVES = 8; // NeuralRenderOptions::max_rounds default

vk::Context make_lavapipe() {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    return vk::Context(o);
}

struct NeuralHit {
    float t = NB_INF; // NB_INF: miss
    glm::vec3 normal{0.0f, 0.0f, 1.0f};
};

// How a leaf that contains the origin is queried: as the method says (reversed, with the margin), or,
// for the negative control, forward from the origin (t_entry clamped to 0: no margin at all).
enum class InsideLeaf { reversed, forward_from_origin };

struct LeafSpan {
    float key, t_entry, t_exit;
};

class NeuralTracer {
public:
    NeuralTracer(const vk::Context& ctx, const NeuralModel& model)
        : gpu_(ctx, model), eval_(ctx, gpu_, choose_neural_kernel(ctx.features(), NeuralPath::scalar)) {
        for (uint32_t n : model.tree().leaves_at(0)) leaves_.push_back(model.nodes[n].bounds);
    }
    size_t leaf_count() const { return leaves_.size(); }
    uint64_t queries() const { return queries_; }

    // Closest neural hits of object-space rays with t in (tmin, inf).
    std::vector<NeuralHit> trace(const std::vector<glm::vec3>& org, const std::vector<glm::vec3>& dir, float tmin = 0.0f,
                                 InsideLeaf inside = InsideLeaf::reversed) {
        const size_t n = org.size();
        std::vector<std::vector<LeafSpan>> spans(n);
        for (size_t i = 0; i < n; ++i) {
            const glm::vec3 inv = nb_safe_inv_dir(dir[i]);
            for (const Aabb& b : leaves_) {
                float te, tx;
                if (!nb_neural_leaf_interval(org[i], inv, b.lo, b.hi, te, tx) || !(tx > tmin)) continue;
                if (inside == InsideLeaf::forward_from_origin) te = std::max(te, 0.0f);
                spans[i].push_back({std::max(te, tmin), te, tx});
            }
            std::sort(spans[i].begin(), spans[i].end(), [](const LeafSpan& a, const LeafSpan& b) { return a.key < b.key; });
        }
        std::vector<NeuralHit> best(n);
        for (uint32_t round = 0; round < MAX_LEAVES; ++round) {
            std::vector<GpuNeuralQuery> qs;
            std::vector<size_t> ray_of;
            for (size_t i = 0; i < n; ++i) {
                if (round >= spans[i].size() || !(spans[i][round].key < best[i].t)) continue;
                GpuNeuralQuery q{};
                q.origin = org[i];
                q.dir = dir[i];
                q.t_entry = spans[i][round].t_entry;
                q.t_exit = spans[i][round].t_exit;
                qs.push_back(q);
                ray_of.push_back(i);
            }
            if (qs.empty()) break;
            queries_ += qs.size();
            const std::vector<GpuNeuralHit> hs = eval_.evaluate(qs);
            for (size_t k = 0; k < hs.size(); ++k) {
                const GpuNeuralHit& h = hs[k];
                NeuralHit& b = best[ray_of[k]];
                const uint32_t both = NB_NEURAL_VISIBLE | NB_NEURAL_ACCEPTED;
                if ((h.flags & both) == both && h.t > tmin && h.t < b.t) b = {h.t, h.normal};
            }
        }
        return best;
    }

private:
    NeuralModelGpu gpu_;
    NeuralEvaluator eval_;
    std::vector<Aabb> leaves_;
    uint64_t queries_ = 0;
};

glm::vec3 uniform_sphere(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const float z = 1.0f - 2.0f * u(rng), phi = 6.2831853f * u(rng);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Cosine-distributed direction about unit n.
glm::vec3 cosine_hemisphere(std::mt19937& rng, glm::vec3 n) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const float r = std::sqrt(u(rng)), phi = 6.2831853f * u(rng);
    const glm::vec3 a = std::abs(n.x) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 t = glm::normalize(glm::cross(a, n)), b = glm::cross(n, t);
    return glm::normalize(t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1.0f - r * r)));
}

// Rays from a sphere of radius `diag` about the asset centre towards random points of the inner half
// of the asset box (most of them meet the bunny).
void outside_rays(const Aabb& box, size_t count, uint32_t seed, std::vector<glm::vec3>& org, std::vector<glm::vec3>& dir) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-0.25f, 0.25f);
    const glm::vec3 c = (box.lo + box.hi) * 0.5f, e = box.extent();
    const float diag = glm::length(e);
    for (size_t i = 0; i < count; ++i) {
        const glm::vec3 o = c + uniform_sphere(rng) * diag;
        const glm::vec3 target = c + glm::vec3(u(rng), u(rng), u(rng)) * e;
        org.push_back(o);
        dir.push_back(glm::normalize(target - o));
    }
}

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// `count` secondary rays leaving hit point p of a ray along `dir`: the origin offset as shade.comp does
// (shared nb_ray_offset, with `extent` as the scene extent) along the normal turned towards the ray,
// cosine-distributed directions about it.
void add_secondary_rays(glm::vec3 p, glm::vec3 normal, glm::vec3 dir, float extent, int count, std::mt19937& rng,
                        std::vector<glm::vec3>& so, std::vector<glm::vec3>& sd) {
    const glm::vec3 n = glm::dot(normal, dir) < 0.0f ? normal : -normal;
    const glm::vec3 o = nb_ray_offset(p, n, NB_RAY_EPSILON_SCALE * extent);
    for (int k = 0; k < count; ++k) {
        so.push_back(o);
        sd.push_back(cosine_hemisphere(rng, n));
    }
}

} // namespace

// (1) Self-hits. Camera-like rays from outside hit the neural bunny; from every neural hit (point,
// predicted normal turned towards the ray) 8 cosine-distributed secondary rays leave from the offset
// origin. A self-hit is a neural hit closer than 1e-3 of the asset diagonal.
// Bound 1 %: the leaf containing the origin is queried reversed and rejects hits closer than
// 0.2 x its chord (leaves of a ~100-leaf cut are >> 1e-3 diagonals across), so a self-hit needs an
// origin within 1e-3 diagonals of another leaf's face whose forward query predicts a hit right at
// its entry; such origins are a small fraction of the surface (measured 0.06 %). Hits closer than
// 1e-2 diagonals, bound 5 % (measured 1.5 %): these include true nearby geometry (creases, the
// ears) as well as self-hits. Negative control: the same rays with the containing leaf queried
// forward from the origin (no reversed query, no margin) hit within 1e-2 diagonals far more often
// (measured 39 %; must exceed 20 %), so this test can fail.
TEST(SecondaryRays, NoSelfHitsLeavingNeuralSurface) {
    NBVH_REQUIRE_SHARED();
    const test::TrainedBunny& b = test::trained_bunny();
    vk::Context ctx = make_lavapipe();
    NeuralTracer tracer(ctx, b.model);
    const Aabb box = b.asset.bounds;
    const float diag = glm::length(box.extent());

    std::vector<glm::vec3> org, dir;
    outside_rays(box, 256, 3, org, dir);
    const std::vector<NeuralHit> primary = tracer.trace(org, dir);

    constexpr int PER_HIT = 8;
    std::mt19937 rng(5);
    std::vector<glm::vec3> so, sd;
    size_t hits = 0, nonfinite = 0;
    for (size_t i = 0; i < primary.size(); ++i) {
        if (!(primary[i].t < NB_INF)) continue;
        const glm::vec3 p = org[i] + dir[i] * primary[i].t;
        if (!finite3(p) || !finite3(primary[i].normal)) {
            ++nonfinite;
            continue;
        }
        ++hits;
        add_secondary_rays(p, primary[i].normal, dir[i], diag, PER_HIT, rng, so, sd);
    }
    EXPECT_EQ(nonfinite, 0u);
    ASSERT_GT(hits, 64u) << "too few primary neural hits to measure anything";

    const float near = 1.0e-3f * diag;
    auto measure = [&](const std::vector<NeuralHit>& sec, size_t& self, size_t& any, size_t& bad, size_t& close) {
        self = any = bad = close = 0;
        for (const NeuralHit& h : sec) {
            if (!(h.t < NB_INF)) continue;
            ++any;
            if (h.t < near) ++self;
            if (h.t < 10.0f * near) ++close;
            if (!std::isfinite(h.t) || !finite3(h.normal)) ++bad;
        }
    };
    size_t self = 0, any = 0, bad = 0, close = 0;
    measure(tracer.trace(so, sd), self, any, bad, close);
    const double self_frac = double(self) / double(so.size());
    size_t cself = 0, cany = 0, cbad = 0, cclose = 0;
    measure(tracer.trace(so, sd, 0.0f, InsideLeaf::forward_from_origin), cself, cany, cbad, cclose);
    std::printf("hits closer than 1e-2 diagonals: %.2f %% (bound 5 %%; control %.2f %%, must exceed 20 %%); "
                "control hits %.1f %%\n",
                100.0 * double(close) / double(so.size()), 100.0 * double(cclose) / double(so.size()),
                100.0 * double(cany) / double(so.size()));
    const double control_frac = double(cself) / double(so.size());

    std::printf("primary: %zu rays, %zu neural hits; secondary: %zu rays, %zu hit (%.1f %%), self-hits (< %.2e) "
                "%.3f %% (bound 1 %%); control without reversed queries: %.2f %%; %llu queries, %zu leaves\n",
                org.size(), hits, so.size(), any, 100.0 * double(any) / double(so.size()), near, 100.0 * self_frac,
                100.0 * control_frac, (unsigned long long)tracer.queries(), tracer.leaf_count());
    EXPECT_EQ(bad, 0u);
    EXPECT_LT(self_frac, 0.01);
    EXPECT_LT(double(close) / double(so.size()), 0.05);
    EXPECT_GT(double(cclose) / double(so.size()), 0.20);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// (2) Leaking. Rays from outside (half towards the inner half of the asset box, half towards random
// triangles) aimed so the triangles say "blocked": the neural loop leaks when it finds no hit before
// a point 0.05 diagonals behind the first triangle hit. "Thin" rays are those whose triangle ground
// truth leaves the mesh again within 0.03 diagonals (ears, edges). Unblocked rays (the triangles miss
// the asset) measure the opposite error (false occlusion).
// The method is approximate: visibility is a classifier with agreement a on fresh rays of the
// training distribution (trainer check, measured a = 98.5 % for this 300-step model). A blocked ray
// leaks only if every queried leaf along it says "invisible", so over all blocked rays the leak rate is
// about the per-query error: bound 3 (1 - a) + 0.02 (measured 1.7 % vs bound 6.7 %); same bound for
// false occlusion of unblocked rays (measured 0.8 %). Thin parts are where the classifier's errors
// concentrate (both faces within a few finest hash-grid cells; they are rare in the training
// distribution, so `a` says little about them): measured 17 % of thin rays leak with this tiny model.
// Bound 30 %: the network must still block the large majority of rays through thin parts, i.e. discriminate
// them from unblocked rays (false occlusion ~1 %) instead of letting light through at chance.
TEST(SecondaryRays, LightLeaksThroughAssetBoundedByVisibilityAccuracy) {
    NBVH_REQUIRE_SHARED();
    const test::TrainedBunny& b = test::trained_bunny();
    vk::Context ctx = make_lavapipe();
    NeuralTracer tracer(ctx, b.model);
    const Aabb box = b.asset.bounds;
    const float diag = glm::length(box.extent());
    const double err = 1.0 - b.check.visibility_agreement;

    std::vector<glm::vec3> org, dir;
    outside_rays(box, 1024, 9, org, dir);
    {
        // As many rays aimed at random triangles (covers ears and edges, where the asset is thin).
        const Mesh& m = *b.asset.mesh;
        std::mt19937 rng(13);
        std::uniform_int_distribution<uint32_t> tri(0, m.triangle_count() - 1);
        const glm::vec3 c = (box.lo + box.hi) * 0.5f;
        for (int i = 0; i < 1024; ++i) {
            const uint32_t t = tri(rng);
            const glm::vec3 p = (m.positions[m.indices[3 * t]] + m.positions[m.indices[3 * t + 1]] +
                                 m.positions[m.indices[3 * t + 2]]) / 3.0f;
            const glm::vec3 o = c + uniform_sphere(rng) * diag;
            org.push_back(o);
            dir.push_back(glm::normalize(p - o));
        }
    }
    const std::vector<NeuralHit> nh = tracer.trace(org, dir);
    size_t blocked = 0, leaked = 0, thin = 0, thin_leaked = 0, open = 0, false_block = 0;
    for (size_t i = 0; i < org.size(); ++i) {
        Ray r;
        r.org = org[i];
        r.dir = dir[i];
        Hit h;
        if (intersect_closest(b.asset.mesh_bvh, r, 0.0f, NB_INF, h)) {
            const float target = h.t + 0.05f * diag;
            const bool leak = !(nh[i].t < target);
            Hit h2;
            const bool is_thin = intersect_closest(b.asset.mesh_bvh, r, h.t + 1e-4f * diag, NB_INF, h2) &&
                                 h2.t - h.t < 0.03f * diag;
            ++blocked;
            leaked += leak;
            thin += is_thin;
            thin_leaked += is_thin && leak;
        } else {
            ++open;
            false_block += nh[i].t < NB_INF;
        }
    }
    const double leak_frac = double(leaked) / double(std::max<size_t>(blocked, 1));
    const double thin_frac = double(thin_leaked) / double(std::max<size_t>(thin, 1));
    const double open_frac = double(false_block) / double(std::max<size_t>(open, 1));
    std::printf("visibility agreement (trainer check, %u rays): %.2f %%; blocked %zu: leaked %.2f %% (bound %.2f %%); "
                "thin %zu: leaked %.2f %% (bound 30 %%); unblocked %zu: neural hit %.2f %% (bound %.2f %%)\n",
                b.check.rays, 100.0 * b.check.visibility_agreement, blocked, 100.0 * leak_frac,
                100.0 * (3 * err + 0.02), thin, 100.0 * thin_frac, open,
                100.0 * open_frac, 100.0 * (3 * err + 0.02));
    ASSERT_GT(blocked, 200u);
    ASSERT_GT(open, 50u);
    EXPECT_GT(b.check.visibility_agreement, 0.9);
    EXPECT_LT(leak_frac, 3 * err + 0.02);
    ASSERT_GT(thin, 50u);
    EXPECT_LT(thin_frac, 0.30);
    EXPECT_LT(open_frac, 3 * err + 0.02);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// (3) The renderer's own neural rounds (WavefrontRenderer::trace in a hybrid renderer: passes
// neural_traverse / neural_args / neural_query_scalar / neural_tail, K leaves per round, the
// last-group shortcut) against the host replay above on the same rays: the same leaves in the same key
// order through the same scalar kernel, so hits must agree (bound: 99 % of the rays, hit t within 1e-3
// diagonals, normals within 1e-3; measured: every ray). Then secondary rays from the renderer's hits,
// offset along its predicted normals, through the renderer again: self-hits below the bound of (1).
TEST(SecondaryRays, RendererNeuralRoundsAgreeWithTheHostReplay) {
    NBVH_REQUIRE_SHARED();
    const test::TrainedBunny& b = test::trained_bunny();
    vk::Context ctx = make_lavapipe();
    NeuralTracer host(ctx, b.model);
    const SceneAccel accel = build_scene_accel(b.scene);
    RenderOptions o;
    o.width = o.height = 16; // trace() works in chunks of the wave capacity
    o.neural.model = &b.model;
    o.neural.path = NeuralPath::scalar;
    WavefrontRenderer renderer(ctx, b.scene, accel, default_sky(), auto_frame(b.scene, 1.0f), o);
    ASSERT_FALSE(b.scene.instances.empty());
    const glm::mat4 m = b.scene.instances[0].object_to_world;
    for (const Instance& inst : b.scene.instances) ASSERT_EQ(inst.object_to_world, m) << "one placement expected";
    const glm::mat3 n_to_world = glm::transpose(glm::inverse(glm::mat3(m)));
    const Aabb box = b.asset.bounds;
    const float diag = glm::length(box.extent());

    std::vector<glm::vec3> org, dir, worg, wdir;
    outside_rays(box, 512, 21, org, dir);
    for (size_t i = 0; i < org.size(); ++i) { // world rays with the same parameter t
        worg.push_back(glm::vec3(m * glm::vec4(org[i], 1.0f)));
        wdir.push_back(glm::mat3(m) * dir[i]);
    }
    const std::vector<NeuralHit> want = host.trace(org, dir);
    const std::vector<TraceHit> got = renderer.trace(worg, wdir);
    ASSERT_EQ(got.size(), org.size());
    size_t agree = 0, hits = 0;
    float max_dn = 0.0f;
    for (size_t i = 0; i < org.size(); ++i) {
        const bool hw = want[i].t < NB_INF, hg = got[i].t < NB_INF;
        EXPECT_TRUE(!hg || got[i].neural) << "the bunny is neural: ray " << i;
        hits += hw;
        if (hw != hg) continue;
        if (!hw) {
            ++agree;
            continue;
        }
        if (std::abs(got[i].t - want[i].t) > 1e-3f * diag) continue;
        ++agree;
        max_dn = std::max(max_dn, glm::length(got[i].normal - glm::normalize(n_to_world * want[i].normal)));
    }
    std::printf("renderer vs host replay: %zu of %zu rays agree (%zu host hits), max normal difference %.2e\n", agree,
                org.size(), hits, max_dn);
    ASSERT_GT(hits, 128u);
    EXPECT_GE(double(agree), 0.99 * double(org.size()));
    EXPECT_LT(max_dn, 1e-3f);

    // Secondary rays from the renderer's hits.
    const float wdiag = glm::length(glm::mat3(m) * box.extent());
    std::mt19937 rng(8);
    std::vector<glm::vec3> so, sd;
    for (size_t i = 0; i < got.size(); ++i)
        if (got[i].t < NB_INF && got[i].neural)
            add_secondary_rays(worg[i] + wdir[i] * got[i].t, got[i].normal, wdir[i], wdiag, 4, rng, so, sd);
    const std::vector<TraceHit> sec = renderer.trace(so, sd);
    size_t self = 0, any = 0;
    for (const TraceHit& h : sec) {
        if (!(h.t < NB_INF)) continue;
        ++any;
        EXPECT_TRUE(std::isfinite(h.t) && finite3(h.normal));
        self += h.t < 1.0e-3f * wdiag;
    }
    std::printf("renderer secondary rays: %zu, hit %zu, self-hits (< 1e-3 diagonals) %.3f %% (bound 1 %%)\n",
                so.size(), any, 100.0 * double(self) / double(std::max<size_t>(so.size(), 1)));
    ASSERT_GT(so.size(), 256u);
    EXPECT_LT(double(self) / double(so.size()), 0.01);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}
