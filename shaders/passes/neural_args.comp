// One invocation between a neural traversal round and the neural query pass: hands the pairs queued so
// far to the query pass (pending_active), empties the queue for the next round, writes the indirect
// dispatch arguments (NB_NEURAL_GROUP pairs per workgroup; the split query pass: its first
// neural_params.split_chunk pairs, and the rest for the fused pass; a round of fewer than
// neural_params.split_min_pairs pairs all for the fused pass) and counts queries for --stats.
#version 460
#include "lib/bindings.glsl"
#include "lib/neural_bindings.glsl"

layout(local_size_x = 1) in;

void main() {
    uint n = counters.pending_count;
    counters.pending_count = 0u;
    neural_counters.pending_active = n;
    nb_add_u64(neural_counters.queries_total, neural_counters.queries_total_hi, n);
    neural_counters.queries_by_depth[min(pc.depth, NB_STAT_DEPTHS - 1u)] += n;
    if (n > 0u) neural_counters.rounds += 1u;
    counters.pending_dispatch.x = (n + NB_NEURAL_GROUP - 1u) / NB_NEURAL_GROUP;
    counters.pending_dispatch.y = 1u;
    counters.pending_dispatch.z = 1u;
    uint split = n >= neural_params.split_min_pairs ? min(n, neural_params.split_chunk) : 0u;
    neural_counters.overflow_first = split;
    neural_counters.split_dispatch.x = (split + NB_NEURAL_GROUP - 1u) / NB_NEURAL_GROUP;
    neural_counters.split_dispatch.y = 1u;
    neural_counters.split_dispatch.z = 1u;
    neural_counters.overflow_dispatch.x = (n - split + NB_NEURAL_GROUP - 1u) / NB_NEURAL_GROUP;
    neural_counters.overflow_dispatch.y = 1u;
    neural_counters.overflow_dispatch.z = 1u;
}
