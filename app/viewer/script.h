// Scripted viewer sessions (`nbvh view --script FILE`): a small command file that drives the viewer
// through the same settings and actions as the panel, for tests under Xvfb and for reproducible
// measurements. One command per line, `#` starts a comment; commands run in order at the start of a
// frame, and a command that waits (frames, screenshot, train wait) lets frames pass before the next.
//
//   frames N              draw N frames
//   set KEY VALUE         change a setting as the panel would (keys: script_setting_keys())
//   orbit DX DY           a left-button drag of DX, DY pixels (camera)
//   zoom NOTCHES          mouse wheel
//   reset-camera
//   restart               restart the accumulation
//   compare               compare the hybrid and classical films now and wait for it (compare views)
//   drop PATH             as a file dropped on the window (.gltf/.glb: scene, .nbvh: model)
//   screenshot PATH.png   save the window content after the next frame
//   report PATH.json      write the viewer's counters and state (renderer builds, live updates,
//                         samples, FLIP, training, status)
//   train start|pause|resume|stop
//   train wait [SECONDS]  draw frames until live training ends (default limit 600 s; an error after it)
//   train save PATH.nbvh  save the live-trained model
//   quit
// Engine-free (ui_panel.h settings only), unit-tested in tests/viewer/.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "app/viewer/ui_panel.h"

namespace nbvh::viewer {

enum class ScriptOp { frames, set, orbit, zoom, reset_camera, restart, compare, drop, screenshot, report, train, quit };

struct ScriptCommand {
    ScriptOp op = ScriptOp::frames;
    int line = 0;                 // 1-based line in the file (for messages)
    std::string key, value;       // set: key and value; train: sub-command and argument; drop/screenshot/report: path in value
    uint32_t count = 0;           // frames
    float x = 0.0f, y = 0.0f;     // orbit: pixels; zoom: notches in x; train wait: seconds in x
};

// The keys `set` accepts.
const std::vector<std::string>& script_setting_keys();

// Applies `set KEY VALUE` to `settings` as the panel's widget would; `lod_node_counts` maps the
// `nodes` key to a LoD (as the node-count slider). Returns the panel actions it implies (a renderer
// setting: rebuild = apply). Throws nbvh::Error for an unknown key or a bad value.
PanelActions apply_setting(ViewSettings& settings, const std::string& key, const std::string& value,
                           const std::vector<uint32_t>& lod_node_counts = {});

// Parses a script; `name` prefixes messages ("FILE:LINE: ..."). Every command and `set` value is
// checked here, so a typo fails before the window opens. Throws nbvh::Error.
std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& name);
std::vector<ScriptCommand> load_script(const std::string& path);

// Steps through a parsed script: next() returns the commands to run now, one at a time, until a
// waiting command; frame_done() counts drawn frames down.
class ScriptRunner {
public:
    ScriptRunner() = default;
    explicit ScriptRunner(std::vector<ScriptCommand> commands) : commands_(std::move(commands)) {}

    bool active() const { return !commands_.empty(); }
    bool finished() const { return next_ >= commands_.size() && wait_frames_ == 0; }
    // The next command when nothing is waited for, else nullptr.
    const ScriptCommand* next();
    void wait_frames(uint32_t frames) { wait_frames_ += frames; }
    void frame_done() {
        if (wait_frames_ > 0) --wait_frames_;
    }
    bool waiting() const { return wait_frames_ > 0; }

private:
    std::vector<ScriptCommand> commands_;
    size_t next_ = 0;
    uint32_t wait_frames_ = 0;
};

} // namespace nbvh::viewer
