// How many paths one wave of the wavefront renderer holds (the queues' capacity) and how many samples
// of every pixel it traces. A pass costs its work plus the latency of its slowest warp, and a path's
// deep bounces carry few rays: a wave of several samples pays that tail once for all of them
// (results/perf/frame_depths.md). The capacity is bounded by --wave-pixels, one buffer's bytes (the
// storage-binding range and one allocation's size), a quarter of the GPU's memory, the indirect
// dispatch of the neural query pass and the 32-bit statistics counters. A pure function of the options
// and the device's limits, tested without a GPU (tests/render/wave_plan_test.cpp).
#pragma once
#include <cstdint>

#include "engine/render/wavefront.h"
#include "engine/vk/context.h"

namespace nbvh::render {

struct WaveLimits {
    uint64_t buffer_bytes = 128ull << 20; // one buffer: min(maxStorageBufferRange, maxMemoryAllocationSize)
    uint64_t device_local_bytes = 0;      // the largest device-local heap (0: unknown, no bound)
    uint32_t max_workgroups_x = 0;        // maxComputeWorkGroupCount[0] (0: unknown, no bound)
};
WaveLimits wave_limits(const vk::DeviceFeatures& dev);

struct WavePlan {
    uint32_t capacity = 0; // paths per wave (>= 64)
    uint32_t samples = 1;  // samples of every pixel per wave (1 when the image takes several waves)
};

// Paths of a wave of several samples, whatever --wave-pixels says (its default too: 16 samples of 1080p),
// and samples of every pixel per wave: 32 (16.6M paths at the study's 960x540; a renderer's queues are
// bounded by a quarter of the GPU's memory, and `nbvh study` holds several renderers at once).
constexpr uint64_t NB_WAVE_MAX_PATHS = 1u << 25;
constexpr uint32_t NB_WAVE_MAX_SAMPLES = 32;

// Queue bytes per path: classical queues (two path-ray queues, hits, shadow rays, sample radiance),
// and in a renderer with a model the neural state of a path and of its shadow ray and its pending
// (ray, leaf) pairs.
uint64_t wave_bytes_per_path(const RenderOptions& o);

// Paths one submission may trace without a 32-bit statistics counter growing by 2^31 (read after each
// submission): a path adds at most 2 * max_depth rays to a ray counter. The neural query counter, which
// grows with the leaf budget, is 64-bit: the budget does not bound the wave. (apply() rebuilds instead of
// raising max_depth past this bound for the built wave.)
uint64_t counter_safe_paths(const RenderOptions& o);

// No more samples per wave than o.spp: a renderer built for one sample per call (the viewer) keeps one
// sample's queues (more samples per call then take more waves, same image).
WavePlan plan_wave(uint64_t pixels, const RenderOptions& o, const WaveLimits& limits);

} // namespace nbvh::render
