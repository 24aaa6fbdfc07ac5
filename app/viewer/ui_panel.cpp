#include "app/viewer/ui_panel.h"

#include <algorithm>
#include <cstdlib>

#include <imgui.h>

namespace nbvh::viewer {

int lod_for_node_count(const std::vector<uint32_t>& counts, uint32_t nodes) {
    int best = 0;
    for (size_t l = 1; l < counts.size(); ++l) {
        const long long d = std::llabs((long long)counts[l] - (long long)nodes);
        const long long b = std::llabs((long long)counts[size_t(best)] - (long long)nodes);
        if (d < b) best = int(l);
    }
    return best;
}

PanelActions draw_panel(ViewSettings& s, const PanelInfo& info) {
    PanelActions act;
    // Small windows (headless tests) start with the panel collapsed so the film stays visible.
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowCollapsed(info.width < 480, ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("nbvh view")) {
        ImGui::End();
        return act;
    }
    ImGui::Text("%s  %ux%u", info.scene.c_str(), info.width, info.height);
    ImGui::TextDisabled("%s", info.device.c_str());
    ImGui::Text("frame %.1f ms  |  %u spp", info.frame_ms, info.samples);
    ImGui::Text("%.3g rays/s (GPU)", info.rays_per_second);
    ImGui::Text("renderer builds %u, live setting changes %u", info.renderer_builds, info.live_updates);
    if (ImGui::Button("reset camera (R)")) act.reset_camera = true;
    ImGui::SameLine();
    if (ImGui::Button("restart")) act.reset_accumulation = true;

    ImGui::Separator();
    ImGui::TextUnformatted("path tracing");
    ImGui::SliderInt("spp / frame", &s.spp_per_frame, 1, 16);
    ImGui::SliderInt("max depth", &s.max_depth, 1, 32);
    if (ImGui::IsItemDeactivatedAfterEdit()) act.rebuild = true;
    ImGui::SliderInt("max spp", &s.max_samples, 0, 65536, s.max_samples == 0 ? "unlimited" : "%d");
    ImGui::SliderFloat("exposure", &s.exposure, -8.0f, 8.0f, "%+.1f stops");

    if (info.has_model) {
        ImGui::Separator();
        ImGui::TextUnformatted("neural (N-BVH)");
        if (ImGui::Checkbox("neural (off: classical reference)", &s.neural)) act.rebuild = true;
        const int lods = int(std::max<size_t>(1, info.lod_node_counts.size()));
        ImGui::BeginDisabled(!s.neural);
        ImGui::SliderInt("LoD", &s.lod, 0, lods - 1);
        if (ImGui::IsItemDeactivatedAfterEdit()) act.rebuild = true;
        // The node-count slider: pick the cut by its size; snaps to the nearest LoD's count.
        if (!info.lod_node_counts.empty()) {
            const auto [mn, mx] = std::minmax_element(info.lod_node_counts.begin(), info.lod_node_counts.end());
            int nodes = int(info.lod_node_counts[size_t(std::clamp(s.lod, 0, lods - 1))]);
            if (ImGui::SliderInt("nodes", &nodes, int(*mn), int(*mx)))
                s.lod = lod_for_node_count(info.lod_node_counts, uint32_t(nodes));
            if (ImGui::IsItemDeactivatedAfterEdit()) act.rebuild = true;
        }
        ImGui::SliderInt("secondary LoD", &s.secondary_lod, -1, lods - 1, s.secondary_lod < 0 ? "same" : "%d");
        if (ImGui::IsItemDeactivatedAfterEdit()) act.rebuild = true;
        ImGui::EndDisabled();
        // Neural surfaces are shaded with their asset's glTF material unless overridden here.
        if (ImGui::Checkbox("override material", &s.override_material)) act.rebuild = true;
        ImGui::BeginDisabled(!s.override_material);
        ImGui::SliderFloat("roughness", &s.roughness, 0.0f, 1.0f);
        if (ImGui::IsItemDeactivatedAfterEdit()) act.rebuild = true;
        ImGui::SliderFloat("metallic", &s.metallic, 0.0f, 1.0f);
        if (ImGui::IsItemDeactivatedAfterEdit()) act.rebuild = true;
        ImGui::EndDisabled();
        if (s.neural && !info.neural_path.empty())
            ImGui::Text("%s, %.2f queries/ray", info.neural_path.c_str(), info.neural_queries_per_ray);
        if (ImGui::TreeNode("nodes per LoD")) {
            for (size_t l = 0; l < info.lod_node_counts.size(); ++l)
                ImGui::Text("%s LoD %zu: %u nodes", int(l) == s.lod ? ">" : " ", l, info.lod_node_counts[l]);
            ImGui::TreePop();
        }
    }
    if (!info.status.empty()) ImGui::TextWrapped("%s", info.status.c_str());
    ImGui::TextDisabled("left drag orbit, middle/shift drag pan, wheel zoom, WASD/QE fly, F1 UI");
    ImGui::End();
    return act;
}

} // namespace nbvh::viewer
