// nbvh: neural BVH renderer. Subcommands: render, train, flip, info, bench, view.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "engine/core/error.h"

int main(int argc, char** argv) {
    CLI::App app{"nbvh: ray queries against complex 3D assets answered by a learned N-BVH"};
    app.require_subcommand(1);
    nbvh::app::add_render_command(app);
    nbvh::app::add_train_command(app);
    nbvh::app::add_flip_command(app);
    nbvh::app::add_info_command(app);
    nbvh::app::add_bench_command(app);
    nbvh::app::add_view_command(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
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
