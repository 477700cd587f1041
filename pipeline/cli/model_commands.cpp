// `nbsim replay`, `nbsim compare`, `nbsim table2` and `nbsim config`: the SystemC model from the
// command line. table2 runs one replay per culling mode, each in a child process of this executable
// (SystemC allows one elaboration per process), and prints the paper's Table 2 beside ours.
#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>

#include "model/common/error.h"
#include "model/cull/primitive.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "pipeline/explore/child.h"
#include "pipeline/explore/runner.h"
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

// Table 2 of Décoret 2005: average depth comparisons per frame, city walkthrough at 512x512 with
// back-face culling. Fixed by the paper; the Hi-Z baselines have no paper value.
struct Table2Row {
  const char* mode;
  const char* paper_label;
  std::optional<double> paper;
};
constexpr Table2Row kTable2[] = {
    {"oq_hier", "occlusion queries with hierarchy", 1'100'000.0},
    {"oq", "occlusion queries", 200'000.0},
    {"nb_hier", "N-buffer with hierarchy", 350.0},
    {"nb", "N-buffer", 500.0},
    {"hiz_tile", "tile Hi-Z (baseline, not in the paper)", std::nullopt},
    {"hiz_pyramid", "Hi-Z pyramid (baseline, not in the paper)", std::nullopt},
};

// Runs every Table 2 mode as `nbsim replay TRACE --out DIR/MODE [config] --set cull.mode=MODE`, in
// child processes (pipeline/explore/child.h), `parallel` at a time; returns each mode's run.json summary.
// `config` is the checked config the options give (its cull.mode is overwritten per row).
std::vector<nlohmann::json> run_table2(const std::string& trace, const std::filesystem::path& out, const ModelOptions& mo,
                                       pipeline::GpuConfig config, int parallel) {
  const std::size_t n = std::size(kTable2);
  const bool primitive = cull::parse_granularity(config.cull.granularity) == cull::Granularity::Primitive;
  std::vector<explore::ChildJob> jobs;
  for (const Table2Row& row : kTable2) {
    const std::filesystem::path dir = out / row.mode;
    std::vector<std::string> args = {"replay", trace, "--out", dir.string()};
    if (!mo.config_file.empty()) args.insert(args.end(), {"--config", mo.config_file});
    for (const auto& s : mo.sets) args.insert(args.end(), {"--set", s});
    args.insert(args.end(), {"--set", std::string("cull.mode=") + row.mode});
    // Per-primitive culling where the mode has a depth-query structure; the occlusion-query rows stay
    // at object granularity (a query per triangle would rasterize it), so one setting runs every row.
    config.cull.mode = row.mode;
    if (primitive && !cull::supports_primitive_granularity(config.cull.parsed_mode()))
      args.insert(args.end(), {"--set", "cull.granularity=object"});
    jobs.push_back({std::move(args), dir});
  }
  std::vector<nlohmann::json> results(n);
  std::string failures;
  explore::run_children(explore::self_executable(), jobs, parallel, [&](std::size_t i, const explore::ChildOutcome& outcome) {
    if (!outcome.ok) {
      failures += fmt::format("cull.mode={}: replay failed: {}\n", kTable2[i].mode, outcome.error);
      return;
    }
    std::ifstream in(jobs[i].dir / "run.json");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.contains("summary") || !j["summary"].contains("cull"))
      failures += fmt::format("cull.mode={}: {}/run.json has no cull summary\n", kTable2[i].mode, jobs[i].dir.string());
    else
      results[i] = j["summary"];
  });
  if (!failures.empty()) throw InputError(failures.substr(0, failures.size() - 1));
  return results;
}

}  // namespace

