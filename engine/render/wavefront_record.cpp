// Command recording of the wavefront renderer (engine/render/wavefront.h): one pass with its dispatch
// and barrier, a sample wave's passes, and the neural rounds of a bounce (batched rounds of traversal,
// query and resume, then the tail).
#include "engine/render/wavefront.h"
#include "engine/render/wavefront_passes.h"

#include "shaders/shared/wavefront_gpu.h"

namespace nbvh::render {

using namespace wavefront_passes;

GpuPassConstants WavefrontRenderer::constants(uint32_t queue, uint32_t depth, const Wave& w, uint32_t mode) const {
    GpuPassConstants pc{};
    pc.in_queue = queue;
    pc.depth = depth;
    pc.sample_index = w.sample;
    pc.pixel_offset = w.offset;
    pc.pixel_count = w.count;
    pc.mode = mode;
    pc.wave_samples = w.samples;
    return pc;
}

void WavefrontRenderer::record_pass(vk::CommandBuffer& cmd, size_t pass, const GpuPassConstants& pc,
                                    Dispatch dispatch, uint64_t items) {
    // The split query's MLP pass is timed as the query pass (it decodes and stores the results).
    cmd.begin_pass(PASS_SHADERS[pass == NEURAL_MLP ? NEURAL_QUERY : pass],
                   timer_.available() ? &timer_ : nullptr, pc.depth);
    cmd.bind(pipelines_[pass], sets_[pass]).push(pc);
    switch (dispatch) {
    case Dispatch::items: cmd.dispatch_items(items, NB_WAVEFRONT_GROUP); break;
    case Dispatch::single: cmd.dispatch(1); break;
    case Dispatch::indirect_rays: cmd.dispatch_indirect(buffers_[NB_BIND_COUNTERS], NB_COUNTERS_RAY_DISPATCH_OFFSET); break;
    case Dispatch::indirect_shadow:
        cmd.dispatch_indirect(buffers_[NB_BIND_COUNTERS], NB_COUNTERS_SHADOW_DISPATCH_OFFSET);
        break;
    case Dispatch::indirect_pending:
        cmd.dispatch_indirect(buffers_[NB_BIND_COUNTERS], NB_COUNTERS_PENDING_DISPATCH_OFFSET);
        break;
    case Dispatch::indirect_split:
        cmd.dispatch_indirect(buffers_[NB_BIND_NEURAL_COUNTERS], NB_NEURAL_SPLIT_DISPATCH_OFFSET);
        break;
    case Dispatch::indirect_overflow:
        cmd.dispatch_indirect(buffers_[NB_BIND_NEURAL_COUNTERS], NB_NEURAL_OVERFLOW_DISPATCH_OFFSET);
        break;
    }
    cmd.end_pass();
    // queue_args writes dispatch arguments; everything else feeds the next pass's shader reads.
    cmd.barrier(pass == QUEUE_ARGS || pass == NEURAL_ARGS ? vk::Barrier::compute_to_indirect
                                                          : vk::Barrier::compute_to_compute);
}

// Op 0 of `traverse_pass` over every ray (path queue or shadow rays), then per round: hand the queued
// pairs to the query pass, query them, and resume exactly the rays of those pairs (op 1, dispatched over
// the pairs). Round r queries pending half r & 1; the traversal after it queues into the other half.
void WavefrontRenderer::record_neural_rounds(vk::CommandBuffer& cmd, size_t traverse_pass, uint32_t q, uint32_t depth,
                                             const Wave& w) {
    const bool shadow = traverse_pass == NEURAL_SHADOW;
    const Dispatch all = shadow ? Dispatch::indirect_shadow : Dispatch::indirect_rays;
    const bool sort = record_ray_sort(cmd, q, depth, w, shadow); // op 0 reads the ray order
    record_pass(cmd, traverse_pass, constants(q, depth, w, sort ? NB_NL_MODE_SORTED : 0u), all);
    using RayClass = NeuralStage::RayClass;
    const uint32_t batched =
        neural_->batched_rounds(shadow ? RayClass::shadow : depth > 0 ? RayClass::path : RayClass::camera);
    for (uint32_t round = 0; round < batched; ++round) {
        const uint32_t half = round & 1u;
        record_pass(cmd, NEURAL_ARGS, constants(q, depth, w, 0), Dispatch::single);
        record_query(cmd, constants(q, depth, w, half << 2));
        record_pass(cmd, traverse_pass, constants(q, depth, w, 1u | ((half ^ 1u) << 2)),
                    Dispatch::indirect_pending);
    }
    // The few rays left finish in one pass (query, resume, query, ... per invocation).
    record_pass(cmd, NEURAL_ARGS, constants(q, depth, w, 0), Dispatch::single);
    record_pass(cmd, NEURAL_TAIL, constants(q, depth, w, (batched & 1u) << 2), Dispatch::indirect_pending);
}

uint32_t WavefrontRenderer::neural_query_passes() const {
    if (!neural_) return 0;
    return neural_->split() ? (neural_->split_overflow() ? 3 : 2) : 1;
}

void WavefrontRenderer::record_query(vk::CommandBuffer& cmd, const GpuPassConstants& pc) {
    if (!neural_->split()) {
        record_pass(cmd, NEURAL_QUERY, pc, Dispatch::indirect_pending);
        return;
    }
    // The round's first split_chunk pairs (neural_args wrote the dispatches); where a round can hold
    // more than the features buffer, the fused pass takes the rest (none in most rounds).
    record_pass(cmd, NEURAL_GATHER, pc, Dispatch::indirect_split);
    record_pass(cmd, NEURAL_MLP, pc, Dispatch::indirect_split);
    if (neural_->split_overflow()) {
        GpuPassConstants rest = pc;
        rest.mode |= NB_QUERY_MODE_OVERFLOW;
        record_pass(cmd, NEURAL_QUERY, rest, Dispatch::indirect_overflow);
    }
}

bool WavefrontRenderer::record_ray_sort(vk::CommandBuffer& cmd, uint32_t q, uint32_t depth, const Wave& w, bool shadow) {
    if (params_.sort_rays == 0 || (!shadow && depth == 0)) return false; // camera rays keep pixel order
    record_pass(cmd, RAY_SORT, constants(q, depth, w, shadow ? NB_ARGS_MODE_SHADOW : NB_ARGS_MODE_RAYS),
                shadow ? Dispatch::indirect_shadow : Dispatch::indirect_rays);
    return true;
}

void WavefrontRenderer::record_sample_wave(vk::CommandBuffer& cmd, const Wave& w) {
    record_pass(cmd, CAMERA, constants(0, 0, w, 0), Dispatch::items, uint64_t(w.count) * w.samples);
    uint32_t q = 0;
    for (uint32_t depth = 0; depth < options_.max_depth; ++depth) {
        record_pass(cmd, QUEUE_ARGS, constants(q, depth, w, NB_ARGS_MODE_RAYS), Dispatch::single);
        if (hybrid_) {
            // Closest hits through triangles and neural leaves: queue a pair per ray, query, resume.
            record_neural_rounds(cmd, NEURAL_TRAVERSE, q, depth, w);
        } else {
            const bool sort = record_ray_sort(cmd, q, depth, w, false);
            record_pass(cmd, TRAVERSE, constants(q, depth, w, sort ? NB_TRAVERSE_MODE_SORTED : 0u), Dispatch::indirect_rays);
        }
        record_pass(cmd, SHADE, constants(q, depth, w, 0), Dispatch::indirect_rays);
        if (features_.has_lights()) {
            record_pass(cmd, QUEUE_ARGS, constants(q, depth, w, NB_ARGS_MODE_SHADOW),
                        Dispatch::single);
            // Hybrid: neural_shadow's op 0 reads the order and decides; shadow.comp only applies it.
            const bool sort = !hybrid_ && record_ray_sort(cmd, q, depth, w, true);
            if (hybrid_) record_neural_rounds(cmd, NEURAL_SHADOW, q, depth, w);
            record_pass(cmd, SHADOW,
                        constants(q, depth, w, hybrid_ ? NB_SHADOW_MODE_HYBRID : (sort ? NB_SHADOW_MODE_SORTED : 0u)),
                        Dispatch::indirect_shadow);
        }
        q = 1 - q;
    }
    record_pass(cmd, ACCUMULATE, constants(0, 0, w, 0), Dispatch::items, w.count);
}

} // namespace nbvh::render
