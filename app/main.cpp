// nbvh: neural BVH renderer. Subcommands: render, train, flip, info, bench, bench-features, study, converge, view.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/render_measure.h"
#include "engine/core/error.h"

int main(int argc, char** argv) {
    CLI::App app{"nbvh: ray queries against complex 3D assets answered by a learned N-BVH"};
    app.require_subcommand(1);
    const std::string command = nbvh::app::command_line(argc, argv);
    nbvh::app::add_render_command(app, command);
    nbvh::app::add_train_command(app);
    nbvh::app::add_flip_command(app);
    nbvh::app::add_info_command(app);
    nbvh::app::add_bench_command(app, command);
    nbvh::app::add_bench_features_command(app, command);
    nbvh::app::add_study_command(app, command);
    nbvh::app::add_converge_command(app, command);
    nbvh::app::add_view_command(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help/--version (exit code 0) print as CLI11 does; a usage error is one line like every other
        // error (CLI11's default adds a second "Run with --help" line).
        if (e.get_exit_code() == 0) return app.exit(e);
        std::string msg = e.what();
        for (char& c : msg)
            if (c == '\n') c = ' ';
        std::fprintf(stderr, "nbvh: error: %s (see nbvh --help)\n", msg.c_str());
        return e.get_exit_code();
    } catch (const nbvh::Error& e) {
        std::fprintf(stderr, "nbvh: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "nbvh: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "nbvh: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
