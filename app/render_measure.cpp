#include "app/render_measure.h"

#include <algorithm>
#include <vector>

namespace nbvh::app {

render::RenderStats median_render_stats(render::WavefrontRenderer& renderer, uint32_t repeat) {
    renderer.render();
    std::vector<render::RenderStats> runs;
    for (uint32_t i = 0; i < std::max(1u, repeat); ++i) runs.push_back(renderer.render().stats);
    std::sort(runs.begin(), runs.end(), [](const auto& a, const auto& b) { return a.gpu_ms < b.gpu_ms; });
    return runs[runs.size() / 2];
}

nlohmann::json pass_ms_json(const render::RenderStats& s) {
    nlohmann::json passes = nlohmann::json::object();
    for (const auto& [name, ms] : s.pass_ms) passes[name] = ms;
    return passes;
}

nlohmann::json pass_depth_ms_json(const render::RenderStats& s) {
    nlohmann::json passes = nlohmann::json::object();
    for (const auto& [name, ms] : s.pass_depth_ms) passes[name] = ms;
    return passes;
}

std::string command_line(int argc, const char* const* argv) {
    std::string out;
    for (int i = 0; i < argc; ++i) {
        std::string a = argv[i];
        if (a.empty() || a.find_first_of(" \t'\"$\\") != std::string::npos) {
            std::string q = "'";
            for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
            a = q + "'";
        }
        out += (i ? " " : "") + a;
    }
    return out;
}

} // namespace nbvh::app
