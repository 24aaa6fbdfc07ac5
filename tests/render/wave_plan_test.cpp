// The wave plan (engine/render/wave_plan.h): how many paths a wave holds and how many samples of every
// pixel it traces, against the limits that bound it. Pure arithmetic, no GPU: the hard cases are the
// devices' limits (NVIDIA's 4094-MiB allocations, lavapipe's 128-MiB bindings, small cards) and the
// extreme options (1 spp, max depth 256, a 256-leaf budget, a one-pixel image, a 16k x 16k one).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "engine/neural/model_file.h"
#include "engine/render/neural_stage.h"
#include "engine/render/wave_plan.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/wavefront_gpu.h"

using namespace nbvh;
using namespace nbvh::render;

namespace {

constexpr uint64_t P1080 = 1920ull * 1080;
constexpr uint64_t MIB = 1ull << 20, GIB = 1ull << 30;

WaveLimits h100() { return WaveLimits{4094 * MIB, 80 * GIB, 0x7FFFFFFFu}; }

RenderOptions opts(uint32_t spp = 16, const NeuralModel* model = nullptr, uint32_t k = 2) {
    RenderOptions o;
    o.spp = spp;
    o.neural.model = model;
    o.neural.leaves_per_round = k;
    return o;
}

// Every buffer sized by the capacity fits one buffer, the queues a quarter of the GPU, the counters.
void expect_within_limits(uint64_t pixels, const RenderOptions& o, const WaveLimits& l, const WavePlan& p) {
    SCOPED_TRACE(testing::Message() << pixels << " pixels, spp " << o.spp << ", depth " << o.max_depth);
    ASSERT_GE(p.capacity, 64u);
    ASSERT_GE(p.samples, 1u);
    EXPECT_LE(p.samples, NB_WAVE_MAX_SAMPLES);
    EXPECT_LE(p.samples, std::max(o.spp, 1u));
    if (p.capacity >= pixels && p.capacity > 64) {
        EXPECT_EQ(p.capacity, uint64_t(p.samples) * pixels) << "a one-wave image keeps no unused slot";
    }
    if (p.samples > 1) {
        EXPECT_LE(uint64_t(p.samples) * pixels, p.capacity);
    }
    EXPECT_LE(p.capacity, std::max<uint64_t>(o.max_wave_pixels, 64));
    if (p.capacity > 64) { // the bounds, restated here rather than taken from wave_plan.cpp
        const uint64_t cap = p.capacity;
        const bool hybrid = o.neural.model != nullptr;
        const uint64_t k = o.neural.leaves_per_round;
        EXPECT_LE(2ull * NB_RAY_WORDS * 4 * cap, l.buffer_bytes);
        // No 32-bit counter grows by 2^31 within one wave: rays by 2 per bounce (queries: 64-bit).
        EXPECT_LE(cap * 2 * o.max_depth, 1ull << 31);
        const uint64_t bytes =
            196 + (hybrid ? 2 * 64 + 2 * k * 48 : 0); // queues + ray order + neural state + pending pairs
        if (l.device_local_bytes) {
            EXPECT_LE(bytes * cap, uint64_t(double(l.device_local_bytes) * o.wave_memory_share));
        }
        if (l.max_workgroups_x) {
            EXPECT_LE(cap, uint64_t(l.max_workgroups_x) * 64) << "one invocation per path per dispatch";
            if (hybrid) {
                EXPECT_LE(cap * k, uint64_t(l.max_workgroups_x) * NB_NEURAL_GROUP);
            }
        }
        if (hybrid) {
            EXPECT_LE(k * sizeof(GpuPendingLeaf) * cap, l.buffer_bytes); // each half of the pending queue
            EXPECT_LE(2ull * sizeof(GpuNeuralRayState) * cap, l.buffer_bytes);
        }
    }
}

} // namespace

// 16 samples of 1080p in one wave, classical and hybrid (2 leaves per round: each half of the pending
// queue 2 x 48 bytes x 33.2M = 3.19 GB, within one allocation; ~17.2 GB of queues, within a quarter of 80).
TEST(WavePlan, FullHdTakesSixteenSamplesPerWaveOnALargeGpu) {
    const NeuralModel model;
    for (const NeuralModel* m : {static_cast<const NeuralModel*>(nullptr), &model}) {
        const WavePlan p = plan_wave(P1080, opts(16, m), h100());
        EXPECT_EQ(p.samples, 16u) << (m ? "hybrid" : "classical");
        EXPECT_EQ(p.capacity, 16 * P1080);
        expect_within_limits(P1080, opts(16, m), h100(), p);
    }
}

