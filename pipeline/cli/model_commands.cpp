// `nbsim replay`, `nbsim compare`, `nbsim table2`, `nbsim particles`, `nbsim shadows` and `nbsim config`: the SystemC model from the
// command line. table2 runs one replay per row of the table the trace's technique declares
// (pipeline/techniques/results.h; occlusion culling: one per culling mode), each in a child process
// of this executable (SystemC allows one elaboration per process), and prints the paper's Table 2
// beside ours.
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "pipeline/explore/child.h"
#include "pipeline/explore/runner.h"
#include "pipeline/sim/replay.h"
#include "pipeline/techniques/relief/relief_table.h"
#include "pipeline/techniques/results.h"
#include "traces/format/reader.h"

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
      const std::string text = config::read_input_file(config_file, "config file");
      schema.apply(config::parse_input(text, fmt::format("config file '{}'", config::excerpt_text(config_file, 1024))), config_file);
    }
    for (const auto& s : sets) schema.set(s);
    values = schema.values();
  }
};

// The effective value of a flat config key ("unit.field") in the nested values, as text ("" when
// the config has no such key).
std::string config_value(const nlohmann::ordered_json& values, const std::string& key) {
  const auto dot = key.find('.');
  if (dot == std::string::npos) return {};
  const std::string unit = key.substr(0, dot), field = key.substr(dot + 1);
  if (!values.contains(unit) || !values[unit].contains(field)) return {};
  const auto& v = values[unit][field];
  return v.is_string() ? v.get<std::string>() : v.dump();
}

// The declared table of the trace's technique (pipeline/techniques/results.h); throws InputError
// when the trace names no technique or its technique declares no table.
const techniques::TableSpec& table_of(const std::string& trace_file) {
  const trace::TraceReader reader(trace_file);
  const std::string* technique = reader.property("technique");
  if (!technique || technique->empty())
    throw InputError(fmt::format("trace '{}' names no technique in its header: table2 takes its rows from the technique's "
                                 "declared results (pipeline/techniques/results.cpp)",
                                 trace_file));
  const techniques::TechniqueResults* t = techniques::find_technique_results(*technique);
  if (!t || !t->table)
    throw InputError(fmt::format("trace '{}': technique '{}' declares no Table-2 rows (pipeline/techniques/results.cpp): "
                                 "nothing for table2 to run",
                                 trace_file, *technique));
  return *t->table;
}

// Runs every row of the table as `nbsim replay TRACE --out DIR/VALUE [config] --set KEY=VALUE`, in
// child processes (pipeline/explore/child.h), `parallel` at a time; returns each row's run.json.
// `values` are the checked config the options give (the row key is overwritten per row).
std::vector<nlohmann::json> run_table(const techniques::TableSpec& table, const std::string& trace, const std::filesystem::path& out,
                                      const ModelOptions& mo, const nlohmann::ordered_json& values, int parallel) {
  std::vector<explore::ChildJob> jobs;
  for (const techniques::TableRow& row : table.rows) {
    const std::filesystem::path dir = out / row.value;
    std::vector<std::string> args = {"replay", trace, "--out", dir.string()};
    if (!mo.config_file.empty()) args.insert(args.end(), {"--config", mo.config_file});
    for (const auto& s : mo.sets) args.insert(args.end(), {"--set", s});
    args.insert(args.end(), {"--set", table.row_key + "=" + row.value});
    for (const auto& o : row.overrides)
      if (config_value(values, o.key) == o.when) args.insert(args.end(), {"--set", o.key + "=" + o.set});
    jobs.push_back({std::move(args), dir});
  }
  std::vector<nlohmann::json> results(table.rows.size());
  std::string failures;
  explore::run_children(explore::self_executable(), jobs, parallel, [&](std::size_t i, const explore::ChildOutcome& outcome) {
    const std::string row = table.row_key + "=" + table.rows[i].value;
    if (!outcome.ok) {
      failures += fmt::format("{}: replay failed: {}\n", row, outcome.error);
      return;
    }
    std::ifstream in(jobs[i].dir / "run.json");
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !techniques::at_pointer(j, table.section))
      failures += fmt::format("{}: {}/run.json has no {}\n", row, jobs[i].dir.string(), table.section);
    else
      results[i] = j;
  });
  if (!failures.empty()) throw InputError(failures.substr(0, failures.size() - 1));
  return results;
}

