// Each subcommand of the `nbvh` executable lives in its own cmd_<name>.cpp and registers itself here.
// Mains stay thin: parse options, call engine/trainer functions, print.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace nbvh::app {

// `command_line`: the whole command as typed (written into render's --stats and the benchmark results).
void add_render_command(CLI::App& app, const std::string& command_line);
void add_train_command(CLI::App& app);
void add_flip_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_bench_command(CLI::App& app, const std::string& command_line);
void add_bench_features_command(CLI::App& app, const std::string& command_line);
void add_study_command(CLI::App& app, const std::string& command_line);
void add_converge_command(CLI::App& app, const std::string& command_line);
void add_view_command(CLI::App& app);

} // namespace nbvh::app
