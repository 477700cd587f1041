// `nbsim replay`, `nbsim compare`, `nbsim table2` and `nbsim config`: the SystemC model from the
// command line (a technique's own table command sits in its folder, pipeline/techniques/<name>/). table2 runs one replay per row of the table the trace's technique declares
// (pipeline/techniques/results.h; e.g. one per culling mode), each in a child process
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
#include "pipeline/cli/table_command.h"
#include "pipeline/cli/progress.h"
#include "pipeline/explore/child.h"
#include "pipeline/explore/runner.h"
#include "pipeline/sim/replay.h"
#include "pipeline/techniques/results.h"
#include "traces/format/reader.h"

namespace nbsim::cli {

namespace {

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
                "frame's 'stencil' image when it has one, and what the trace's technique program compares with GL itself\n"
                "(e.g. each walk or peel pass) equal to GL's; exit 1 otherwise.");
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
    // footer shows every declared table's.
    std::string footer;
    for (const techniques::TechniqueResults& r : techniques::technique_results())
      if (r.table) footer += r.table->footer + "\n";
    cmd->footer(footer + "Rows and columns: the trace's technique's declared table; a technique without one exits 2.");
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
