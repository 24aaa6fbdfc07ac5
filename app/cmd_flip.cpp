// nbvh flip REF TEST [--heatmap FILE.png] [--ppd P]: FLIP error between two images (flip.md).
// .png (and other 8-bit formats) are sRGB and go through LDR-FLIP; .exr are linear and go through
// HDR-FLIP (ACES, exposure range from the reference). Prints "Mean: 0.123456" like the official tool.
#include <cstdio>
#include <string>

#include "app/commands.h"
#include "engine/core/error.h"
#include "engine/core/flip.h"
#include "engine/core/image.h"
#include "engine/core/log.h"

namespace nbvh::app {
namespace {

struct FlipArgs {
    std::string reference, test, heatmap, tone_mapper = "aces";
    float ppd = 0.0f; // 0 = default viewing conditions
};

FlipToneMapper parse_flip_tone_mapper(const std::string& s) {
    if (s == "aces") return FlipToneMapper::aces;
    if (s == "hable") return FlipToneMapper::hable;
    if (s == "reinhard") return FlipToneMapper::reinhard;
    throw Error(strfmt("unknown tone mapper '%s' (aces, hable, reinhard)", s.c_str()));
}

void run_flip(const FlipArgs& a) {
    const bool ref_hdr = is_exr_path(a.reference), test_hdr = is_exr_path(a.test);
    if (ref_hdr != test_hdr)
        throw Error("flip: reference and test must both be EXR (HDR-FLIP) or both 8-bit images (LDR-FLIP)");
    const Image ref = load_image(a.reference);
    const Image test = load_image(a.test);
    if (ref.width != test.width || ref.height != test.height)
        throw Error(strfmt("flip: reference '%s' is %dx%d but test '%s' is %dx%d", a.reference.c_str(), ref.width,
                           ref.height, a.test.c_str(), test.width, test.height));
    const float ppd = a.ppd > 0.0f ? a.ppd : flip_ppd();
    FlipResult r;
    if (ref_hdr) {
        HdrFlipOptions opt;
        opt.tone_mapper = parse_flip_tone_mapper(a.tone_mapper);
        r = flip_hdr(ref, test, ppd, opt);
        log_info("HDR-FLIP: %d exposures from %.4f to %.4f stops, %.4f ppd", r.exposure_count,
                 double(r.start_exposure), double(r.stop_exposure), double(ppd));
    } else {
        r = flip_ldr(ref, test, ppd);
    }
    std::printf("Mean: %.6f\n", double(r.mean));
    if (!a.heatmap.empty()) save_flip_heatmap(a.heatmap, r);
}

} // namespace

void add_flip_command(CLI::App& app) {
    auto args = std::make_shared<FlipArgs>();
    auto* cmd = app.add_subcommand("flip", "FLIP error between a reference and a test image (PNG: LDR, EXR: HDR)");
    cmd->add_option("reference", args->reference, "reference image (.png or .exr)")->required();
    cmd->add_option("test", args->test, "test image, same size and kind")->required();
    cmd->add_option("--heatmap", args->heatmap, "write the error map (magma colour map) to this PNG");
    cmd->add_option("--ppd", args->ppd, "pixels per degree (default 67.0206: 0.7 m wide 4K monitor at 0.7 m)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--tone-mapper", args->tone_mapper, "HDR-FLIP tone mapper: aces (default), hable, reinhard");
    cmd->callback([args] { run_flip(*args); });
}

} // namespace nbvh::app
