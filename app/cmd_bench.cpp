// nbvh bench — being written (scaffold from the project skeleton; replaced by its issue's work).
#include "app/commands.h"
#include "engine/core/error.h"

namespace nbvh::app {

void add_bench_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("bench", "(not built yet)");
    cmd->callback([] { throw Error("'nbvh bench' is not built yet"); });
}

} // namespace nbvh::app