void add_model_commands(CLI::App& app, Action& action) {
  {
    auto* cmd = app.add_subcommand("replay", "Replay a trace through the SystemC model; write run.json, frames.csv, draws.csv");
    auto trace = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    auto mo = std::make_shared<ModelOptions>();
    cmd->add_option("TRACE", *trace, "Trace file (nbsim capture)")->required();
    cmd->add_option("--out", *out, "Output folder")->required();
    auto timeline = std::make_shared<std::string>();
    auto vcd = std::make_shared<std::string>();
    cmd->add_option("--timeline", *timeline,
                    "Write a trace-event JSON of every unit's busy spans (ui.perfetto.dev; ts and dur in cycles)");
    cmd->add_option("--vcd", *vcd, "Write a VCD of every unit's busy bit (GTKWave; 1 ns = 1 cycle; needs gpu.quantum_cycles=0)");
    mo->add_options(cmd);
    cmd->callback([&action, trace, out, timeline, vcd, mo] {
      action = [trace, out, timeline, vcd, mo] {
        pipeline::ReplayOptions o;
        o.trace = *trace;
        o.out = std::filesystem::path(*out);
        if (!timeline->empty()) o.timeline = std::filesystem::path(*timeline);
        if (!vcd->empty()) o.vcd = std::filesystem::path(*vcd);
        mo->apply(o.config, o.config_values);
        ProgressBar bar("replay", 1);
        o.progress = [&bar](std::uint64_t done, std::uint64_t total) {
          bar = ProgressBar("replay", static_cast<long long>(total));
          bar.update(static_cast<long long>(done));
        };
        const pipeline::ReplaySummary s = pipeline::replay(o);
        bar.finish();
        fmt::print("replayed {} frames, {} draws: {} cycles ({:.0f} per frame), {} depth tests, {:.2f} s host "
                   "({:.1f} M depth tests/s); wrote {}/run.json, frames.csv, draws.csv, culls.csv\n",
                   s.frames, s.draws, s.cycles, s.frames ? static_cast<double>(s.cycles) / static_cast<double>(s.frames) : 0.0,
                   s.depth_tests, s.host_seconds, s.host_seconds > 0 ? static_cast<double>(s.depth_tests) / s.host_seconds / 1e6 : 0.0,
                   *out);
        if (o.timeline)
          fmt::print("timeline: {} spans in {}{}\n", s.timeline_events, o.timeline->string(),
                     s.timeline_dropped ? fmt::format(" ({} later spans left out: the file's cap)", s.timeline_dropped) : "");
        if (o.vcd) fmt::print("busy bits: {}\n", o.vcd->string());
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
    auto* cmd = app.add_subcommand("table2", "Replay in every culling mode and print the paper's Table 2 beside ours");
    auto trace = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    auto jobs = std::make_shared<int>(2);
    auto mo = std::make_shared<ModelOptions>();
    cmd->add_option("TRACE", *trace, "Trace file (nbsim capture) with scene objects and ground truth")->required();
    cmd->add_option("--out", *out, "Keep each mode's replay outputs in OUT/MODE and the table in OUT/table2.json (default: a temporary folder, removed)");
    cmd->add_flag("--json", *json, "Print a JSON list, one object per mode");
    cmd->add_option("--jobs", *jobs, "Replays run at a time (one process each)")->check(CLI::Range(1, 16));
    mo->add_options(cmd);
    cmd->footer("Modes: oq_hier, oq, nb_hier, nb (the paper's rows), hiz_tile, hiz_pyramid. Query depth tests are the\n"
                "paper's count (box fragments, or N-buffer/Hi-Z texels compared); the total adds the N-buffer/Hi-Z\n"
                "update texels and the depth tests of the drawn objects. Exit 1 when any mode has a false cull.");
    cmd->callback([&action, trace, out, json, jobs, mo] {
      action = [trace, out, json, jobs, mo] {
        pipeline::GpuConfig config;  // a bad config is refused here, before any child starts
        {
          nlohmann::ordered_json values;
          mo->apply(config, values);
        }
        if (!std::filesystem::exists(*trace)) throw InputError(fmt::format("trace '{}' does not exist", *trace));
        std::filesystem::path dir;
        const bool temporary = out->empty();
        if (temporary) {
          std::string tmpl = (std::filesystem::temp_directory_path() / "nbsim_table2_XXXXXX").string();
          if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a temporary folder");
          dir = tmpl;
        } else {
          dir = *out;
        }
        std::vector<nlohmann::json> rows;
        try {
          rows = run_table2(std::filesystem::absolute(*trace).string(), dir, *mo, config, *jobs);
        } catch (...) {
          if (temporary) std::filesystem::remove_all(dir);
          throw;
        }
        if (temporary) std::filesystem::remove_all(dir);
        nlohmann::ordered_json list = nlohmann::ordered_json::array();
        std::uint64_t false_culls = 0;
        for (std::size_t i = 0; i < rows.size(); ++i) {
          const nlohmann::json& c = rows[i]["cull"];
          nlohmann::ordered_json r;
          r["mode"] = kTable2[i].mode;
          r["paper"] = kTable2[i].paper_label;
          r["paper_depth_tests_per_frame"] = kTable2[i].paper ? nlohmann::ordered_json(*kTable2[i].paper) : nullptr;
          for (const char* k : {"query_depth_tests_per_frame", "update_texels_per_frame", "total_depth_tests_per_frame",
                                "cycles_per_frame", "false_culls", "culling_efficiency", "frames", "bounds_tests",
                                "candidates", "culled", "candidates_not_visible", "undrawable", "max_lookups_per_test", "granularity"})
            r[k] = c[k];
          r["host_seconds"] = rows[i]["host_seconds"];
          false_culls += c["false_culls"].get<std::uint64_t>();
          list.push_back(std::move(r));
        }
        if (!temporary) {  // the report (analysis/report.py) reads it: rows plus what produced them
          nlohmann::ordered_json t;
          t["trace"] = *trace;
          t["trace_crc32"] = explore::inspect_trace(*trace).crc32;
          t["nbsim_version"] = NBSIM_VERSION;
          t["config_file"] = mo->config_file;
          t["settings"] = mo->sets;
          t["rows"] = list;
          std::ofstream f(dir / "table2.json");
          f << t.dump(2) << "\n";
          if (!f) throw InputError(fmt::format("cannot write '{}'", (dir / "table2.json").string()));
        }
        if (*json) {
          fmt::print("{}\n", list.dump());
        } else {
          fmt::print("Table 2: average depth comparisons per frame ({}, {} frames)\n", *trace, list[0]["frames"].get<std::uint64_t>());
          fmt::print("{:<12} {:>12} {:>14} {:>14} {:>14} {:>12} {:>6} {:>8} {:>7}\n", "mode", "paper", "query tests",
                     "update texels", "total tests", "cycles", "false", "culling", "undraw");
          for (const auto& r : list)
            fmt::print("{:<12} {:>12} {:>14.1f} {:>14.1f} {:>14.1f} {:>12.0f} {:>6} {:>7.1f}% {:>7}\n", r["mode"].get<std::string>(),
                       r["paper_depth_tests_per_frame"].is_null() ? std::string("-")
                                                                  : fmt::format("{:.0f}", r["paper_depth_tests_per_frame"].get<double>()),
                       r["query_depth_tests_per_frame"].get<double>(), r["update_texels_per_frame"].get<double>(),
                       r["total_depth_tests_per_frame"].get<double>(), r["cycles_per_frame"].get<double>(),
                       r["false_culls"].get<std::uint64_t>(), 100.0 * r["culling_efficiency"].get<double>(),
                       r["undrawable"].get<std::uint64_t>());
          const double oq = list[1]["query_depth_tests_per_frame"].get<double>(), nb = list[3]["query_depth_tests_per_frame"].get<double>();
          fmt::print("occlusion queries / N-buffer query depth tests: {:.0f}x (paper: 400x); false culls: {}\n",
                     nb > 0 ? oq / nb : 0.0, false_culls);
          if (list[2]["granularity"] == "primitive")
            fmt::print("cull.granularity=primitive in nb_hier, nb, hiz_tile and hiz_pyramid; oq_hier and oq test objects only\n");
        }
        return false_culls == 0 ? 0 : 1;
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
