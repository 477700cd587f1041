// How nbsim's subcommands plug into the one `nbsim` executable: each module adds its subcommands
// to the CLI11 app and, when one of them is chosen, sets the action that main() runs after parsing.
// Exit status: 0 success, 2 bad usage or bad input (InputError), 1 any other failure.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>

#include "model/common/rect.h"
#include "nbsim/technique_list.h"

namespace nbsim::cli {

using Action = std::function<int()>;

void add_nbuffer_commands(CLI::App& app, Action& action);
void add_bench_commands(CLI::App& app, Action& action);
void add_info_command(CLI::App& app, Action& action);
void add_trace_commands(CLI::App& app, Action& action);
void add_capture_command(CLI::App& app, Action& action);
void add_model_commands(CLI::App& app, Action& action);
void add_explore_command(CLI::App& app, Action& action);
void add_report_command(CLI::App& app, Action& action);

// Each technique of the registration list (cmake/NbsimTechniques.cmake) defines
// add_<name>_commands(), its own commands (e.g. its table), in pipeline/techniques/<name>/.
#define NBSIM_DECLARE_TECHNIQUE_COMMANDS(name) void add_##name##_commands(CLI::App& app, Action& action);
NBSIM_EACH_TECHNIQUE(NBSIM_DECLARE_TECHNIQUE_COMMANDS)
#undef NBSIM_DECLARE_TECHNIQUE_COMMANDS

// "X,Y,W,H" -> Rect; throws InputError naming the text.
Rect parse_rect(const std::string& text);
// "WxH" -> {W, H}, both at least 1; throws InputError naming the option.
std::pair<int, int> parse_size(const std::string& text, const std::string& option);

// Prints a float with the fewest digits that read back as the same float.
double tidy(float v);

}  // namespace nbsim::cli
