// nbvh render — being written (scaffold from the project skeleton; replaced by its issue's work).
#include "app/commands.h"
#include "engine/core/error.h"

namespace nbvh::app {

void add_render_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("render", "(not built yet)");
    cmd->callback([] { throw Error("'nbvh render' is not built yet"); });
}

} // namespace nbvh::app