// One cell of the text table.
std::string format_cell(const techniques::PrintedColumn& c, const nlohmann::ordered_json& v) {
  using techniques::CellFormat;
  switch (c.format) {
    case CellFormat::Text: return fmt::format("{:<{}}", v.is_string() ? v.get<std::string>() : v.dump(), c.width);
    case CellFormat::Paper:
      return fmt::format("{:>{}}", v.is_number() ? fmt::format("{:.0f}", v.get<double>()) : std::string("-"), c.width);
    case CellFormat::Fixed0: return fmt::format("{:>{}.0f}", v.is_number() ? v.get<double>() : 0.0, c.width);
    case CellFormat::Fixed1: return fmt::format("{:>{}.1f}", v.is_number() ? v.get<double>() : 0.0, c.width);
    case CellFormat::Count: return fmt::format("{:>{}}", v.is_number() ? v.get<std::uint64_t>() : 0, c.width);
    case CellFormat::Percent: return fmt::format("{:>{}.1f}%", v.is_number() ? 100.0 * v.get<double>() : 0.0, c.width - 1);
  }
  return {};
}

// The row whose value is `value`, or nullptr.
const nlohmann::ordered_json* row_named(const techniques::TableSpec& table, const nlohmann::ordered_json& list, const std::string& value) {
  for (const auto& r : list)
    if (r[table.row_column] == value) return &r;
  return nullptr;
}

// The arguments of a technique's table command (`nbsim particles`, `nbsim shadows`): its traces,
// one replay each in a child process, and where the table goes.
struct TableCommandArgs {
  std::vector<std::string> traces;
  std::string out;
  bool json = false;
  int jobs = 2;
  ModelOptions mo;

  void add_options(CLI::App* cmd, const std::string& traces_help, const std::string& table_file) {
    cmd->add_option("TRACE", traces, traces_help)->required();
    cmd->add_option("--out", out, "Keep each replay's outputs in OUT/<trace name> and the table in OUT/" + table_file);
    cmd->add_flag("--json", json, "Print a JSON list, one object per trace");
    cmd->add_option("--jobs", jobs, "Replays run at a time (one process each)")->check(CLI::Range(1, 16));
    mo.add_options(cmd);
  }

