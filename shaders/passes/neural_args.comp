// One workgroup between a neural traversal round and the neural query pass: hands the pairs queued so
// far (pending half nb_nl_half(pc.mode)) to the query pass (pending_active), empties the queue for the
// next round, writes the indirect dispatch arguments (NB_NEURAL_GROUP pairs per workgroup) and counts
// queries for --stats. With the leaf-binned order (shared/neural_gpu.h NB_NL_SORT_*) it also turns the
// half's bin counts into bin offsets (exclusive scan, for passes/neural_sort.comp) and zeroes the other
// half's bins, which the next traversal round counts into (their offsets served the previous round).
// Before the tail pass (NB_NL_ARGS_TAIL, no sort follows) both halves are zeroed, so every neural loop
// starts from zero counts.
#version 460
#include "lib/bindings.glsl"
#include "lib/neural_bindings.glsl"

layout(local_size_x = NB_NL_SORT_SCAN_THREADS) in;

#define NB_SCAN_PER_THREAD (NB_NL_SORT_BINS / NB_NL_SORT_SCAN_THREADS)

shared uint s_scan[NB_NL_SORT_SCAN_THREADS];

void main() {
    uint t = gl_LocalInvocationID.x;
    if (t == 0u) {
        uint n = counters.pending_count;
        counters.pending_count = 0u;
        neural_counters.pending_active = n;
        neural_counters.queries_total += n;
        if (n > 0u) neural_counters.rounds += 1u;
        counters.pending_dispatch.x = (n + NB_NEURAL_GROUP - 1u) / NB_NEURAL_GROUP;
        counters.pending_dispatch.y = 1u;
        counters.pending_dispatch.z = 1u;
    }
    uint half_ = nb_nl_half(pc.mode);
    uint mine = half_ * NB_NL_SORT_BINS + t * NB_SCAN_PER_THREAD;      // this invocation's bins
    uint other = (half_ ^ 1u) * NB_NL_SORT_BINS + t * NB_SCAN_PER_THREAD;
    for (uint j = 0u; j < NB_SCAN_PER_THREAD; ++j) nl_bins[other + j] = 0u;
    if ((pc.mode & NB_NL_ARGS_TAIL) != 0u) {
        for (uint j = 0u; j < NB_SCAN_PER_THREAD; ++j) nl_bins[mine + j] = 0u;
        return;
    }
    if (!nb_nl_sorted()) return; // uniform: the bins stay zero
    // Exclusive scan of the counts: each invocation sums its bins, an inclusive Hillis-Steele scan of
    // those sums in shared memory, then each invocation writes its bins' offsets.
    uint c[NB_SCAN_PER_THREAD];
    uint sum = 0u;
    for (uint j = 0u; j < NB_SCAN_PER_THREAD; ++j) {
        c[j] = nl_bins[mine + j];
        sum += c[j];
    }
    s_scan[t] = sum;
    barrier();
    for (uint d = 1u; d < NB_NL_SORT_SCAN_THREADS; d <<= 1u) {
        uint add = t >= d ? s_scan[t - d] : 0u;
        barrier();
        s_scan[t] += add;
        barrier();
    }
    uint offset = s_scan[t] - sum;
    for (uint j = 0u; j < NB_SCAN_PER_THREAD; ++j) {
        nl_bins[mine + j] = offset;
        offset += c[j];
    }
}
