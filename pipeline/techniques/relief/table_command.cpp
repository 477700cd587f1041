// `nbsim relief`: the relief table, from one replay of each trace (pipeline/cli/table_command.h).
#include "pipeline/cli/command.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>

#include "model/common/error.h"
#include "pipeline/cli/table_command.h"
#include "pipeline/techniques/relief/relief_table.h"
#include "pipeline/techniques/results.h"

namespace nbsim::cli {

void add_relief_commands(CLI::App& app, Action& action) {
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
      for (const auto& r : rows)
        differing += r["pixel_mismatches"].get<std::uint64_t>() + r["walk_mismatches"].get<std::uint64_t>() + r["depth_mismatches"].get<std::uint64_t>();
      if (!a->out.empty()) {
        const std::filesystem::path dir = a->out;
        std::ofstream f(dir / "relief.json");
        f << doc.dump(2) << "\n";
        if (!f) throw InputError(fmt::format("cannot write '{}'", (dir / "relief.json").string()));
        std::ofstream c(dir / "relief.csv");
        c << "trace,field,field_size,frame,angle,method,fragments,lookups,steps,errors,reference_hits,cycles,lookups_per_fragment,"
             "steps_per_fragment,error_rate,pixel_mismatches,walk_mismatches,box_depth,rasterized,depth_written,depth_mismatches,scene_hidden\n";
        for (const auto& r : rows) {
          const auto num = [&](const char* k) { return r[k].is_null() ? std::string() : r[k].dump(); };
          c << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", r["trace"].get<std::string>(), r["field"].get<std::string>(),
                           num("field_size"), num("frame"), num("angle"), r["method"].get<std::string>(), num("fragments"), num("lookups"),
                           num("steps"), num("errors"), num("reference_hits"), num("cycles"), num("lookups_per_fragment"),
                           num("steps_per_fragment"), num("error_rate"), num("pixel_mismatches"), num("walk_mismatches"),
                           r["box_depth"].get<std::string>(), num("rasterized"), num("depth_written"), num("depth_mismatches"), num("scene_hidden"));
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
      fmt::print("{:<13} {:>12} {:>10} {:>9} {:>9} {:>13}\n", "method", "cycles/frame", "lookups/f", "errors", "error", "bytes/texel");
      for (const auto& r : doc["ranking"])
        fmt::print("{:<13} {:>12.0f} {:>10.2f} {:>9} {:>8.3f}% {:>13.1f}{}\n", r["method"].get<std::string>(), num(r, "cycles_per_frame"),
                   num(r, "lookups_per_fragment"), r["errors"].get<std::uint64_t>(), 100.0 * num(r, "error_rate"),
                   num(r, "storage_bytes_per_texel"), r["pareto"].get<bool>() ? " *" : "");
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
      if (differing) fmt::print("fragments whose walk differs from GL's, and box draws whose depth does: {}\n", differing);
      return differing == 0 ? 0 : 1;
    };
  });
}

}  // namespace nbsim::cli