TEST(WavePlan, OneSamplePerCallKeepsOneSamplesQueues) {
    const WavePlan p = plan_wave(P1080, opts(1), h100()); // the viewer
    EXPECT_EQ(p.samples, 1u);
    EXPECT_EQ(p.capacity, P1080);
    EXPECT_EQ(plan_wave(P1080, opts(3), h100()).samples, 3u);
}

// A renderer that shares the GPU with others (`nbvh study`'s image renderers: half of the memory
// between 5) takes fewer samples per wave, within its share: 80 GiB x 0.09 = 7.2 GiB at 516 bytes a
// hybrid path is 15.0M paths, 28 samples of 960x540; at a twentieth, 16.
TEST(WavePlan, AMemoryShareBoundsTheWave) {
    const NeuralModel model;
    for (float share : {0.09f, 0.05f}) {
        RenderOptions o = opts(512, &model);
        o.wave_memory_share = share;
        const WavePlan p = plan_wave(960ull * 540, o, h100());
        expect_within_limits(960ull * 540, o, h100(), p);
        EXPECT_EQ(p.samples, share == 0.09f ? 28u : 16u) << share;
        EXPECT_LE(uint64_t(p.capacity) * wave_bytes_per_path(o), uint64_t(80.0 * double(GIB) * share));
    }
    const WavePlan classical = plan_wave(
        960ull * 540,
        [] {
            RenderOptions o = opts(512);
            o.wave_memory_share = 0.1f;
            return o;
        }(),
        h100());
    EXPECT_EQ(classical.samples, 32u); // 196 bytes a path: 43.8M paths fit, the 32-sample bound holds
}

TEST(WavePlan, SmallImagesStopAtThirtyTwoSamples) {
    const WavePlan p = plan_wave(960ull * 540, opts(512), h100());
    EXPECT_EQ(p.samples, 32u);
    EXPECT_EQ(p.capacity, 32ull * 960 * 540);
    const WavePlan one = plan_wave(1, opts(512), h100()); // one pixel: the 64-path floor, 32 samples
    EXPECT_EQ(one.samples, 32u);
    EXPECT_GE(one.capacity, 64u);
}

// Four leaves per round at 1080p: 16 samples would need 4 x 48 bytes x 33.2M = 5.9 GiB of pending pairs
// in each half's buffer; the wave shrinks to what 4094 MiB holds (it failed with a one-line allocation
// error before the plan knew the allocation limit).
TEST(WavePlan, PendingPairsStayWithinOneAllocation) {
    const NeuralModel model;
    const WavePlan p = plan_wave(P1080, opts(16, &model, 4), h100());
    EXPECT_EQ(p.samples, 10u); // 4094 MiB / 192 bytes = 22.4M paths: 10 samples, trimmed to them
    EXPECT_EQ(p.capacity, 10 * P1080);
    EXPECT_LE(4 * sizeof(GpuPendingLeaf) * p.capacity, 4094 * MIB);
    expect_within_limits(P1080, opts(16, &model, 4), h100(), p);
}

TEST(WavePlan, SmallGpusGetSmallerWaves) {
    const NeuralModel model;
    const WaveLimits card{4094 * MIB, 8 * GIB, 0x7FFFFFFFu};
    const WavePlan hybrid = plan_wave(P1080, opts(16, &model), card);
    EXPECT_EQ(hybrid.samples, 2u); // 2 GiB / 516 bytes = 4.16M paths: two samples of 1080p
    EXPECT_EQ(hybrid.capacity, 2 * P1080);
    const WavePlan classical = plan_wave(P1080, opts(16), card);
    EXPECT_EQ(classical.samples, 5u); // 2 GiB / 196 bytes = 11.0M paths
    expect_within_limits(P1080, opts(16, &model), card, hybrid);
    expect_within_limits(P1080, opts(16), card, classical);
}

