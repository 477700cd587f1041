// The model commands' shared pieces; see table_command.h.
#include "pipeline/cli/table_command.h"

#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "pipeline/explore/child.h"
#include "pipeline/techniques/results.h"

namespace nbsim::cli {

void ModelOptions::add_options(CLI::App* cmd) {
  cmd->add_option("--config", config_file, "JSON file of config keys: {\"unit\": {\"field\": value}} (nbsim config --defaults)");
  cmd->add_option("--set", sets, "Override one key, unit.field=value (repeatable)");
}

void ModelOptions::apply(pipeline::GpuConfig& c, nlohmann::ordered_json& values) const {
  config::Schema schema;
  pipeline::GpuConfig::describe(schema, c);
  if (!config_file.empty()) {
    const std::string text = config::read_input_file(config_file, "config file");
    schema.apply(config::parse_input(text, fmt::format("config file '{}'", config::excerpt_text(config_file, 1024))), config_file);
  }
  for (const auto& s : sets) schema.set(s);
  values = schema.values();
}

void TableCommandArgs::add_options(CLI::App* cmd, const std::string& traces_help, const std::string& table_file) {
  cmd->add_option("TRACE", traces, traces_help)->required();
  cmd->add_option("--out", out, "Keep each replay's outputs in OUT/<trace name> and the table in OUT/" + table_file);
  cmd->add_flag("--json", json, "Print a JSON list, one object per trace");
  cmd->add_option("--jobs", jobs, "Replays run at a time (one process each)")->check(CLI::Range(1, 16));
  mo.add_options(cmd);
}

void TableCommandArgs::check(const std::string& technique, const std::function<void(const trace::TraceReader&)>& each) const {
  pipeline::GpuConfig config;
  nlohmann::ordered_json values;
  mo.apply(config, values);
  for (const std::string& t : traces) {
    if (!std::filesystem::exists(t)) throw InputError(fmt::format("trace '{}' does not exist", t));
    const trace::TraceReader reader(t);
    const std::string* name = reader.property("technique");
    if (!name || *name != technique)
      throw InputError(fmt::format("trace '{}' is not a {} trace (technique '{}')", t, technique, name ? *name : ""));
    each(reader);
  }
}

std::vector<nlohmann::json> replay_each(const std::vector<std::string>& traces, const std::string& out, int jobs,
                                        const ModelOptions& mo, const std::string& section) {
  std::filesystem::path dir;
  const bool temporary = out.empty();
  if (temporary) {
    std::string tmpl = (std::filesystem::temp_directory_path() / "nbsim_replays_XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a temporary folder");
    dir = tmpl;
  } else {
    dir = out;
  }
  std::vector<explore::ChildJob> children;
  for (std::size_t i = 0; i < traces.size(); ++i) {
    const std::filesystem::path d = dir / fmt::format("{}_{}", i, std::filesystem::path(traces[i]).stem().string());
    std::vector<std::string> args = {"replay", std::filesystem::absolute(traces[i]).string(), "--out", d.string()};
    if (!mo.config_file.empty()) args.insert(args.end(), {"--config", mo.config_file});
    for (const auto& s : mo.sets) args.insert(args.end(), {"--set", s});
    children.push_back({std::move(args), d});
  }
  std::vector<nlohmann::json> runs(traces.size());
  std::string failures;
  explore::run_children(explore::self_executable(), children, jobs, [&](std::size_t i, const explore::ChildOutcome& o) {
    if (!o.ok) {
      failures += fmt::format("{}: replay failed: {}\n", traces[i], o.error);
      return;
    }
    std::ifstream in(children[i].dir / "run.json");
    nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !techniques::at_pointer(j, section))
      failures += fmt::format("{}: its run.json has no {}\n", traces[i], section);
    else
      runs[i] = std::move(j);
  });
  if (temporary) std::filesystem::remove_all(dir);
  if (!failures.empty()) throw InputError(failures.substr(0, failures.size() - 1));
  return runs;
}

nlohmann::ordered_json settings_of(const ModelOptions& mo) {
  nlohmann::ordered_json settings = nlohmann::ordered_json::array();
  if (!mo.config_file.empty()) settings.push_back("--config " + mo.config_file);
  for (const auto& s : mo.sets) settings.push_back(s);
  return settings;
}

}  // namespace nbsim::cli
