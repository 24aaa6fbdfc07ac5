#include "app/viewer/stats_panel.h"

#include <algorithm>

#include <imgui.h>

namespace nbvh::viewer {

namespace {

double mib(uint64_t bytes) { return double(bytes) / double(1u << 20); }

// Share of the path rays that spent their whole leaf budget (--neural-max-leaves) in the last frame.
double leaf_cap_fraction(const render::RenderStats& s) {
    const uint64_t rays = s.rays_primary + s.rays_secondary;
    return rays ? double(s.neural_leaf_cap_rays) / double(rays) : 0.0;
}

void pass_table(const char* id, const render::RenderStats& s) {
    if (!ImGui::BeginTable(id, 2, ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_RowBg)) return;
    for (const auto& [name, ms] : s.pass_ms) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(name.c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%.3f ms", ms);
    }
    ImGui::EndTable();
}

nlohmann::json render_json(const render::RenderStats& s) {
    nlohmann::json passes = nlohmann::json::object();
    for (const auto& [name, ms] : s.pass_ms) passes[name] = ms;
    nlohmann::json j = {{"gpu_ms", s.gpu_ms},          {"wall_ms", s.wall_ms},
                        {"pass_gpu_ms", passes},       {"rays_per_second", s.rays_per_second()},
                        {"rays", s.rays_total()},      {"non_finite_samples", s.nonfinite_samples}};
    if (!s.neural_path.empty())
        j["neural"] = {{"path", s.neural_path},
                       {"queries", s.neural_queries},
                       {"queries_per_ray", s.neural_queries_per_ray()},
                       {"query_gpu_ms", s.neural_query_ms},
                       {"queries_per_second", s.neural_queries_per_second()},
                       {"leaf_cap_rays", s.neural_leaf_cap_rays},
                       {"leaf_cap_fraction", leaf_cap_fraction(s)}};
    return j;
}

} // namespace

void draw_stats_panel(const StatsView& v) {
    const PanelInfo& info = *v.info;
    const float w = ImGui::GetIO().DisplaySize.x;
    // Right of the panel (340 px wide at x = 8), at the right edge in wide windows.
    ImGui::SetNextWindowPos(ImVec2(std::max(356.0f, w - 348.0f), 8.0f), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver); // opened on demand
    if (!ImGui::Begin("stats")) {
        ImGui::End();
        return;
    }
    ImGui::Text("%ux%u, %u spp", info.width, info.height, info.samples);
    if (v.main) {
        ImGui::Text("frame %.2f ms wall, %.2f ms GPU", info.frame_ms, v.main->gpu_ms);
        ImGui::Text("%.3g rays/s (GPU)", v.main->rays_per_second());
        if (!v.main->neural_path.empty())
            ImGui::Text("neural %s: %.2f queries/ray, %.3g queries/s", v.main->neural_path.c_str(),
                        v.main->neural_queries_per_ray(), v.main->neural_queries_per_second());
        if (!v.main->neural_path.empty())
            ImGui::Text("leaf-cap hits %llu rays (%.3f %% of path rays) at %d leaves per ray",
                        (unsigned long long)v.main->neural_leaf_cap_rays, 100.0 * leaf_cap_fraction(*v.main),
                        v.settings->max_leaves);
    }
    if (v.reference)
        ImGui::Text("classical reference: %u spp, %.2f ms wall, %.2f ms GPU", info.reference_samples,
                    info.reference_frame_ms, v.reference->gpu_ms);
    if (info.flip_mean >= 0.0)
        ImGui::Text("FLIP vs classical %.4f (%u / %u spp)", info.flip_mean, info.flip_samples,
                    info.flip_reference_samples);
    const NeuralMemory& m = v.memory;
    if (m.neural_instances > 0) {
        ImGui::Separator();
        ImGui::Text("%u neural instance(s); meshes + BLAS %.2f MiB", m.neural_instances, mib(m.classical_bytes));
        if (m.model_bytes > 0)
            ImGui::Text("model %.2f MiB (%u assets; this LoD alone %.2f MiB): %.1fx smaller", mib(m.model_bytes),
                        m.assets, mib(m.lod_bytes), double(m.classical_bytes) / double(m.model_bytes));
    }
    ImGui::Text("renderer builds %u (+%u reference), live setting changes %u, model swaps %u",
                info.renderer_builds, v.reference_builds, info.live_updates, info.model_swaps);
    if (v.main && ImGui::CollapsingHeader("GPU time per pass (last frame)")) pass_table("main passes", *v.main);
    if (v.reference && ImGui::CollapsingHeader("classical reference passes")) pass_table("ref passes", *v.reference);
    ImGui::End();
}

nlohmann::json stats_json(const StatsView& v) {
    const PanelInfo& i = *v.info;
    const ViewSettings& s = *v.settings;
    nlohmann::json j;
    j["scene"] = i.scene;
    j["device"] = i.device;
    j["width"] = i.width;
    j["height"] = i.height;
    j["view"] = view_mode_name(s.view);
    j["neural"] = s.neural;
    j["lod"] = s.lod;
    j["secondary_lod"] = s.secondary_lod;
    j["max_depth"] = s.max_depth;
    j["split"] = s.split;
    j["samples"] = i.samples;
    j["reference_samples"] = i.reference_samples;
    j["frame_ms"] = i.frame_ms;
    j["reference_frame_ms"] = i.reference_frame_ms;
    j["renderer_builds"] = i.renderer_builds;
    j["reference_builds"] = v.reference_builds;
    j["live_updates"] = i.live_updates;
    j["model_swaps"] = i.model_swaps;
    j["max_leaves"] = s.max_leaves;
    j["has_model"] = i.has_model;
    j["lod_node_counts"] = i.lod_node_counts;
    j["status"] = i.status;
    if (v.main) j["main"] = render_json(*v.main);
    if (v.reference) j["reference"] = render_json(*v.reference);
    if (i.flip_mean >= 0.0)
        j["flip"] = {{"mean", i.flip_mean}, {"samples", i.flip_samples}, {"reference_samples", i.flip_reference_samples}};
    j["memory"] = {{"model_bytes", v.memory.model_bytes},
                   {"lod_bytes", v.memory.lod_bytes},
                   {"classical_bytes", v.memory.classical_bytes},
                   {"assets", v.memory.assets},
                   {"neural_instances", v.memory.neural_instances}};
    j["loss_view"] = {{"available", i.has_node_loss}, {"leaves", i.loss_leaves}, {"lo", i.loss_lo}, {"hi", i.loss_hi}};
    j["training"] = {{"state", i.train_state},     {"step", i.train_step},   {"steps", i.train_steps},
                     {"nodes", i.train_nodes},     {"loss", i.train_loss},   {"snapshots", i.train_snapshots},
                     {"loss_history", i.train_loss_history}};
    return j;
}

} // namespace nbvh::viewer
