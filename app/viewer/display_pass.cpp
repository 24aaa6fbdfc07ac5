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

void DisplayPass::record(VkCommandBuffer cmd, const vk::Buffer& linear, const vk::Buffer& packed, uint32_t pixels,
                         float exposure, ToneMap tone_map) {
    if (linear.handle() != bound_linear_ || packed.handle() != bound_packed_) {
        set_.bind(0, linear).bind(1, packed);
        bound_linear_ = linear.handle();
        bound_packed_ = packed.handle();
    }
    const DisplayPush push{pixels, std::exp2(exposure), tone_map_id(tone_map), 0u};
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.handle());
    const VkDescriptorSet set = set_.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.layout(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd, pipeline_.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
    const uint32_t groups = (pixels + 255u) / 256u; // passes/display.comp: 256 invocations a group
    const uint32_t gx = std::min(groups, ctx_.features().max_workgroup_count[0]);
    const uint32_t gy = (groups + gx - 1u) / gx;
    NBVH_CHECK_MSG(gy <= ctx_.features().max_workgroup_count[1], "window too large for the display pass");
    if (groups > 0) vkCmdDispatch(cmd, gx, gy, 1);
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &b, 0,
                         nullptr, 0, nullptr);
}

} // namespace nbvh::viewer
