// `nbsim shadows`: the shadows technique's table command.
#pragma once

#include "pipeline/cli/command.h"

namespace nbsim::cli {

void add_shadows_command(CLI::App& app, Action& action);

}  // namespace nbsim::cli
