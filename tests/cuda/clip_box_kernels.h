// Device evaluation of the CUDA sampler's ray/box clips (trainer/cuda/clip_box.cuh) for clip_box_test.cpp,
// which compares it bit for bit with the CPU's clip_line_to_box(dilate_box()) (trainer/training_rays.h):
// both backends must find the same first leaf, entry and exit for a seed.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace nbvh::test {

struct ClipCase {
    float box[6];        // lo xyz, hi xyz
    float origin[3], dir[3];
    float dilation;
    uint32_t hit;        // out
    float t_entry, t_exit; // out (when hit)
    // The branch-free clip_regular, evaluated where it applies (a box the cut tree keeps as regular,
    // cut_tree.h classify_cut_box, and a ray with normal direction components, slab_ray_regular).
    uint32_t regular;                      // out: it applied
    uint32_t hit_regular;                  // out
    float t_entry_regular, t_exit_regular; // out (when hit_regular)
};

// On the first CUDA device; returns "" or the CUDA error.
std::string clip_on_device(std::vector<ClipCase>& cases);

} // namespace nbvh::test
