// The viewer's GPU display pass (app/viewer/display_pass.h, passes/display.comp) against the host's PNG
// encoding (to_srgb8): both go through shaders/shared/display.h, so the window shows the bytes `nbvh
// render` writes. HDR values, exposure, NaN / +-Inf / negative pixels, every tone map; lavapipe with
// validation on.
#include "app/viewer/display_pass.h"
#include "app/viewer/film_stage.h"
#include "engine/core/image.h"
#include "engine/vk/commands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace nbvh;

namespace {

Image hdr_test_image(int w, int h) {
    Image img(w, h, 4);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        float* p = img.data.data() + i * 4;
        for (int c = 0; c < 3; ++c) p[c] = std::pow(2.0f, 16.0f * u(rng) - 10.0f) * (u(rng) < 0.05f ? -1.0f : 1.0f);
        p[3] = 1.0f;
    }
    const float inf = std::numeric_limits<float>::infinity();
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(), inf, -inf, 0.0f, 1.0f, 3.0e38f, 1e-30f};
    for (size_t k = 0; k < std::size(specials); ++k)
        for (int c = 0; c < 3; ++c) img.data[k * 4 + size_t(c)] = specials[(k + size_t(c)) % std::size(specials)];
    return img;
}

} // namespace

TEST(DisplayPass, MatchesThePngEncoding) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    const Image img = hdr_test_image(331, 97); // not a multiple of the 256-invocation group
    const uint32_t n = uint32_t(img.pixel_count());
    vk::Buffer linear = vk::make_buffer(ctx, img.data, "linear");
    vk::Buffer packed(ctx, uint64_t(n) * 4, vk::MemoryKind::device, 0, "packed");
    viewer::DisplayPass pass(ctx);
    for (ToneMap tm : {ToneMap::aces, ToneMap::clamp, ToneMap::reinhard}) {
        for (float exposure : {0.0f, -2.5f, 3.0f}) {
            vk::CommandBuffer cmd(ctx, "display test");
            cmd.begin();
            pass.record(cmd, linear, packed, n, exposure, tm);
            cmd.submit_and_wait();
            const std::vector<uint32_t> gpu = packed.download<uint32_t>(n);
            PngEncode enc;
            enc.exposure = exposure;
            enc.tone_map = tm;
            int channels = 0;
            const std::vector<uint8_t> host = to_srgb8(img, enc, &channels);
            ASSERT_EQ(channels, 3);
            size_t exact = 0, off_by_one = 0, worse = 0;
            for (uint32_t i = 0; i < n; ++i) {
                for (int c = 0; c < 3; ++c) {
                    const int g = int((gpu[i] >> (8 * c)) & 0xFFu), h = host[size_t(i) * 3 + size_t(c)];
                    const int d = std::abs(g - h);
                    exact += d == 0;
                    off_by_one += d == 1;
                    worse += d > 1;
                }
                EXPECT_EQ(gpu[i] >> 24, 255u);
            }
            // The same formulas in fp32; the GPU's pow may differ from std::pow by an ulp, which can
            // move a value across a rounding boundary of the 8-bit quantisation, never further.
            EXPECT_EQ(worse, 0u) << "tone map " << int(tm) << ", exposure " << exposure;
            EXPECT_GE(double(exact) / double(3 * n), 0.999) << "tone map " << int(tm) << ", exposure " << exposure;
            // The special pixels: NaN -> 0, +Inf -> white, -Inf -> 0 under every tone map (host rules).
            EXPECT_EQ(gpu[0] & 0xFFu, host[0]);
        }
    }
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// A frame slot's film stage (app/viewer/film_stage.h): the split view's image is the left film's display
// bytes left of the column and the right film's right of it; host bytes go in unchanged. Two slots are
// recorded and submitted before either is waited for (frames in flight), each keeping its own image.
TEST(FilmStage, SplitAndHostBytesWithTwoFramesInFlight) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    const uint32_t w = 37, h = 11, n = w * h;
    const Image a = hdr_test_image(int(w), int(h));
    std::vector<float> bdata = a.data;
    for (float& v : bdata) v *= 0.25f; // other display bytes
    vk::Buffer la = vk::make_buffer(ctx, a.data, "left film"), lb = vk::make_buffer(ctx, bdata, "right film");
    // Each film's display bytes alone, through the display pass.
    auto packed_of = [&](const vk::Buffer& film) {
        vk::Buffer out(ctx, uint64_t(n) * 4, vk::MemoryKind::device, 0, "packed");
        viewer::DisplayPass pass(ctx);
        vk::CommandBuffer cmd(ctx, "display");
        cmd.begin();
        pass.record(cmd, film, out, n, 0.5f, ToneMap::aces);
        cmd.submit_and_wait();
        return out.download<uint32_t>(n);
    };
    const std::vector<uint32_t> pa = packed_of(la), pb = packed_of(lb);
    ASSERT_NE(pa, pb);
    std::vector<uint32_t> host(n);
    for (uint32_t i = 0; i < n; ++i) host[i] = 0xFF000000u | (i * 2654435761u >> 8);

    viewer::FrameSlot split_slot(ctx, false, "slot 0"), host_slot(ctx, false, "slot 1");
    viewer::FilmSource split{&la, w, h, 0.5f, ToneMap::aces, &lb, 13, nullptr};
    viewer::FilmSource bytes{&la, w, h, 0.5f, ToneMap::aces, nullptr, 0, &host};
    split_slot.cmd.begin();
    const vk::Image& split_image = split_slot.film.record(split_slot.cmd, split);
    split_slot.cmd.submit();
    host_slot.cmd.begin();
    const vk::Image& host_image = host_slot.film.record(host_slot.cmd, bytes);
    host_slot.cmd.submit();
    EXPECT_TRUE(split_slot.cmd.in_flight() || host_slot.cmd.in_flight());
    split_slot.cmd.wait();
    host_slot.cmd.wait();
    std::vector<uint32_t> got(n);
    split_image.download(got.data(), got.size() * 4);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            ASSERT_EQ(got[y * w + x], (x < 13 ? pa : pb)[y * w + x]) << x << "," << y;
    host_image.download(got.data(), got.size() * 4);
    EXPECT_EQ(got, host);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}
