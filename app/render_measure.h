// Measuring renders for the benchmark subcommands (nbvh bench, nbvh study): frame time as the median of
// GPU-timestamped renders after a warm-up, and images as the PNGs `nbvh render` writes, which is what
// LDR-FLIP compares (`nbvh flip a.png b.png`).
#pragma once
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/core/image.h"
#include "engine/render/wavefront.h"

namespace nbvh::app {

// One warm-up render (pipelines, caches, clocks), then `repeat` timed ones: the stats of the median by
// GPU time. The renderer keeps its options (apply() them first).
render::RenderStats median_render_stats(render::WavefrontRenderer& renderer, uint32_t repeat);

// Per-pass GPU milliseconds of `s` as a JSON object.
nlohmann::json pass_ms_json(const render::RenderStats& s);
// The same per path depth: pass name -> [ms at depth 0, 1, ...] (RenderStats::pass_depth_ms).
nlohmann::json pass_depth_ms_json(const render::RenderStats& s);

// The command line as one string (arguments with spaces or quotes single-quoted), for result files.
std::string command_line(int argc, const char* const* argv);

} // namespace nbvh::app
