// The GPU sampler's view of an N-BVH cut (sampling_kernels.cu first_leaf): the base-BVH nodes above and
// at the cut's leaves, copied into one compact array in depth-first order with their boxes, so the
// first-leaf search of every training ray reads a few contiguous, cache-resident nodes instead of three
// scattered arrays over the whole base BVH (1.1 M nodes for the dragon). Built on the host (cuda_core.cu
// set_cuts) whenever the cut changes; the search over it visits the same nodes in the same order as the
// CPU's first_leaf_of_cut (trainer/training_rays.cpp), so both draw the same rays.
// Host code (g++ and nvcc): plain arrays only.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

namespace nbvh::cuda {

inline constexpr uint32_t kCutNone = 0xFFFFFFFFu;     // no child / no node
inline constexpr uint32_t kCutLeafTag = 0xFFFFFFFEu;  // `right` of a cut leaf; `left` holds its slot

// 32 bytes, read as two 16-byte loads: the box as centre and half extent (box_centre_half: the first
// two steps of the sampler's dilated clip, clip_box.cuh, done once here) and the two children's compact
// indices (kCutNone where absent; a base leaf below no cut leaf has none). A cut leaf: left = leaf slot,
// right = kCutLeafTag.
struct alignas(16) CutNode {
    float centre[3], half[3];
    uint32_t left, right;
};

// trainer/training_rays.cpp dilate_box's centre 0.5 (lo + hi) and half extent 0.5 (hi - lo), in the same
// float operations (no FMA can contract them), so a clip from them is the CPU's to the bit. An empty
// box (lo > hi) has a negative half extent; a NaN or infinite bound gives a NaN or infinite one.
inline void box_centre_half(const float lo[3], const float hi[3], float centre[3], float half[3]) {
    for (int k = 0; k < 3; ++k) {
        centre[k] = 0.5f * (lo[k] + hi[k]);
        half[k] = 0.5f * (hi[k] - lo[k]);
    }
}
static_assert(sizeof(CutNode) == 32, "CutNode is two 16-byte loads");

// What the sampler's clip (clip_box.cuh) does with a box, as centre and half extent: a regular box
// (finite, not empty, |centre| + 2 |half| <= 1e37 on every axis, so its bounds stay finite at any
// dilation below 1e-3) takes the branch-free clip_regular; an empty box or one with a non-finite bound
// is never crossed (the CPU's clip_line_to_box rejects it whatever the ray), so the cut tree leaves it
// and its subtree out; anything else (finite, beyond 1e37: the scene loader stops at 1e9) is refused.
enum class CutBox { regular, never_crossed, out_of_range };
inline CutBox classify_cut_box(const float centre[3], const float half[3]) {
    bool never = false, beyond = false;
    for (int k = 0; k < 3; ++k) {
        const float c = centre[k], h = half[k];
        // NaN or infinite: lo or hi of the dilated box is NaN or infinite; h < 0: lo > hi.
        if (!std::isfinite(c) || !std::isfinite(h) || h < 0.0f)
            never = true;
        else if (!(std::fabs(c) + 2.0f * h <= 1e37f))
            beyond = true;
    }
    return never ? CutBox::never_crossed : beyond ? CutBox::out_of_range : CutBox::regular;
}

// Appends the compact tree of one cut to `nodes` and one root per part to `roots` (compact index, or
// kCutNone for an empty base BVH or a root box no ray crosses), leaving out the boxes no ray crosses
// with their subtrees (classify_cut_box; throws std::invalid_argument for one out of range). `boxes`: 6
// floats per base node; `children`: 2 per base node (kCutNone for none); `leaf_of_base_node`: the cut's slot
// per base node or -1.
void append_cut_tree(const std::vector<float>& boxes, const std::vector<uint32_t>& children,
                     const std::vector<int32_t>& leaf_of_base_node, const std::vector<uint32_t>& part_roots,
                     std::vector<CutNode>& nodes, std::vector<uint32_t>& roots);

} // namespace nbvh::cuda