TEST(WavePlan, LavapipeBindingsBoundTheQueues) {
    const WaveLimits lavapipe{128 * MIB, 0, 65535};
    const WavePlan p = plan_wave(P1080, opts(16), lavapipe);
    EXPECT_EQ(p.capacity, 128 * MIB / (2 * NB_RAY_WORDS * 4)); // under one 1080p sample: several waves
    EXPECT_EQ(p.samples, 1u);
}

// The spec's minimum maxComputeWorkGroupCount (65535, e.g. Intel's Linux driver): 65535 x 64 paths per
// dispatch, classical waves included (the camera pass dispatches one invocation per path directly).
TEST(WavePlan, MinimumWorkgroupCountBoundsEveryWave) {
    const WavePlan p = plan_wave(P1080, opts(16), WaveLimits{4094 * MIB, 16 * GIB, 65535});
    EXPECT_EQ(p.samples, 2u); // 65535 x 64 = 4.19M paths
    EXPECT_EQ(p.capacity, 2 * P1080);
    const WavePlan big = plan_wave(8192ull * 8192, opts(16), WaveLimits{4094 * MIB, 16 * GIB, 65535});
    EXPECT_EQ(big.capacity, 65535ull * 64);
    EXPECT_EQ(big.samples, 1u);
}

// Deep paths shrink the wave so that no 32-bit ray counter can wrap; the leaf budget does not (the query
// counter is 64-bit, GpuNeuralCounters): 256 leaves per ray keep the wave of 8 leaves.
TEST(WavePlan, DeepPathsKeepTheRayCountersFromWrapping) {
    const NeuralModel model;
    RenderOptions o = opts(16, &model);
    o.max_depth = 256;
    o.neural.max_rounds = 256;
    const WavePlan p = plan_wave(P1080, o, h100());
    EXPECT_EQ(p.samples, 2u); // 2^31 / (2 x 256) = 4.19M paths: two samples of 1080p
    EXPECT_EQ(p.capacity, 2 * P1080);
    // Each path adds at most 2 x 256 rays to a ray counter: under 2^31 per wave.
    EXPECT_LE(uint64_t(p.capacity) * 2 * 256, 1ull << 31);
    RenderOptions eight = o;
    eight.neural.max_rounds = 8;
    EXPECT_EQ(plan_wave(P1080, eight, h100()).capacity, p.capacity);
}

TEST(WavePlan, RandomOptionsAndLimitsStayWithinEveryBound) {
    const NeuralModel model;
    std::mt19937_64 rng(7);
    auto pick = [&](uint64_t lo, uint64_t hi) {
        return std::uniform_int_distribution<uint64_t>(lo, hi)(rng);
    };
    for (int i = 0; i < 20000; ++i) {
        const uint64_t pixels = pick(0, 3) == 0 ? pick(1, 64) : pick(1, 16384ull * 16384);
        RenderOptions o = opts(uint32_t(pick(1, 4096)), pick(0, 1) ? &model : nullptr,
                               uint32_t(pick(1, NB_NL_MAX_LEAVES_PER_ROUND)));
        o.max_depth = uint32_t(pick(1, 256));
        o.neural.max_rounds = uint32_t(pick(1, 256));
        o.max_wave_pixels = uint32_t(pick(64, 1u << 26));
        const WaveLimits l{pick(16 * MIB, 8 * GIB), pick(0, 1) ? pick(256 * MIB, 192 * GIB) : 0,
                           uint32_t(pick(0, 0x7FFFFFFF))};
        const WavePlan p = plan_wave(pixels, o, l);
        expect_within_limits(pixels, o, l, p);
        if (HasFatalFailure() || HasNonfatalFailure()) break;
    }
}

// The 64-bit query counter's carry (shared/neural_gpu.h nb_add_u64, passes/neural_args.comp): sums past
// 2^32 land in the high word, exactly as 64-bit arithmetic.
TEST(WavePlan, QueryCounterCarriesIntoItsHighWord) {
    std::mt19937_64 rng(11);
    uint32_t lo = 0xFFFFFF00u, hi = 0;
    uint64_t expect = lo;
    for (int i = 0; i < 100000; ++i) {
        const uint32_t n = i % 3 == 0 ? 0xFFFFFFFFu : uint32_t(rng() >> 40);
        nb_add_u64(lo, hi, n);
        expect += n;
        ASSERT_EQ((uint64_t(hi) << 32) | lo, expect) << i;
    }
    EXPECT_GT(hi, 1000u);
}

