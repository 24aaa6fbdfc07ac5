// Leaf-binned query order (shared/neural_gpu.h NB_NL_SORT_*), after passes/neural_args.comp turned the
// bin counts of pending half nb_nl_half(pc.mode) into offsets: each queued pair takes the next position
// of its leaf's bin, and the order array maps that position to the pair; the query pass then evaluates
// the pairs bin by bin. Dispatched indirectly over the pairs, like the query pass.
#version 460
#include "lib/bindings.glsl"
#include "lib/neural_bindings.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= neural_counters.pending_active) return;
    uint half_ = nb_nl_half(pc.mode);
    uint leaf = pending_leaves[nb_nl_pending_index(half_, k)].leaf;
    uint pos = atomicAdd(nl_bins[nb_nl_bin_index(half_, leaf)], 1u);
    nl_order[pos] = k;
}