  // Refuses a bad config and any trace that is missing or not of `technique` before any child
  // starts; hands each trace's reader to `each`.
  void check(const std::string& technique, const std::function<void(const trace::TraceReader&)>& each) const {
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
};

// Replays every trace as `nbsim replay TRACE --out DIR/<i>_<stem> [config]` in child processes,
// `jobs` at a time, into `out` (or a temporary folder removed afterwards), and returns each run.json
// (`nbsim particles`, `nbsim shadows`). Throws InputError naming every replay that failed or whose
// run.json has no `section`.
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

// The run's settings, so that a table read later says what it was made with.
nlohmann::ordered_json settings_of(const ModelOptions& mo) {
  nlohmann::ordered_json settings = nlohmann::ordered_json::array();
  if (!mo.config_file.empty()) settings.push_back("--config " + mo.config_file);
  for (const auto& s : mo.sets) settings.push_back(s);
  return settings;
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
                   s.frames, s.draws + s.own_draws, s.cycles, s.frames ? static_cast<double>(s.cycles) / static_cast<double>(s.frames) : 0.0,
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
                "of draws exact, at least 99.99% of depth pixels within 1e-6 of GL's snapshots, every stencil pixel equal to a\n"
                "frame's 'stencil' image when it has one, and (relief traces) every method's fragments, hits and per-fragment\n"
                "walks equal to GL's; exit 1 otherwise.");
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
          if (s.own_draws)
            fmt::print("  own draws          {} (the program's own, not GL's: not compared with GL's counters)\n", s.own_draws);
          fmt::print("  draws exact        {} of {} ({:.3f}%)\n", s.draws_exact, s.draws,
                     s.draws ? 100.0 * static_cast<double>(s.draws_exact) / static_cast<double>(s.draws) : 100.0);
          fmt::print("  fragments          model {} GL {} (error {:.4f}%)\n", s.fragments_model, s.fragments_gl, 100 * s.fragment_error());
          fmt::print("  passed samples     model {} GL {} (error {:.4f}%)\n", s.passed_model, s.passed_gl, 100 * s.passed_error());
          fmt::print("  depth pixels       {} of {} within 1e-6 (max error {:.3g})\n", s.depth_pixels_matching, s.depth_pixels,
                     s.depth_max_abs_error);
          if (s.stencil_pixels) {
            fmt::print("  stencil pixels     {} of {} equal to GL's '{}' images ({} stencil tests)\n", s.stencil_pixels_matching,
                       s.stencil_pixels, pipeline::kStencilSnapshotName, s.stencil_tests);
            for (const pipeline::StencilMismatch& m : s.stencil_mismatches)
              fmt::print("    frame {} pixel ({}, {}): model {} GL {}\n", m.frame, m.x, m.y, m.model, m.gl);
            if (s.stencil_pixels - s.stencil_pixels_matching > s.stencil_mismatches.size())
              fmt::print("    ... {} more\n", s.stencil_pixels - s.stencil_pixels_matching - s.stencil_mismatches.size());
          } else if (s.stencil_tests) {
            fmt::print("  stencil tests      {} (no '{}' stencil image in the trace to compare with)\n", s.stencil_tests,
                       pipeline::kStencilSnapshotName);
          }
          if (const pipeline::ProgramRow* row = pipeline::find_program(s.program_name); row && row->results.describe && !s.program.is_null())
            fmt::print("{}", row->results.describe(s.program));
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
    // The rows and columns come from the trace's technique (pipeline/techniques/results.cpp); the
    // footer shows occlusion culling's table.
    if (const auto* oc = techniques::find_technique_results("occlusion_culling"); oc && oc->table)
      cmd->footer(oc->table->footer + "\nRows and columns: the trace's technique's declared table; a technique without one exits 2.");
    cmd->callback([&action, trace, out, json, jobs, mo] {
      action = [trace, out, json, jobs, mo] {
        pipeline::GpuConfig config;  // a bad config is refused here, before any child starts
        nlohmann::ordered_json values;
        mo->apply(config, values);
        if (!std::filesystem::exists(*trace)) throw InputError(fmt::format("trace '{}' does not exist", *trace));
        const techniques::TableSpec& table = table_of(*trace);
        std::filesystem::path dir;
        const bool temporary = out->empty();
        if (temporary) {
          std::string tmpl = (std::filesystem::temp_directory_path() / "nbsim_table2_XXXXXX").string();
          if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a temporary folder");
          dir = tmpl;
        } else {
          dir = *out;
        }
        std::vector<nlohmann::json> runs;
        try {
          runs = run_table(table, std::filesystem::absolute(*trace).string(), dir, *mo, values, *jobs);
        } catch (...) {
          if (temporary) std::filesystem::remove_all(dir);
          throw;
        }
        if (temporary) std::filesystem::remove_all(dir);
        nlohmann::ordered_json list = nlohmann::ordered_json::array();
        std::uint64_t must_be_zero = 0;
        for (std::size_t i = 0; i < runs.size(); ++i) {
          const techniques::TableRow& row = table.rows[i];
          nlohmann::ordered_json r;
          r[table.row_column] = row.value;
          r[table.paper_label_column] = row.paper_label;
          r[table.paper_value_column] = row.paper ? nlohmann::ordered_json(*row.paper) : nullptr;
          for (const auto& [name, pointer] : table.columns) {
            const nlohmann::json* v = techniques::at_pointer(runs[i], pointer);
            if (v)
              r[name] = *v;
            else
              r[name] = nullptr;
          }
          if (!table.must_be_zero.empty() && r[table.must_be_zero].is_number_unsigned())
            must_be_zero += r[table.must_be_zero].get<std::uint64_t>();
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
          const nlohmann::ordered_json& frames = list[0]["frames"];
          fmt::print("{} ({}, {} frames)\n", table.title, *trace, frames.is_number() ? frames.dump() : std::string("?"));
          std::string header;
          for (const auto& c : table.printed)
            header += (header.empty() ? "" : " ") +
                      (c.format == techniques::CellFormat::Text ? fmt::format("{:<{}}", c.header, c.width) : fmt::format("{:>{}}", c.header, c.width));
          fmt::print("{}\n", header);
          for (const auto& r : list) {
            std::string line;
            for (const auto& c : table.printed) line += (line.empty() ? "" : " ") + format_cell(c, r[c.column]);
            fmt::print("{}\n", line);
          }
          std::string summary;
          if (table.ratio) {
            const auto* num = row_named(table, list, table.ratio->numerator);
            const auto* den = row_named(table, list, table.ratio->denominator);
            const double a = num && (*num)[table.ratio->column].is_number() ? (*num)[table.ratio->column].get<double>() : 0.0;
            const double b = den && (*den)[table.ratio->column].is_number() ? (*den)[table.ratio->column].get<double>() : 0.0;
            summary = fmt::format("{}: {:.0f}x (paper: {})", table.ratio->label, b > 0 ? a / b : 0.0, table.ratio->paper);
          }
          if (!table.must_be_zero.empty()) {
            std::string label = table.must_be_zero;
            std::replace(label.begin(), label.end(), '_', ' ');
            summary += fmt::format("{}{}: {}", summary.empty() ? "" : "; ", label, must_be_zero);
          }
          if (!summary.empty()) fmt::print("{}\n", summary);
          for (const auto& n : table.notes)
            if (const auto* r = row_named(table, list, n.row); r && (*r)[n.column] == n.value) fmt::print("{}\n", n.text);
        }
        return must_be_zero == 0 ? 0 : 1;
      };
    });
  }
  {
    // One replay per particles trace (one capture per mode: GL's draws depend on it), in child
    // processes, and a row each from its run.json's /summary/particles beside the paper's claim
    // (16 px sprites: 256 N depth tests by rasterization, N with the N-buffer).
    auto* cmd = app.add_subcommand(
        "particles",
        "Replay particles traces (one per mode, or one `none` capture with --set particles.mode=M) and print the particles table");
    auto a = std::make_shared<TableCommandArgs>();
    a->add_options(cmd, "Particles traces (nbsim capture particles), e.g. one per --mode", "particles.json");
    cmd->callback([&action, a] {
      action = [a] {
        std::vector<std::string> sprites;
        a->check("particles", [&](const trace::TraceReader& reader) {
          const std::string* sprite = reader.property("sprite");
          sprites.push_back(sprite ? *sprite : "");
        });
        const std::vector<nlohmann::json> runs = replay_each(a->traces, a->out, a->jobs, a->mo, "/summary/particles");
        const std::filesystem::path dir = a->out;
        const bool temporary = a->out.empty();
        std::vector<nlohmann::ordered_json> rows(a->traces.size());
        for (std::size_t i = 0; i < a->traces.size(); ++i) {
          const nlohmann::json* p = techniques::at_pointer(runs[i], "/summary/particles");
          nlohmann::ordered_json r;
          r["trace"] = (a->traces)[i];
          r["mode"] = (*p)["mode"];
          r["capture_mode"] = p->contains("capture_mode") ? (*p)["capture_mode"] : (*p)["mode"];
          r["sprite"] = sprites[i];
          r["settings"] = settings_of(a->mo);
          const double n = (*p)["particles_per_frame"].get<double>();
          r["particles_per_frame"] = n;
          // The paper's claim for 16 px sprites: 256 N by rasterization (none), N with the N-buffer.
          const std::string mode = (*p)["mode"].get<std::string>();
          r["paper_depth_tests_per_frame"] = sprites[i] != "16" ? nlohmann::ordered_json(nullptr)
                                             : mode == "none"   ? nlohmann::ordered_json(256.0 * n)
                                             : mode == "nb"     ? nlohmann::ordered_json(n)
                                                                : nlohmann::ordered_json(nullptr);
          for (const char* k : {"culled_per_frame", "query_depth_tests_per_frame", "raster_depth_tests_per_frame",
                                "build_texels_per_frame", "total_depth_tests_per_frame", "cycles_per_frame", "popping",
                                "false_culls", "decision_mismatches", "kept_too_large", "redrawn"})
            r[k] = (*p)[k];
          rows[i] = std::move(r);
        }
        nlohmann::ordered_json list = nlohmann::ordered_json::array();
        for (auto& r : rows) list.push_back(std::move(r));
        if (!temporary) {
          std::ofstream f(dir / "particles.json");
          f << list.dump(2) << "\n";
          if (!f) throw InputError(fmt::format("cannot write '{}'", (dir / "particles.json").string()));
        }
        if (a->json) {
          fmt::print("{}\n", list.dump());
          return 0;
        }
        fmt::print("Particles: depth tests per frame (paper, 16 px sprites: 256 N by rasterization, N with the N-buffer)\n");
        // mismatches: decisions unlike GL's (0 in the capture's own mode; a replay in another mode
        // differs by design); capture: the mode the trace was captured in.
        fmt::print("{:<7} {:<7} {:>6} {:>9} {:>12} {:>9} {:>10} {:>10} {:>10} {:>10} {:>11} {:>8} {:>7} {:>10}\n", "mode",
                   "capture", "sprite", "particles", "paper", "culled", "query", "raster", "build", "total", "cycles",
                   "popping", "false", "mismatches");
        for (const auto& r : list) {
          const auto num = [&](const char* k) { return r[k].is_number() ? r[k].get<double>() : 0.0; };
          fmt::print("{:<7} {:<7} {:>6} {:>9.0f} {:>12} {:>9.0f} {:>10.0f} {:>10.0f} {:>10.0f} {:>10.0f} {:>11.0f} {:>8} {:>7} {:>10}\n",
                     r["mode"].get<std::string>(), r["capture_mode"].get<std::string>(), r["sprite"].get<std::string>(),
                     num("particles_per_frame"),
                     r["paper_depth_tests_per_frame"].is_number()
                         ? fmt::format("{:.0f}", r["paper_depth_tests_per_frame"].get<double>())
                         : std::string("-"),
                     num("culled_per_frame"), num("query_depth_tests_per_frame"), num("raster_depth_tests_per_frame"),
                     num("build_texels_per_frame"), num("total_depth_tests_per_frame"), num("cycles_per_frame"),
                     r["popping"].dump(), r["false_culls"].dump(), r["decision_mismatches"].dump());
        }
        return 0;
      };
    });
  }
  {
    // One replay per shadows trace (one capture per shadow_mode: GL's volumes depend on it), in
    // child processes, and a row each from its run.json's /summary/shadows beside the paper's
    // figures (fill 20 M -> 512 K px in the city, 2.5%; about 20% on simpler scenes). The ratio to
    // infinite divides by the trace's own reference fill (SHDC reference_fill: GL's infinite volumes
    // of the same frames); a trace captured before that field gets the fill per frame of an
    // `infinite` row of the same scene, seed, viewport and frames given in the same command ("-"
    // when there is none); `ratio_reference` says which.
    auto* cmd = app.add_subcommand(
        "shadows", "Replay shadows traces (one per shadow mode) and print the shadows table; exit 1 when a mask pixel differs");
    auto a = std::make_shared<TableCommandArgs>();
    a->add_options(cmd, "Shadows traces (nbsim capture shadows), e.g. one per --shadow-mode", "shadows.json");
    cmd->callback([&action, a] {
      action = [a] {
        std::vector<std::string> keys;  // scene, seed, viewport and frames: rows comparable for the ratio
        a->check("shadows", [&](const trace::TraceReader& reader) {
          std::string key;
          for (const char* k : {"scene", "seed", "viewport", "frames", "path", "objects", "litmap_size", "light"}) {
            const std::string* v = reader.property(k);
            key += fmt::format("{}={};", k, v ? *v : "");
          }
          keys.push_back(std::move(key));
        });
        const std::vector<nlohmann::json> runs = replay_each(a->traces, a->out, a->jobs, a->mo, "/summary/shadows");
        const std::filesystem::path dir = a->out;
        const bool temporary = a->out.empty();
        std::vector<nlohmann::ordered_json> rows(a->traces.size());
        for (std::size_t i = 0; i < a->traces.size(); ++i) {
          const nlohmann::json* p = techniques::at_pointer(runs[i], "/summary/shadows");
          const nlohmann::json* sum = techniques::at_pointer(runs[i], "/summary");
          nlohmann::ordered_json r;
          r["trace"] = (a->traces)[i];
          for (const char* k : {"scene", "shadow_mode", "litmap_size"}) r[k] = p->contains(k) ? (*p)[k] : nlohmann::json("");
          r["settings"] = settings_of(a->mo);
          for (const char* k : {"frames", "casters_per_frame", "culled_per_frame", "gl_culled_per_frame", "outside_per_frame", "fill_per_frame",
                                "gl_fill_per_frame", "reference_fill_per_frame", "fill_ratio_to_infinite", "build_texels_per_frame", "lookups_per_frame", "stencil_tests_per_frame",
                                "litmap_reprojections_per_frame", "receiver_splats_per_frame", "cycles_per_frame", "nbuffer_memory_bytes", "mask_diff",
                                "mask_diff_infinite", "decision_mismatches", "zmin_mismatches", "zmax_mismatches",
                                "not_conservative", "unsafe_culls", "kept_by_slab"})
            r[k] = (*p)[k];
          r["draws"] = (*sum)["draws"];
          r["draws_exact"] = (*sum)["draws_exact"];
          r["stencil_pixels_matching"] = sum->value("stencil_pixels_matching", 0);
          r["stencil_pixels"] = sum->value("stencil_pixels", 0);
          rows[i] = std::move(r);
        }
        // The ratio to infinite: the trace's own reference fill, else an infinite row with the same key.
        std::uint64_t differing = 0;
        for (std::size_t i = 0; i < rows.size(); ++i) {
          nlohmann::ordered_json& r = rows[i];
          r["ratio_to_infinite"] = r["fill_ratio_to_infinite"];
          r["ratio_reference"] = r["ratio_to_infinite"].is_number() ? nlohmann::ordered_json("reference_fill")
                                                                     : nlohmann::ordered_json(nullptr);
          for (std::size_t k = 0; k < rows.size() && r["ratio_to_infinite"].is_null(); ++k)
            if (keys[k] == keys[i] && rows[k]["shadow_mode"] == "infinite" && rows[k]["fill_per_frame"].get<double>() > 0.0) {
              r["ratio_to_infinite"] = r["fill_per_frame"].get<double>() / rows[k]["fill_per_frame"].get<double>();
              r["ratio_reference"] = rows[k]["trace"];
              break;
            }
          differing += r["mask_diff"].get<std::uint64_t>() + r["mask_diff_infinite"].get<std::uint64_t>();
        }
        nlohmann::ordered_json list = nlohmann::ordered_json::array();
        for (auto& r : rows) list.push_back(std::move(r));
        if (!temporary) {
          std::ofstream f(dir / "shadows.json");
          f << list.dump(2) << "\n";
          if (!f) throw InputError(fmt::format("cannot write '{}'", (dir / "shadows.json").string()));
        }
        if (a->json) {
          fmt::print("{}\n", list.dump());
          return differing == 0 ? 0 : 1;
        }
        fmt::print("Shadows: fill per frame (paper, 640x480: city 20 M -> 512 K px, 2.5%; simpler scenes about 20%)\n");
        fmt::print("{:<8} {:<9} {:>12} {:>8} {:>7} {:>14} {:>10} {:>8} {:>11} {:>8} {:>8} {:>10}\n", "scene", "mode", "fill/frame",
                   "ratio", "paper", "culled/casters", "build", "lookups", "cycles", "mask", "mask_inf", "mismatches");
        for (const auto& r : list) {
          const auto num = [&](const char* k) { return r[k].is_number() ? r[k].get<double>() : 0.0; };
          const std::string scene = r["scene"].get<std::string>();
          const std::string paper = r["shadow_mode"] == "clamped" ? (scene == "boxes" ? "~20%" : "2.5%") : "-";
          fmt::print("{:<8} {:<9} {:>12.0f} {:>8} {:>7} {:>14} {:>10.0f} {:>8.0f} {:>11.0f} {:>8} {:>8} {:>10}\n", scene,
                     r["shadow_mode"].get<std::string>(), num("fill_per_frame"),
                     r["ratio_to_infinite"].is_number() ? fmt::format("{:.1f}%", 100.0 * num("ratio_to_infinite")) : std::string("-"),
                     paper, fmt::format("{:.1f}/{:.0f}", num("gl_culled_per_frame") + num("outside_per_frame"), num("casters_per_frame")),
                     num("build_texels_per_frame"), num("lookups_per_frame"), num("cycles_per_frame"), r["mask_diff"].dump(),
                     r["mask_diff_infinite"].dump(),
                     r["decision_mismatches"].get<std::uint64_t>() + r["zmin_mismatches"].get<std::uint64_t>() +
                         r["zmax_mismatches"].get<std::uint64_t>());
        }
        if (differing) fmt::print("mask pixels differing from GL's: {}\n", differing);
        return differing == 0 ? 0 : 1;
      };
    });
  }
  {
    // One replay per relief trace (a heightfield and size each; a frame per view angle, a box draw per
    // method), in child processes; a row per trace, frame and method from run.json's frames, then the
    // ranking with the Pareto front, the N-buffer walk against the exact walk, and the paper's Table 1.
    auto* cmd = app.add_subcommand(
        "relief", "Replay relief traces and print each method's cost and hit error, the ranking, the N-buffer walk against the "
                  "exact walk and the paper's Table 1; exit 1 when a walk differs from GL's");
    auto a = std::make_shared<TableCommandArgs>();
    a->add_options(cmd, "Relief traces (nbsim capture relief), e.g. one per heightfield and size", "relief.json");
    cmd->footer("Rows: trace x frame (a view angle) x method. cycles: the method's box draw in the model (relief.* keys).\n"
                "errors: fragments whose hit or miss differs from the exact reference beyond relief.hit_tolerance_texels.\n"
                "OUT/relief.json holds rows, ranking, nbuffer_vs_exact and paper; OUT/relief.csv the rows.");
    cmd->callback([&action, a] {
      action = [a] {
        a->check("relief", [](const trace::TraceReader&) {});
        const std::vector<nlohmann::json> runs = replay_each(a->traces, a->out, a->jobs, a->mo, "/summary/relief");
        const nlohmann::ordered_json rows = techniques::relief_rows(runs, a->traces);
        nlohmann::ordered_json doc;
        doc["settings"] = settings_of(a->mo);
        doc["rows"] = rows;
        doc["ranking"] = techniques::relief_ranking(rows);
        doc["nbuffer_vs_exact"] = techniques::relief_nbuffer_vs_exact(rows);
        doc["paper"] = techniques::relief_paper_table(rows);
        std::uint64_t differing = 0;
        for (const auto& r : rows) differing += r["pixel_mismatches"].get<std::uint64_t>() + r["walk_mismatches"].get<std::uint64_t>();
        if (!a->out.empty()) {
          const std::filesystem::path dir = a->out;
          std::ofstream f(dir / "relief.json");
          f << doc.dump(2) << "\n";
          if (!f) throw InputError(fmt::format("cannot write '{}'", (dir / "relief.json").string()));
          std::ofstream c(dir / "relief.csv");
          c << "trace,field,field_size,frame,angle,method,fragments,lookups,steps,errors,reference_hits,cycles,lookups_per_fragment,"
               "steps_per_fragment,error_rate,pixel_mismatches,walk_mismatches\n";
          for (const auto& r : rows) {
            const auto num = [&](const char* k) { return r[k].is_null() ? std::string() : r[k].dump(); };
            c << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", r["trace"].get<std::string>(), r["field"].get<std::string>(),
                             num("field_size"), num("frame"), num("angle"), r["method"].get<std::string>(), num("fragments"), num("lookups"),
                             num("steps"), num("errors"), num("reference_hits"), num("cycles"), num("lookups_per_fragment"),
                             num("steps_per_fragment"), num("error_rate"), num("pixel_mismatches"), num("walk_mismatches"));
          }
          if (!c) throw InputError(fmt::format("cannot write '{}'", (dir / "relief.csv").string()));
        }
        if (a->json) {
          fmt::print("{}\n", doc.dump());
          return differing == 0 ? 0 : 1;
        }
        const auto num = [](const nlohmann::ordered_json& r, const char* k) { return r[k].is_number() ? r[k].get<double>() : 0.0; };
        fmt::print("Relief: per heightfield, size, view angle and method (hit error against the exact reference)\n");
        fmt::print("{:<22} {:>5} {:>6} {:<13} {:>9} {:>9} {:>8} {:>10} {:>8} {:>9}\n", "field", "size", "angle", "method", "fragments",
                   "lookups/f", "steps/f", "cycles", "errors", "error");
        for (const auto& r : rows)
          fmt::print("{:<22} {:>5} {:>6} {:<13} {:>9} {:>9.2f} {:>8.2f} {:>10} {:>8} {:>8.3f}%\n", r["field"].get<std::string>(),
                     r["field_size"].get<int>(), r["angle"].is_number() ? fmt::format("{:g}", r["angle"].get<double>()) : std::string("-"),
                     r["method"].get<std::string>(), r["fragments"].get<std::uint64_t>(), num(r, "lookups_per_fragment"),
                     num(r, "steps_per_fragment"), r["cycles"].get<std::uint64_t>(), r["errors"].get<std::uint64_t>(),
                     100.0 * num(r, "error_rate"));
        fmt::print("\nRanking (cost: mean cycles per box draw; * on the Pareto front of cost against error)\n");
        fmt::print("{:<13} {:>12} {:>10} {:>9} {:>9}\n", "method", "cycles/frame", "lookups/f", "errors", "error");
        for (const auto& r : doc["ranking"])
          fmt::print("{:<13} {:>12.0f} {:>10.2f} {:>9} {:>8.3f}%{}\n", r["method"].get<std::string>(), num(r, "cycles_per_frame"),
                     num(r, "lookups_per_fragment"), r["errors"].get<std::uint64_t>(), 100.0 * num(r, "error_rate"),
                     r["pareto"].get<bool>() ? " *" : "");
        if (!doc["nbuffer_vs_exact"].empty()) {
          fmt::print("\nN-buffer walk against the exact walk\n");
          fmt::print("{:<22} {:>5} {:>12} {:>12} {:>7} {:>12} {:>14}\n", "field", "size", "exact look/f", "nbuf look/f", "ratio",
                     "exact errors", "nbuffer errors");
          for (const auto& r : doc["nbuffer_vs_exact"])
            fmt::print("{:<22} {:>5} {:>12.2f} {:>12.2f} {:>7.3f} {:>12} {:>14}\n", r["field"].get<std::string>(), r["field_size"].get<int>(),
                       num(r, "exact_lookups_per_fragment"), num(r, "nbuffer_lookups_per_fragment"), num(r, "lookup_ratio"),
                       r["exact_errors"].get<std::uint64_t>(), r["nbuffer_errors"].get<std::uint64_t>());
        }
        fmt::print("\nThe paper's Table 1, terrain (frames/s on a GeForce 6800 GT) beside our fbm rows (cycles per box draw)\n");
        for (const auto& r : doc["paper"])
          fmt::print("{:<8} {:>4}^2 {:>5.0f} Hz   {}\n", r["method"].get<std::string>(), r["field_size"].get<int>(), num(r, "paper_hz"),
                     r["cycles_per_frame"].is_number() ? fmt::format("{:.0f} cycles, {:.2f} lookups/fragment", num(r, "cycles_per_frame"),
                                                                     num(r, "lookups_per_fragment"))
                                                       : std::string("-"));
        if (differing) fmt::print("fragments whose walk differs from GL's: {}\n", differing);
        return differing == 0 ? 0 : 1;
      };
    });
  }
  {
    auto* cmd = app.add_subcommand("config", "List every model config key with its default, unit, limits and meaning");
    auto defaults = std::make_shared<bool>(false);
    auto json = std::make_shared<bool>(false);
    cmd->add_flag("--defaults", *defaults, "List the defaults (the only listing there is today)");
    cmd->add_flag("--json", *json, "As a JSON array");
    // Every option's storage is captured by the callback: it must outlive this set-up function,
    // since CLI11 writes into it while parsing.
    cmd->callback([&action, defaults, json] {
      action = [defaults, json] {
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
