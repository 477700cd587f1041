// Occlusion culling's own commands: none. Its table is `nbsim table2`, the shared table command,
// which runs the rows its results declare (results.cpp: one replay per culling mode).
#include "pipeline/cli/command.h"

namespace nbsim::cli {

void add_occlusion_commands(CLI::App&, Action&) {}

}  // namespace nbsim::cli
