#include "engine/render/wave_plan.h"

#include <algorithm>

#include "engine/render/gpu_memory.h"
#include "engine/render/neural_stage.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/wavefront_gpu.h"

static_assert(NB_NL_MAX_LEAVES_PER_ROUND <= 15u, "a pair's group count is packed in 4 bits (GpuPendingLeaf)");

namespace nbvh::render {

WaveLimits wave_limits(const vk::DeviceFeatures& dev) {
    WaveLimits l;
    // NVIDIA: a 4096-MiB binding range but 4094-MiB allocations (a 16M-path hybrid wave's pending pairs,
    // sized to the first, failed on the second).
    if (dev.max_storage_buffer_range) l.buffer_bytes = dev.max_storage_buffer_range;
    if (dev.max_allocation_size) l.buffer_bytes = std::min(l.buffer_bytes, dev.max_allocation_size);
    l.device_local_bytes = dev.device_local_bytes;
    l.max_workgroups_x = dev.max_workgroup_count[0];
    return l;
}

uint64_t wave_bytes_per_path(const RenderOptions& o) {
    // Two path-ray queues, hits, shadow rays, sample radiance (3), the two queues' ray order (2).
    const uint64_t classical = 4ull * (2 * NB_RAY_WORDS + NB_HIT_WORDS + NB_SHADOW_WORDS + 3 + 2);
    return classical + (o.neural.model ? neural_scratch_bytes_per_ray(effective_leaves_per_round(o.neural)) : 0);
}

uint64_t counter_safe_paths(const RenderOptions& o) {
    // Rays (path or shadow) grow by at most 2 per path and bounce; the query counter, which grows with
    // the leaf budget, is 64-bit (GpuNeuralCounters).
    const uint64_t per_path = 2ull * std::max(o.max_depth, 1u);
    return std::max<uint64_t>((1ull << 31) / per_path, 64);
}

WavePlan plan_wave(uint64_t pixels, const RenderOptions& o, const WaveLimits& limits) {
    pixels = std::max<uint64_t>(pixels, 1);
    const uint64_t max_paths = std::min<uint64_t>(std::max<uint32_t>(o.max_wave_pixels, 64), counter_safe_paths(o));
    const uint64_t samples = std::clamp<uint64_t>(std::min(NB_WAVE_MAX_PATHS, max_paths) / pixels, 1,
                                                  std::min<uint64_t>(NB_WAVE_MAX_SAMPLES, std::max(o.spp, 1u)));
    uint64_t cap = std::min<uint64_t>(pixels * samples, max_paths);
    const uint64_t b = limits.buffer_bytes;
    cap = std::min<uint64_t>(cap, b / (2ull * NB_RAY_WORDS * 4ull)); // the two path-ray queues: one binding
    // Every pass dispatches one invocation per path (camera rays directly, the others indirectly).
    if (limits.max_workgroups_x) cap = std::min<uint64_t>(cap, uint64_t(limits.max_workgroups_x) * NB_WAVEFRONT_GROUP);
    // With a model the neural state (path and shadow ray) and the pending pairs are one binding each,
    // allocated also for a classical start (apply() switches without a rebuild).
    if (o.neural.model) {
        const uint64_t k = effective_leaves_per_round(o.neural);
        cap = std::min<uint64_t>(cap, b / (2ull * sizeof(GpuNeuralRayState)));
        cap = std::min<uint64_t>(cap, b / (k * sizeof(GpuPendingLeaf))); // each half of the pending queue
        // A pair's ray (path slot, or capacity + shadow slot) is packed in NB_PAIR_RAY_BITS bits.
        cap = std::min<uint64_t>(cap, (uint64_t(NB_PAIR_RAY_MASK) + 1u) / 2u);
        // The query pass is dispatched indirectly over up to k pairs per ray (not checked on the host).
        if (limits.max_workgroups_x) cap = std::min<uint64_t>(cap, uint64_t(limits.max_workgroups_x) * NB_NEURAL_GROUP / k);
    }
    // The queues take at most wave_memory_share of the GPU's memory (a quarter by default; 196 bytes per
    // classical path, ~515 per hybrid one with 2 leaves per round: a quarter of an 8 GiB card holds
    // ~11M / ~4M paths).
    if (limits.device_local_bytes)
        cap = std::min<uint64_t>(cap, uint64_t(double(limits.device_local_bytes) * o.wave_memory_share) /
                                          wave_bytes_per_path(o));
    cap = std::clamp<uint64_t>(cap, 64, 0xFFFFFFFFull);
    WavePlan plan;
    plan.samples = cap >= pixels ? uint32_t(std::min<uint64_t>(samples, cap / pixels)) : 1u;
    // No slot a wave would not use (an image of several waves keeps the bound: its last wave is partial).
    if (cap >= pixels) cap = std::max<uint64_t>(pixels * plan.samples, 64);
    plan.capacity = uint32_t(cap);
    return plan;
}

} // namespace nbvh::render