// Wave slots are pixel-major (shared/wavefront_gpu.h): a pixel's samples take neighbouring slots, so a
// subgroup's camera rays are few pixels' samples; every (pixel, sample) of the wave has exactly one slot,
// also in a wave of fewer samples (an image's last wave) and of an offset pixel range.
TEST(WavePlan, SlotsArePixelMajorAndCoverEachPixelSampleOnce) {
    const uint32_t offsets[] = {0u, 1000u};
    for (uint32_t offset : offsets)
        for (uint32_t samples : {1u, 5u, 16u})
            for (uint32_t first_sample : {0u, 16u}) {
                const uint32_t pixels = 37;
                std::vector<int> seen(size_t(pixels) * samples, 0);
                for (uint32_t slot = 0; slot < pixels * samples; ++slot) {
                    const uint32_t p = nb_slot_pixel(slot, offset, samples);
                    const uint32_t s = nb_slot_sample(slot, first_sample, samples);
                    ASSERT_GE(p, offset);
                    ASSERT_LT(p - offset, pixels);
                    ASSERT_GE(s, first_sample);
                    ASSERT_LT(s - first_sample, samples);
                    ++seen[size_t(p - offset) * samples + (s - first_sample)];
                    if (slot % samples != 0u) { // the previous slot is the same pixel's previous sample
                        EXPECT_EQ(nb_slot_pixel(slot - 1u, offset, samples), p);
                        EXPECT_EQ(nb_slot_sample(slot - 1u, first_sample, samples), s - 1u);
                    }
                }
                for (int n : seen) ASSERT_EQ(n, 1);
            }
}

// A pending pair packs its ray (path slot, or capacity + shadow slot) with its group count and back-face
// flag in one word (shared/wavefront_gpu.h GpuPendingLeaf); every value a wave can produce comes back.
TEST(PendingPair, RayGroupAndFlagSurviveThePacking) {
    for (uint32_t ray : {0u, 1u, 12345u, NB_PAIR_RAY_MASK - 1u, NB_PAIR_RAY_MASK})
        for (uint32_t count = 0; count <= NB_NL_MAX_LEAVES_PER_ROUND; ++count)
            for (uint32_t flag : {0u, NB_RAY_BACKFACE_BIT}) {
                const uint32_t w = nb_pair_pack_ray_group(ray, count | flag);
                EXPECT_EQ(nb_pair_ray(w), ray);
                EXPECT_EQ(nb_pair_flagged_group(w), count | flag);
                EXPECT_EQ(nb_pair_group(nb_pair_flagged_group(w)), count);
            }
    // Whatever the image and the wave limit, a hybrid wave's shadow rays (capacity + slot) fit the field.
    const NeuralModel model;
    RenderOptions o = opts(1, &model);
    o.max_wave_pixels = 0xFFFFFFFFu;
    const WavePlan p = plan_wave(1ull << 32, o, WaveLimits{~0ull, 0, 0});
    EXPECT_LE(2ull * p.capacity, uint64_t(NB_PAIR_RAY_MASK) + 1u);
}

