// nbvh train — being written (scaffold from the project skeleton; replaced by its issue's work).
#include "app/commands.h"
#include "engine/core/error.h"

namespace nbvh::app {

void add_train_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("train", "(not built yet)");
    cmd->callback([] { throw Error("'nbvh train' is not built yet"); });
}

} // namespace nbvh::app
