// What a viewer frame does on the GPU before the window: the renderer's linear film (or host bytes)
// -> display pass (tone map + sRGB -> RGBA8 bytes, as `nbvh render`'s PNGs; display_pass.h) -> an RGBA8
// film image, ready to be blitted. The presenter (presenter.h) keeps FRAMES_IN_FLIGHT frame slots, each
// with its own command buffer, acquire semaphore and FilmStage, so that the CPU records frame N+1 while
// the GPU still draws frame N; the latency benchmark (tests/viewer/bench_viewer_latency.cpp) drives the
// same slots without a window.
//
// Why the slots need nothing more: a slot is reused only after its fence (CommandBuffer::begin waits),
// so its buffers, descriptor sets, image and semaphore are never touched while the GPU uses them. The
// renderer's output, which every slot reads, is written again only in the renderer's next frame, after
// at least one of its own submit-and-waits, and a fence covers every earlier submission of the queue;
// whoever destroys a renderer waits for the device first (view_renderers.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "app/viewer/display_pass.h"
#include "engine/core/image.h"
#include "engine/vk/buffer.h"
#include "engine/vk/commands.h"
#include "engine/vk/context.h"
#include "engine/vk/image.h"

namespace nbvh::viewer {

inline constexpr uint32_t FRAMES_IN_FLIGHT = 2;

// What a frame shows: the renderer's linear output on the GPU (WavefrontRenderer::output()); in the
// split view a second film right of a column; in the difference, FLIP and loss views bytes made on the
// host.
struct FilmSource {
    const vk::Buffer* linear = nullptr; // width*height RGBA32F pixels, rows top to bottom
    uint32_t width = 0, height = 0;
    float exposure = 0.0f;              // stops
    ToneMap tone_map = ToneMap::aces;   // as nbvh render's PNGs
    const vk::Buffer* linear_right = nullptr; // split view: columns >= split_column come from this film
    uint32_t split_column = 0;
    const std::vector<uint32_t>* rgba8 = nullptr; // shown instead of the films (display-pass packing)
};

class FilmStage {
public:
    // `srgb`: the film image holds sRGB-encoded texels as an _SRGB format (a swapchain of an sRGB format:
    // a blit between sRGB formats decodes and re-encodes, between UNORM ones it copies the bytes).
    FilmStage(const vk::Context& ctx, bool srgb);

    // Records the film's way into the film image (GENERAL layout, ready for transfer reads) and returns
    // it. Host bytes are copied into this slot's host buffer now.
    const vk::Image& record(vk::CommandBuffer& cmd, const FilmSource& film);

private:
    void ensure_size(uint32_t width, uint32_t height);

    const vk::Context& ctx_;
    bool srgb_ = false;
    DisplayPass display_, display_right_; // one descriptor set each: the split view's two films
    vk::Buffer packed_, packed_right_;    // RGBA8 display bytes written by the display passes
    vk::Buffer upload_;                   // host bytes (difference, FLIP and loss views)
    vk::Image image_;
};

// One frame in flight: its commands (and fence), the semaphore its swapchain image was acquired with
// (presenter only), and its film resources.
struct FrameSlot {
    FrameSlot(const vk::Context& ctx, bool srgb, const char* name)
        : cmd(ctx, name), acquired(ctx, name), film(ctx, srgb) {}
    vk::CommandBuffer cmd;
    vk::Semaphore acquired;
    FilmStage film;
};

} // namespace nbvh::viewer
