// `nbsim ldi`: the layered-depth-image technique's table command (ldi table1).
#pragma once

#include "pipeline/cli/command.h"

namespace nbsim::cli {

void add_ldi_commands(CLI::App& app, Action& action);

}  // namespace nbsim::cli
