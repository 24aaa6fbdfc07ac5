// Scripted viewer sessions (app/viewer/script.h): the command parser, `set` through the panel's
// ranges and actions, and the runner's waits (no window needed).
#include <gtest/gtest.h>

#include "app/viewer/script.h"
#include "engine/core/error.h"

namespace nbvh::viewer {
namespace {

std::string error_of(const std::string& text) {
    try {
        parse_script(text, "s.txt");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(ViewerScript, ParsesEveryCommand) {
    const auto c = parse_script("# a comment\n"
                                "frames 3\n"
                                "set lod 2   # trailing comment\n"
                                "orbit 10 -5.5\nzoom 2\nreset-camera\nrestart\ncompare\n"
                                "drop /tmp/a file.glb\n"
                                "screenshot out.png\nreport r.json\n"
                                "train start\ntrain pause\ntrain resume\ntrain wait 30\ntrain wait\ntrain stop\n"
                                "train save m.nbvh\n\nquit\n",
                                "s.txt");
    ASSERT_EQ(c.size(), 18u);
    EXPECT_EQ(c[0].op, ScriptOp::frames);
    EXPECT_EQ(c[0].count, 3u);
    EXPECT_EQ(c[0].line, 2);
    EXPECT_EQ(c[1].op, ScriptOp::set);
    EXPECT_EQ(c[1].key, "lod");
    EXPECT_EQ(c[1].value, "2");
    EXPECT_EQ(c[2].op, ScriptOp::orbit);
    EXPECT_FLOAT_EQ(c[2].y, -5.5f);
    EXPECT_EQ(c[3].op, ScriptOp::zoom);
    EXPECT_EQ(c[4].op, ScriptOp::reset_camera);
    EXPECT_EQ(c[5].op, ScriptOp::restart);
    EXPECT_EQ(c[6].op, ScriptOp::compare);
    EXPECT_EQ(c[7].op, ScriptOp::drop);
    EXPECT_EQ(c[7].value, "/tmp/a file.glb"); // the rest of the line: paths may hold spaces
    EXPECT_EQ(c[8].op, ScriptOp::screenshot);
    EXPECT_EQ(c[9].op, ScriptOp::report);
    EXPECT_EQ(c[10].key, "start");
    EXPECT_EQ(c[13].key, "wait");
    EXPECT_FLOAT_EQ(c[13].x, 30.0f);
    EXPECT_FLOAT_EQ(c[14].x, 600.0f);
    EXPECT_EQ(c[16].value, "m.nbvh");
    EXPECT_EQ(c[17].op, ScriptOp::quit);
    EXPECT_EQ(c[17].line, 20);
}

TEST(ViewerScript, ErrorsNameFileAndLine) {
    EXPECT_EQ(error_of("frames 1\nfly 3\n"), "s.txt:2: unknown command 'fly'");
    EXPECT_EQ(error_of("frames 0\n"), "s.txt:1: frames: expected a count >= 1");
    EXPECT_EQ(error_of("frames\n"), "s.txt:1: expected 'frames N'");
    EXPECT_EQ(error_of("set lod\n"), "s.txt:1: expected 'set KEY VALUE'");
    EXPECT_EQ(error_of("set colour red\n"), "s.txt:1: set: unknown setting 'colour'");
    EXPECT_EQ(error_of("set view sideways\n"), "s.txt:1: set view 'sideways': expected image, split, difference, flip or loss");
    EXPECT_EQ(error_of("set split 1.5\n"), "s.txt:1: set split '1.5': expected a number in [0, 1]");
    EXPECT_EQ(error_of("set max_depth 3x\n"), "s.txt:1: set max_depth '3x': expected an integer in [1, 32]");
    EXPECT_EQ(error_of("set neural maybe\n"), "s.txt:1: set neural 'maybe': expected on or off");
    EXPECT_EQ(error_of("train jump\n"), "s.txt:1: train: unknown sub-command 'jump'");
    EXPECT_EQ(error_of("train wait -1\n"), "s.txt:1: train wait: expected a positive number of seconds");
    EXPECT_EQ(error_of("screenshot\n"), "s.txt:1: screenshot: expected a path");
    EXPECT_EQ(error_of("orbit 1 nan\n"), "s.txt:1: orbit: expected two numbers");
}

TEST(ViewerScript, SettingsUseThePanelsActions) {
    ViewSettings s;
    // Renderer settings ask for an apply (the same flag as a released slider); display-only ones do not.
    for (const char* key : {"max_depth", "lod", "secondary_lod", "roughness", "metallic"})
        EXPECT_TRUE(apply_setting(s, key, "1").rebuild) << key;
    EXPECT_TRUE(apply_setting(s, "neural", "off").rebuild);
    EXPECT_FALSE(s.neural);
    EXPECT_TRUE(apply_setting(s, "view", "split").rebuild);
    EXPECT_EQ(s.view, ViewMode::split);
    EXPECT_FALSE(apply_setting(s, "exposure", "-2.5").rebuild);
    EXPECT_FLOAT_EQ(s.exposure, -2.5f);
    EXPECT_FALSE(apply_setting(s, "spp", "4").rebuild);
    EXPECT_EQ(s.spp_per_frame, 4);
    EXPECT_FALSE(apply_setting(s, "split", "0.25").rebuild);
    EXPECT_FLOAT_EQ(s.split, 0.25f);
    apply_setting(s, "train_steps", "60");
    apply_setting(s, "train_backend", "cpu");
    EXPECT_EQ(s.train.steps, 60);
    EXPECT_EQ(s.train.backend, "cpu");
    // The node-count key snaps to the LoD with the nearest count, as the node-count slider.
    EXPECT_TRUE(apply_setting(s, "nodes", "120", {1000, 400, 100, 10}).rebuild);
    EXPECT_EQ(s.lod, 2);
    EXPECT_THROW(apply_setting(s, "spp", "17"), Error);
    // Every listed key is accepted with some value.
    for (const std::string& key : script_setting_keys()) {
        ViewSettings t;
        const char* value = key == "view" ? "flip" : key == "train_backend" ? "auto"
                            : (key == "neural" || key == "ui" || key == "override_material") ? "on" : "1";
        EXPECT_NO_THROW(apply_setting(t, key, value)) << key;
    }
}

TEST(ViewerScript, RunnerWaitsForFrames) {
    ScriptRunner r(parse_script("set lod 1\nframes 2\nset lod 0\n", "s"));
    ASSERT_TRUE(r.active());
    const ScriptCommand* c = r.next();
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->op, ScriptOp::set);
    c = r.next();
    ASSERT_NE(c, nullptr);
    ASSERT_EQ(c->op, ScriptOp::frames);
    r.wait_frames(c->count);
    EXPECT_EQ(r.next(), nullptr); // waiting
    r.frame_done();
    EXPECT_EQ(r.next(), nullptr);
    r.frame_done();
    c = r.next();
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->value, "0");
    EXPECT_TRUE(r.finished());
    EXPECT_FALSE(ScriptRunner().active());
}

} // namespace
} // namespace nbvh::viewer
