// Runs the built `nbvh` executable as a subprocess (what a user runs) with a timeout, capturing stdout,
// stderr and how it ended, plus checks of the project rule for user errors: exactly one
// "nbvh: error: ..." line, only "warning: ..." lines before it, a non-zero exit and no signal.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace nbvh::test {

struct RunResult {
    int exit_code = -1;     // valid when !signaled && !timed_out
    bool signaled = false;  // killed by a signal (abort, segfault, ...)
    int signal = 0;
    bool timed_out = false; // killed by us after the timeout
    std::string out, err;   // captured stdout / stderr
    std::string describe() const; // one paragraph for test failure messages
};

// Path of the nbvh binary under test (compile definition NBVH_EXE).
std::filesystem::path nbvh_exe();

// Runs `nbvh args...` in `cwd` (empty: current directory), killed after timeout_s seconds.
RunResult run_nbvh(const std::vector<std::string>& args, double timeout_s = 30.0,
                   const std::filesystem::path& cwd = {});
// The same for any executable.
RunResult run_command(const std::filesystem::path& exe, const std::vector<std::string>& args,
                      double timeout_s = 30.0, const std::filesystem::path& cwd = {});

// Empty string when `r` is a clean user error: non-zero exit, no signal/timeout, stderr ends with exactly one
// "nbvh: error: ..." line that contains every word of `must_mention` (case-sensitive), and every line
// before it is a "warning: ..." line (strict) or, when !strict, also an informational log line (progress
// such as the loaded scene's summary) that looks like no error, abort or crash. Otherwise what is wrong.
std::string check_clean_error(const RunResult& r, const std::vector<std::string>& must_mention = {},
                              bool strict = true);

// A tiny 2-LoD model of the default scene's rope knot, trained by `nbvh train` on the CPU backend (about a
// second: 20 steps of 256 rays, 63 nodes, hash 2^12; a poor model, so hybrid and classical images differ),
// once per test process (the first call's `prefix` names its folder, with the process id): ctest runs each test as its own process, in
// parallel, and temp_dir empties the folder it returns (a shared folder once lost its model to
// a sibling test). A failed training fails the calling test.
const std::filesystem::path& tiny_default_model(const std::string& prefix);

// Lines of a text (without the trailing empty line).
std::vector<std::string> split_lines(const std::string& text);

} // namespace nbvh::test
