#include "app/viewer/ui_panel.h"

#include <algorithm>
#include <cfloat>
#include <cstdlib>
#include <string>

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

namespace {

// Compare views: hybrid | classical split, difference, FLIP (a classical reference renders beside).
void draw_compare_section(ViewSettings& s, const PanelInfo& info, PanelActions& act) {
    ImGui::Separator();
    ImGui::TextUnformatted("compare with the classical reference");
    int mode = int(s.view);
    const char* modes[] = {"image", "split (hybrid | classical)", "difference", "FLIP", "loss per node"};
    if (ImGui::Combo("view", &mode, modes, info.has_node_loss ? 5 : 4)) {
        s.view = ViewMode(mode);
        act.rebuild = true;
    }
    if (s.view == ViewMode::split) ImGui::SliderFloat("split", &s.split, 0.0f, 1.0f, "%.2f (or drag the line)");
    if (s.view == ViewMode::difference) ImGui::SliderFloat("gain", &s.gain, 1.0f, 64.0f, "x%.0f");
    if (s.view == ViewMode::loss)
        ImGui::Text("%u leaves seen; colour: training loss %.3g (blue) .. %.3g (red), log", info.loss_leaves,
                    info.loss_lo, info.loss_hi);
    if (needs_reference(s.view)) {
        ImGui::SliderInt("compare every", &s.compare_every, 1, 240, "%d frames");
        ImGui::Text("classical %u spp, %.1f ms/frame", info.reference_samples, info.reference_frame_ms);
        if (info.flip_mean >= 0.0)
            ImGui::Text("FLIP %.4f (hybrid %u spp vs classical %u spp)", info.flip_mean, info.flip_samples,
                        info.flip_reference_samples);
    }
}

// Live training (live_training.h): options, start / pause / stop, progress, loss plot, save.
void draw_training_section(ViewSettings& s, const PanelInfo& info, PanelActions& act) {
    ImGui::Separator();
    if (!ImGui::TreeNode("live training")) return;
    const bool active = info.train_state == "running" || info.train_state == "paused";
    ImGui::BeginDisabled(active);
    ImGui::SliderInt("steps", &s.train.steps, 10, 20000);
    ImGui::SliderInt("target nodes", &s.train.nodes, 3, 20000);
    ImGui::SliderInt("rays / step", &s.train.batch, 256, 1 << 18);
    ImGui::SliderInt("hash log2", &s.train.hash_log2, 10, 18);
    ImGui::SliderInt("swap every", &s.train.snapshot_every, 1, 1000, "%d steps");
    ImGui::EndDisabled();
    if (!active && ImGui::Button("start")) act.train_start = true;
    if (active) {
        if (ImGui::Button(info.train_state == "paused" ? "resume" : "pause")) act.train_pause = true;
        ImGui::SameLine();
        if (ImGui::Button("stop")) act.train_stop = true;
    }
    if (!info.train_state.empty()) {
        const float f = info.train_steps ? float(info.train_step) / float(info.train_steps) : 0.0f;
        ImGui::ProgressBar(f, ImVec2(-1, 0), (std::to_string(info.train_step) + " / " + std::to_string(info.train_steps)).c_str());
        ImGui::Text("%s: %u nodes, loss %.4f, %u models swapped in, ETA %.0f s", info.train_state.c_str(),
                    info.train_nodes, info.train_loss, info.train_snapshots, info.train_eta_s);
        if (!info.train_loss_history.empty())
            ImGui::PlotLines("loss", info.train_loss_history.data(), int(info.train_loss_history.size()), 0,
                             nullptr, 0.0f, FLT_MAX, ImVec2(0, 60));
        ImGui::InputText("file", s.train.save_path.data(), s.train.save_path.size());
        ImGui::SameLine();
        if (ImGui::Button("save")) act.train_save = s.train.save_path.data();
    }
    ImGui::TreePop();
}

} // namespace

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
    ImGui::Text("renderer builds %u, live changes %u, model swaps %u", info.renderer_builds, info.live_updates,
                info.model_swaps);
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
        ImGui::SliderInt("leaf budget", &s.max_leaves, 1, 256, "%d leaves / ray");
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
    if (info.has_model) draw_compare_section(s, info, act);
    if (info.can_train) draw_training_section(s, info, act);
    if (!info.status.empty()) {
        const bool error = info.status.rfind("error", 0) == 0 || info.status.rfind("not applied", 0) == 0;
        if (error) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
        ImGui::TextWrapped("%s", info.status.c_str());
        if (error) ImGui::PopStyleColor();
    }
    ImGui::TextDisabled("left drag orbit, middle/shift drag pan, wheel zoom, WASD/QE fly, F1 UI");
    ImGui::End();
    return act;
}

} // namespace nbvh::viewer
