// `nbsim replay`, `nbsim compare` and `nbsim config`: the SystemC model from the command line.
#include <fmt/format.h>

#include <fstream>
#include <memory>

#include "model/common/error.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "pipeline/sim/replay.h"

namespace nbsim::cli {

namespace {

struct ModelOptions {
  std::string config_file;
  std::vector<std::string> sets;

  void add_options(CLI::App* cmd) {
    cmd->add_option("--config", config_file, "JSON file of config keys: {\"unit\": {\"field\": value}} (nbsim config --defaults)");
    cmd->add_option("--set", sets, "Override one key, unit.field=value (repeatable)");
  }

  // Applies the file, then the --set overrides, to a default config.
  void apply(pipeline::GpuConfig& c, nlohmann::ordered_json& values) const {
    config::Schema schema;
    pipeline::GpuConfig::describe(schema, c);
    if (!config_file.empty()) {
      std::ifstream in(config_file);
      if (!in) throw InputError(fmt::format("config file '{}' cannot be read", config_file));
      const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
      if (j.is_discarded()) throw InputError(fmt::format("config file '{}' is not valid JSON", config_file));
      schema.apply(j, config_file);
    }
    for (const auto& s : sets) schema.set(s);
    values = schema.values();
  }
};

}  // namespace

void add_model_commands(CLI::App& app, Action& action) {
  {
    auto* cmd = app.add_subcommand("replay", "Replay a trace through the SystemC model; write run.json, frames.csv, draws.csv");
    auto trace = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    auto mo = std::make_shared<ModelOptions>();
    cmd->add_option("TRACE", *trace, "Trace file (nbsim capture)")->required();
    cmd->add_option("--out", *out, "Output folder")->required();
    mo->add_options(cmd);
    cmd->callback([&action, trace, out, mo] {
      action = [trace, out, mo] {
        pipeline::ReplayOptions o;
        o.trace = *trace;
        o.out = std::filesystem::path(*out);
        mo->apply(o.config, o.config_values);
        ProgressBar bar("replay", 1);
        o.progress = [&bar](std::uint64_t done, std::uint64_t total) {
          bar = ProgressBar("replay", static_cast<long long>(total));
          bar.update(static_cast<long long>(done));
        };
        const pipeline::ReplaySummary s = pipeline::replay(o);
        bar.finish();
        fmt::print("replayed {} frames, {} draws: {} cycles ({:.0f} per frame), {} depth tests, {:.2f} s host "
                   "({:.1f} M depth tests/s); wrote {}/run.json, frames.csv, draws.csv\n",
                   s.frames, s.draws, s.cycles, s.frames ? static_cast<double>(s.cycles) / static_cast<double>(s.frames) : 0.0,
                   s.depth_tests, s.host_seconds, s.host_seconds > 0 ? static_cast<double>(s.depth_tests) / s.host_seconds / 1e6 : 0.0,
                   *out);
        return 0;
      };
    });
  }
  {
    auto* cmd = app.add_subcommand("compare", "Counter comparison: the model's fragments, passed samples and depth against GL's");
    auto trace = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    auto mo = std::make_shared<ModelOptions>();
    cmd->add_option("TRACE", *trace, "Trace file (nbsim capture)")->required();
    cmd->add_flag("--json", *json, "Print one JSON summary object");
    mo->add_options(cmd);
    cmd->footer("Exit 0 only within the thresholds: total fragment and passed-sample error at most 0.01%, at least 99%\n"
                "of draws exact, at least 99.99% of depth pixels within 1e-6 of GL's snapshots; exit 1 otherwise.");
    cmd->callback([&action, trace, json, mo] {
      action = [trace, json, mo] {
        pipeline::ReplayOptions o;
        o.trace = *trace;
        mo->apply(o.config, o.config_values);
        const pipeline::ReplaySummary s = pipeline::replay(o);
        if (*json) {
          fmt::print("{}\n", s.to_json().dump());
        } else {
          fmt::print("{} frames, {} draws replayed ({} GLSL passes and lookups not replayed)\n", s.frames, s.draws,
                     s.passes_not_replayed);
          fmt::print("  draws exact        {} of {} ({:.3f}%)\n", s.draws_exact, s.draws,
                     s.draws ? 100.0 * static_cast<double>(s.draws_exact) / static_cast<double>(s.draws) : 100.0);
          fmt::print("  fragments          model {} GL {} (error {:.4f}%)\n", s.fragments_model, s.fragments_gl, 100 * s.fragment_error());
          fmt::print("  passed samples     model {} GL {} (error {:.4f}%)\n", s.passed_model, s.passed_gl, 100 * s.passed_error());
          fmt::print("  depth pixels       {} of {} within 1e-6 (max error {:.3g})\n", s.depth_pixels_matching, s.depth_pixels,
                     s.depth_max_abs_error);
          fmt::print("  {}\n", s.within_thresholds() ? "within the thresholds" : "OUTSIDE the thresholds");
        }
        return s.within_thresholds() ? 0 : 1;
      };
    });
  }
  {
    auto* cmd = app.add_subcommand("config", "List every model config key with its default, unit, limits and meaning");
    auto defaults = std::make_shared<bool>(false);
    auto json = std::make_shared<bool>(false);
    cmd->add_flag("--defaults", *defaults, "List the defaults (the only listing there is today)");
    cmd->add_flag("--json", *json, "As a JSON array");
    cmd->callback([&action, json] {
      action = [json] {
        pipeline::GpuConfig c;
        config::Schema schema;
        pipeline::GpuConfig::describe(schema, c);
        const auto d = schema.describe();
        if (*json) {
          fmt::print("{}\n", d.dump(2));
          return 0;
        }
        for (const auto& e : d)
          fmt::print("{:<36} {:>10} {:<16} {:<22} {}\n", e["key"].get<std::string>(), e["default"].dump(),
                     e["unit"].get<std::string>(), e["limits"].get<std::string>(), e["description"].get<std::string>());
        return 0;
      };
    });
  }
}

}  // namespace nbsim::cli