// The split query pass's share of a round (neural_stage.h plan_split_query): whole workgroups of pairs
// whose features fit one buffer, the whole pending half where they fit, never none where one workgroup fits.
TEST(SplitQueryPlan, TakesAPendingHalfWithinOneBuffer) {
    const uint64_t quad_bytes = 8ull * NB_SPLIT_FEATURE_QUADS;
    const uint64_t nvidia = 4094ull << 20; // the H200's one-buffer bound (wave_limits)
    for (uint64_t pairs : {1ull, 63ull, 64ull, 65ull, 49152ull, 1ull << 22, 2ull * 33177600ull}) {
        for (uint64_t limit : {0ull, 1000ull, 12800ull}) {
            const uint64_t chunk = plan_split_query(pairs, nvidia, limit);
            EXPECT_GT(chunk, 0u) << pairs;
            EXPECT_EQ(chunk % NB_NEURAL_GROUP, 0u) << pairs;
            EXPECT_LE(chunk * quad_bytes, nvidia) << pairs;
            if (limit) {
                EXPECT_LE(chunk, limit) << pairs;
            }
            EXPECT_LT(chunk, pairs + NB_NEURAL_GROUP) << pairs; // no workgroup past a full half
            const uint64_t most = limit ? limit / NB_NEURAL_GROUP * NB_NEURAL_GROUP
                                        : nvidia / quad_bytes / NB_NEURAL_GROUP * NB_NEURAL_GROUP;
            if (chunk < pairs) {
                EXPECT_EQ(chunk, most) << pairs; // a partial half: as many as fit
            }
        }
    }
    // 16 samples of 1080p at 2 leaves per round: 66M pairs, 21.8M of them in 4 GiB of features (the fused
    // pass takes the rest of a round, which no default render at that size reaches).
    EXPECT_EQ(plan_split_query(2ull * 33177600ull, nvidia),
              nvidia / quad_bytes / NB_NEURAL_GROUP * NB_NEURAL_GROUP);
    EXPECT_EQ(plan_split_query(65, nvidia), 128u); // a small half: all of it, rounded up to a workgroup
    EXPECT_EQ(plan_split_query(1ull << 24, 128ull << 20), 699008u); // lavapipe's 128 MiB bound
    EXPECT_EQ(plan_split_query(49152, nvidia, 12800), 12800u);
    EXPECT_EQ(plan_split_query(100, nvidia, 10), 0u); // not one workgroup: the fused pass
    EXPECT_EQ(plan_split_query(100, 1000), 0u);
}

// The split query's features buffer (shared/neural_gpu.h nb_split_index, nb_split_tile_word): every
// (pair, quad) has its own slot, a pair's quads lie in its workgroup's block, and inside a block each
// tile of 16 features is a row-major NB_NEURAL_GROUP x 16 fp16 matrix, so that 16 consecutive pairs'
// rows of a tile are the 512 contiguous bytes one cooperative-matrix load of the MLP pass reads (row
// stride NB_SPLIT_TILE_ROW_WORDS 16-byte words), and the gather pass's two 16-byte stores per tile row
// hold that row's 4 quads in order.
TEST(SplitQueryPlan, FeaturesAreTileRowsOfEachWorkgroup) {
    const uint32_t groups = 3, pairs = groups * NB_NEURAL_GROUP, quads = pairs * NB_SPLIT_FEATURE_QUADS;
    ASSERT_EQ(NB_SPLIT_TILES * 4u, NB_SPLIT_FEATURE_QUADS);
    std::vector<int> seen(quads, 0);
    for (uint32_t k = 0; k < pairs; ++k) {
        const uint32_t block = k / NB_NEURAL_GROUP * NB_NEURAL_GROUP * NB_SPLIT_FEATURE_QUADS;
        for (uint32_t s = 0; s < NB_SPLIT_FEATURE_QUADS; ++s) {
            const uint32_t q = nb_split_index(k, s);
            ASSERT_LT(q, quads);
            ++seen[q];
            EXPECT_GE(q, block);
            EXPECT_LT(q, block + NB_NEURAL_GROUP * NB_SPLIT_FEATURE_QUADS);
            // The tile row's word (16 bytes = 2 quads) and the quad's place in it.
            EXPECT_EQ(q, 2u * nb_split_tile_word(k, s / 4u) + s % 4u) << k << " " << s;
        }
    }
    for (uint32_t q = 0; q < quads; ++q) EXPECT_EQ(seen[q], 1) << q;
    for (uint32_t g = 0; g < groups; ++g)
        for (uint32_t t = 0; t < NB_SPLIT_TILES; ++t)
            for (uint32_t r0 = 0; r0 < NB_NEURAL_GROUP; r0 += 16) {
                const uint32_t k0 = g * NB_NEURAL_GROUP + r0, w0 = nb_split_tile_word(k0, t);
                EXPECT_EQ(w0 % 2u, 0u); // 32-byte aligned tile rows
                for (uint32_t r = 0; r < 16; ++r)
                    EXPECT_EQ(nb_split_tile_word(k0 + r, t), w0 + r * NB_SPLIT_TILE_ROW_WORDS)
                        << g << " " << t << " " << r;
            }
}
