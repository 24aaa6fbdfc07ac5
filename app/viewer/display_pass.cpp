#include "app/viewer/display_pass.h"

#include <algorithm>
#include <cmath>

namespace nbvh::viewer {

namespace {
struct DisplayPush {
    uint32_t pixel_count;
    float scale;
    uint32_t tone_map;
    uint32_t pad;
};
static_assert(sizeof(DisplayPush) == 16);

vk::PipelineDesc display_desc() {
    vk::PipelineDesc d;
    d.shader = "passes/display.comp";
    d.bindings = {{0, vk::BindingType::storage_buffer, 1}, {1, vk::BindingType::storage_buffer, 1}};
    d.push_constant_bytes = sizeof(DisplayPush);
    return d;
}
} // namespace

DisplayPass::DisplayPass(const vk::Context& ctx)
    : ctx_(ctx), pipeline_(ctx, display_desc()), set_(ctx, pipeline_) {}

void DisplayPass::record(vk::CommandBuffer& cmd, const vk::Buffer& linear, const vk::Buffer& packed, uint32_t pixels,
                         float exposure, ToneMap tone_map) {
    if (linear.handle() != bound_linear_ || packed.handle() != bound_packed_) {
        set_.bind(0, linear).bind(1, packed);
        bound_linear_ = linear.handle();
        bound_packed_ = packed.handle();
    }
    const DisplayPush push{pixels, std::exp2(exposure), tone_map_id(tone_map), 0u};
    // 2D grid when the pixels need more groups than one dimension allows (large windows).
    const uint32_t groups = (pixels + 255u) / 256u; // passes/display.comp: 256 invocations a group
    const uint32_t gx = std::max(1u, std::min(groups, ctx_.features().max_workgroup_count[0]));
    const uint32_t gy = (groups + gx - 1u) / gx;
    NBVH_CHECK_MSG(gy <= ctx_.features().max_workgroup_count[1], "window too large for the display pass");
    cmd.bind(pipeline_, set_).push(push);
    if (groups > 0) cmd.dispatch(gx, gy);
    cmd.barrier(vk::Barrier::compute_to_transfer);
}

} // namespace nbvh::viewer
