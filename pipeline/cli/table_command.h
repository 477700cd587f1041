// What the model's commands share (pipeline/cli/model_commands.cpp and each technique's table
// command in pipeline/techniques/<name>/): the config options, a table command's arguments, and
// one replay per trace in child processes (SystemC allows one elaboration per process).
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

#include "pipeline/sim/gpu.h"
#include "traces/format/reader.h"

namespace nbsim::cli {

// --config FILE and --set unit.field=value, as every model command takes them.
struct ModelOptions {
  std::string config_file;
  std::vector<std::string> sets;

  void add_options(CLI::App* cmd);
  // Applies the file, then the --set overrides, to a default config.
  void apply(pipeline::GpuConfig& c, nlohmann::ordered_json& values) const;
};

// The arguments of a technique's table command (`nbsim NAME TRACE...`): its traces, one replay each
// in a child process, and where the table goes.
struct TableCommandArgs {
  std::vector<std::string> traces;
  std::string out;
  bool json = false;
  int jobs = 2;
  ModelOptions mo;

  void add_options(CLI::App* cmd, const std::string& traces_help, const std::string& table_file);
  // Refuses a bad config and any trace that is missing or not of `technique` before any child
  // starts; hands each trace's reader to `each`.
  void check(const std::string& technique, const std::function<void(const trace::TraceReader&)>& each) const;
};

// Replays every trace as `nbsim replay TRACE --out DIR/<i>_<stem> [config]` in child processes,
// `jobs` at a time, into `out` (or a temporary folder removed afterwards), and returns each run.json.
// Throws InputError naming every replay that failed or whose run.json has no `section` (a JSON pointer).
std::vector<nlohmann::json> replay_each(const std::vector<std::string>& traces, const std::string& out, int jobs,
                                        const ModelOptions& mo, const std::string& section);

// The run's settings (--config and --set), so that a table read later says what it was made with.
nlohmann::ordered_json settings_of(const ModelOptions& mo);

}  // namespace nbsim::cli
