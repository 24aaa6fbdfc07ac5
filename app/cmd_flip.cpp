// nbvh flip — being written (scaffold from the project skeleton; replaced by its issue's work).
#include "app/commands.h"
#include "engine/core/error.h"

namespace nbvh::app {

void add_flip_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("flip", "(not built yet)");
    cmd->callback([] { throw Error("'nbvh flip' is not built yet"); });
}

} // namespace nbvh::app
