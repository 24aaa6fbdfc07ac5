// nbvh info — being written (scaffold from the project skeleton; replaced by its issue's work).
#include "app/commands.h"
#include "engine/core/error.h"

namespace nbvh::app {

void add_info_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("info", "(not built yet)");
    cmd->callback([] { throw Error("'nbvh info' is not built yet"); });
}

} // namespace nbvh::app
