// The viewer's display pass: the renderer's linear output pixels -> packed RGBA8 display bytes on the
// GPU (passes/display.comp, shared/display.h: the same bytes as `nbvh render`'s PNGs), recorded into
// a frame slot's command buffer (film_stage.h). Before it, each frame downloaded the float film (16 bytes a pixel),
// tone-mapped it on one CPU core and uploaded the bytes again.
#pragma once
#include <cstdint>

#include <vulkan/vulkan.h>

#include "engine/core/image.h"
#include "engine/vk/buffer.h"
#include "engine/vk/commands.h"
#include "engine/vk/context.h"
#include "engine/vk/pipeline.h"

namespace nbvh::viewer {

class DisplayPass {
public:
    explicit DisplayPass(const vk::Context& ctx);

    // Records the conversion of `pixels` linear RGBA32F pixels of `linear` into `packed` (one uint32 a
    // pixel, R in the low byte, alpha 255), then a barrier that makes `packed` ready for a transfer read.
    // Binds the buffers on first use and when they change; do not call while a previous recording runs.
    void record(vk::CommandBuffer& cmd, const vk::Buffer& linear, const vk::Buffer& packed, uint32_t pixels,
                float exposure, ToneMap tone_map);

private:
    const vk::Context& ctx_;
    vk::ComputePipeline pipeline_;
    vk::DescriptorSet set_;
    VkBuffer bound_linear_ = VK_NULL_HANDLE;
    VkBuffer bound_packed_ = VK_NULL_HANDLE;
};

} // namespace nbvh::viewer
