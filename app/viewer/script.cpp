#include "app/viewer/script.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::viewer {

namespace {

bool parse_int(const std::string& text, long long* out) {
    try {
        size_t used = 0;
        const long long v = std::stoll(text, &used);
        if (used != text.size()) return false;
        *out = v;
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

bool parse_float(const std::string& text, float* out) {
    try {
        size_t used = 0;
        const float v = std::stof(text, &used);
        if (used != text.size() || !std::isfinite(v)) return false;
        *out = v;
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

int int_in(const std::string& key, const std::string& value, long long lo, long long hi) {
    long long v = 0;
    if (!parse_int(value, &v) || v < lo || v > hi)
        throw Error("set " + key + " '" + value + "': expected an integer in [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "]");
    return int(v);
}

float float_in(const std::string& key, const std::string& value, float lo, float hi) {
    float v = 0.0f;
    if (!parse_float(value, &v) || v < lo || v > hi)
        throw Error(strfmt("set %s '%s': expected a number in [%g, %g]", key.c_str(), value.c_str(), double(lo),
                           double(hi)));
    return v;
}

bool on_off(const std::string& key, const std::string& value) {
    if (value == "on" || value == "1" || value == "true") return true;
    if (value == "off" || value == "0" || value == "false") return false;
    throw Error("set " + key + " '" + value + "': expected on or off");
}

} // namespace

const char* view_mode_name(ViewMode mode) {
    switch (mode) {
    case ViewMode::image: return "image";
    case ViewMode::split: return "split";
    case ViewMode::difference: return "difference";
    case ViewMode::flip: return "flip";
    case ViewMode::loss: return "loss";
    }
    return "image";
}

bool needs_reference(ViewMode mode) {
    return mode == ViewMode::split || mode == ViewMode::difference || mode == ViewMode::flip;
}

bool parse_view_mode(const std::string& name, ViewMode* mode) {
    for (ViewMode m : {ViewMode::image, ViewMode::split, ViewMode::difference, ViewMode::flip, ViewMode::loss})
        if (name == view_mode_name(m)) {
            *mode = m;
            return true;
        }
    return false;
}

const std::vector<std::string>& script_setting_keys() {
    static const std::vector<std::string> keys = {
        "spp", "max_depth", "max_spp", "exposure", "ui", "neural", "lod", "nodes", "secondary_lod", "max_leaves",
        "override_material", "roughness", "metallic", "view", "split", "gain", "compare_every", "train_steps",
        "train_nodes", "train_batch", "train_hash_log2", "train_lods", "train_threads", "train_snapshot",
        "train_backend"};
    return keys;
}

PanelActions apply_setting(ViewSettings& s, const std::string& key, const std::string& v,
                           const std::vector<uint32_t>& lod_node_counts) {
    PanelActions act;
    // The ranges are the panel's sliders (ui_panel.cpp), so a script cannot reach a state the UI cannot.
    if (key == "spp") s.spp_per_frame = int_in(key, v, 1, 16);
    else if (key == "max_depth") s.max_depth = int_in(key, v, 1, 32), act.rebuild = true;
    else if (key == "max_spp") s.max_samples = int_in(key, v, 0, 65536);
    else if (key == "exposure") s.exposure = float_in(key, v, -8.0f, 8.0f);
    else if (key == "ui") s.show_ui = on_off(key, v);
    else if (key == "neural") s.neural = on_off(key, v), act.rebuild = true;
    else if (key == "lod") s.lod = int_in(key, v, 0, 7), act.rebuild = true;
    else if (key == "nodes") {
        const int nodes = int_in(key, v, 0, 1 << 30);
        if (!lod_node_counts.empty()) s.lod = lod_for_node_count(lod_node_counts, uint32_t(nodes));
        act.rebuild = true;
    } else if (key == "secondary_lod") s.secondary_lod = int_in(key, v, -1, 7), act.rebuild = true;
    else if (key == "max_leaves") s.max_leaves = int_in(key, v, 1, 256), act.rebuild = true;
    else if (key == "override_material") s.override_material = on_off(key, v), act.rebuild = true;
    else if (key == "roughness") s.roughness = float_in(key, v, 0.0f, 1.0f), act.rebuild = true;
    else if (key == "metallic") s.metallic = float_in(key, v, 0.0f, 1.0f), act.rebuild = true;
    else if (key == "view") {
        if (!parse_view_mode(v, &s.view))
            throw Error("set view '" + v + "': expected image, split, difference, flip or loss");
        act.rebuild = true;
    } else if (key == "split") s.split = float_in(key, v, 0.0f, 1.0f);
    else if (key == "gain") s.gain = float_in(key, v, 1.0f, 64.0f);
    else if (key == "compare_every") s.compare_every = int_in(key, v, 1, 1000);
    else if (key == "train_steps") s.train.steps = int_in(key, v, 1, 1000000);
    else if (key == "train_nodes") s.train.nodes = int_in(key, v, 1, 1 << 26);
    else if (key == "train_batch") s.train.batch = int_in(key, v, 1, 1 << 22);
    else if (key == "train_hash_log2") s.train.hash_log2 = int_in(key, v, 1, 30);
    else if (key == "train_lods") s.train.lods = int_in(key, v, 1, 8);
    else if (key == "train_threads") s.train.threads = int_in(key, v, 0, 1024);
    else if (key == "train_snapshot") s.train.snapshot_every = int_in(key, v, 1, 1000000);
    else if (key == "train_backend") {
        if (v != "auto" && v != "cpu" && v != "cuda")
            throw Error("set train_backend '" + v + "': expected auto, cpu or cuda");
        s.train.backend = v;
    } else {
        throw Error("set: unknown setting '" + key + "'");
    }
    return act;
}

std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& name) {
    std::vector<ScriptCommand> out;
    std::istringstream in(text);
    std::string raw;
    int line_no = 0;
    ViewSettings scratch; // `set` values are checked by applying them here
    while (std::getline(in, raw)) {
        ++line_no;
        const size_t hash = raw.find('#');
        if (hash != std::string::npos) raw.resize(hash);
        std::istringstream words(raw);
        std::vector<std::string> w;
        for (std::string s; words >> s;) w.push_back(s);
        if (w.empty()) continue;
        auto fail = [&](const std::string& why) -> Error {
            return Error(name + ":" + std::to_string(line_no) + ": " + why);
        };
        auto want = [&](size_t n, const char* usage) {
            if (w.size() != n) throw fail(std::string("expected '") + usage + "'");
        };
        ScriptCommand c;
        c.line = line_no;
        const std::string& op = w[0];
        try {
            if (op == "frames") {
                want(2, "frames N");
                long long n = 0;
                if (!parse_int(w[1], &n) || n < 1 || n > (1 << 24)) throw fail("frames: expected a count >= 1");
                c.op = ScriptOp::frames;
                c.count = uint32_t(n);
            } else if (op == "set") {
                want(3, "set KEY VALUE");
                c.op = ScriptOp::set;
                c.key = w[1];
                c.value = w[2];
                apply_setting(scratch, c.key, c.value);
            } else if (op == "orbit") {
                want(3, "orbit DX DY");
                c.op = ScriptOp::orbit;
                if (!parse_float(w[1], &c.x) || !parse_float(w[2], &c.y)) throw fail("orbit: expected two numbers");
            } else if (op == "zoom") {
                want(2, "zoom NOTCHES");
                c.op = ScriptOp::zoom;
                if (!parse_float(w[1], &c.x)) throw fail("zoom: expected a number");
            } else if (op == "reset-camera" || op == "restart" || op == "compare" || op == "quit") {
                want(1, op.c_str());
                c.op = op == "quit"      ? ScriptOp::quit
                       : op == "restart" ? ScriptOp::restart
                       : op == "compare" ? ScriptOp::compare
                                         : ScriptOp::reset_camera;
            } else if (op == "drop" || op == "screenshot" || op == "report") {
                if (w.size() < 2) throw fail(op + ": expected a path");
                c.op = op == "drop" ? ScriptOp::drop : op == "screenshot" ? ScriptOp::screenshot : ScriptOp::report;
                // A path may contain spaces: the rest of the line.
                c.value = raw.substr(raw.find(w[1]));
                while (!c.value.empty() && std::isspace((unsigned char)c.value.back())) c.value.pop_back();
            } else if (op == "train") {
                if (w.size() < 2) throw fail("train: expected start, pause, resume, stop, wait or save");
                c.op = ScriptOp::train;
                c.key = w[1];
                if (c.key == "start" || c.key == "pause" || c.key == "resume" || c.key == "stop") {
                    want(2, ("train " + c.key).c_str());
                } else if (c.key == "wait") {
                    if (w.size() > 3) throw fail("expected 'train wait [SECONDS]'");
                    c.x = 600.0f;
                    if (w.size() == 3 && (!parse_float(w[2], &c.x) || c.x <= 0.0f))
                        throw fail("train wait: expected a positive number of seconds");
                } else if (c.key == "save") {
                    want(3, "train save PATH.nbvh");
                    c.value = w[2];
                } else {
                    throw fail("train: unknown sub-command '" + c.key + "'");
                }
            } else {
                throw fail("unknown command '" + op + "'");
            }
        } catch (const Error& e) {
            const std::string what = e.what();
            if (what.rfind(name + ":", 0) == 0) throw;
            throw fail(what);
        }
        out.push_back(std::move(c));
    }
    return out;
}

std::vector<ScriptCommand> load_script(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error("cannot read script '" + path + "'");
    std::stringstream s;
    s << f.rdbuf();
    return parse_script(s.str(), path);
}

const ScriptCommand* ScriptRunner::next() {
    if (wait_frames_ > 0 || next_ >= commands_.size()) return nullptr;
    return &commands_[next_++];
}

} // namespace nbvh::viewer
