#include "app/study/study_rows.h"

#include <map>
#include <tuple>

#include "engine/core/log.h"

namespace nbvh::app {

void mark_floor(StudyRow& r) {
    r.within_2x_floor =
        std::isfinite(r.flip) && std::isfinite(r.noise_floor) && r.flip <= 2.0 * r.noise_floor;
    r.converged = std::isfinite(r.flip) && std::isfinite(r.noise_floor) &&
                  (r.noise_floor <= r.flip / 3.0 || r.noise_floor <= 0.005);
}

std::vector<StudyRow> mean_over_cameras(const std::vector<StudyRow>& rows) {
    using Key = std::tuple<int, std::string, int, int, uint32_t>;
    std::map<Key, std::vector<const StudyRow*>> groups;
    std::vector<Key> order;
    for (const StudyRow& r : rows) {
        if (r.camera < 0) continue;
        const Key k{r.config, r.variant, r.lod, r.secondary_lod, r.max_leaves};
        auto& g = groups[k];
        if (g.empty()) order.push_back(k);
        g.push_back(&r);
    }
    std::vector<StudyRow> out;
    for (const Key& k : order) {
        const auto& g = groups[k];
        StudyRow m = *g.front();
        m.camera = -1;
        for (double StudyRow::*f :
             {&StudyRow::frame_ms, &StudyRow::classical_frame_ms, &StudyRow::ratio_to_classical,
              &StudyRow::flip, &StudyRow::noise_floor, &StudyRow::flip_same_seed, &StudyRow::flip_vs_base_cap,
              &StudyRow::queries_per_ray, &StudyRow::leaf_cap_fraction, &StudyRow::equal_time_flip}) {
            double sum = 0.0;
            for (const StudyRow* r : g) sum += r->*f;
            m.*f = sum / double(g.size());
        }
        double spp = 0.0;
        for (const StudyRow* r : g) spp += r->equal_time_spp;
        m.equal_time_spp = uint32_t(spp / double(g.size()) + 0.5);
        mark_floor(m);
        out.push_back(m);
    }
    return out;
}

std::vector<std::string> study_csv_columns() {
    return {"scene",
            "config",
            "variant",
            "camera",
            "nodes_target",
            "hash_log2",
            "lods",
            "lod",
            "secondary_lod",
            "max_leaves",
            "nodes",
            "memory_bytes",
            "resident_bytes",
            "triangles",
            "compression",
            "frame_ms",
            "classical_frame_ms",
            "ratio_to_classical",
            "flip",
            "noise_floor",
            "flip_same_seed",
            "flip_vs_base_cap",
            "within_2x_floor",
            "converged",
            "queries_per_ray",
            "leaf_cap_fraction",
            "equal_time_spp",
            "equal_time_flip",
            "train_seconds",
            "final_loss",
            "decimation_sloppy"};
}

namespace {
std::string num(double v) { return std::isfinite(v) ? strfmt("%.6g", v) : std::string(); }
std::string csv_text(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}
nlohmann::json jnum(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
} // namespace

std::string study_csv(const std::vector<StudyRow>& rows, const std::string& scene) {
    std::string out;
    const auto cols = study_csv_columns();
    for (size_t i = 0; i < cols.size(); ++i) out += (i ? "," : "") + cols[i];
    out += "\n";
    for (const StudyRow& r : rows) {
        const std::vector<std::string> v = {csv_text(scene),
                                            std::to_string(r.config),
                                            r.variant,
                                            r.camera < 0 ? "mean" : std::to_string(r.camera),
                                            std::to_string(r.nodes_target),
                                            std::to_string(r.hash_log2),
                                            std::to_string(r.lods),
                                            std::to_string(r.lod),
                                            std::to_string(r.secondary_lod),
                                            std::to_string(r.max_leaves),
                                            std::to_string(r.nodes),
                                            std::to_string(r.memory_bytes),
                                            std::to_string(r.resident_bytes),
                                            std::to_string(r.triangles),
                                            num(r.compression),
                                            num(r.frame_ms),
                                            num(r.classical_frame_ms),
                                            num(r.ratio_to_classical),
                                            num(r.flip),
                                            num(r.noise_floor),
                                            num(r.flip_same_seed),
                                            num(r.flip_vs_base_cap),
                                            r.within_2x_floor ? "1" : "0",
                                            r.converged ? "1" : "0",
                                            num(r.queries_per_ray),
                                            num(r.leaf_cap_fraction),
                                            std::to_string(r.equal_time_spp),
                                            num(r.equal_time_flip),
                                            num(r.train_seconds),
                                            num(r.final_loss),
                                            r.decimation_sloppy ? "1" : "0"};
        for (size_t i = 0; i < v.size(); ++i) out += (i ? "," : "") + v[i];
        out += "\n";
    }
    return out;
}

nlohmann::json row_json(const StudyRow& r) {
    return {{"config", r.config},
            {"variant", r.variant},
            {"camera", r.camera < 0 ? nlohmann::json("mean") : nlohmann::json(r.camera)},
            {"nodes_target", r.nodes_target},
            {"hash_log2", r.hash_log2},
            {"lods", r.lods},
            {"lod", r.lod},
            {"secondary_lod", r.secondary_lod},
            {"max_leaves", r.max_leaves},
            {"nodes", r.nodes},
            {"memory_bytes", r.memory_bytes},
            {"resident_bytes", r.resident_bytes},
            {"triangles", r.triangles},
            {"compression", jnum(r.compression)},
            {"frame_ms", jnum(r.frame_ms)},
            {"classical_frame_ms", jnum(r.classical_frame_ms)},
            {"ratio_to_classical", jnum(r.ratio_to_classical)},
            {"flip", jnum(r.flip)},
            {"noise_floor", jnum(r.noise_floor)},
            {"flip_same_seed", jnum(r.flip_same_seed)},
            {"flip_vs_base_cap", jnum(r.flip_vs_base_cap)},
            {"within_2x_floor", r.within_2x_floor},
            {"converged", r.converged},
            {"queries_per_ray", jnum(r.queries_per_ray)},
            {"leaf_cap_fraction", jnum(r.leaf_cap_fraction)},
            {"equal_time_spp", r.equal_time_spp},
            {"equal_time_flip", jnum(r.equal_time_flip)},
            {"train_seconds", jnum(r.train_seconds)},
            {"final_loss", jnum(r.final_loss)},
            {"decimation_sloppy", r.decimation_sloppy}};
}

} // namespace nbvh::app
