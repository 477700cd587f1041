// `nbsim particles`: the particles table, from one replay of each trace (pipeline/cli/table_command.h).
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
#include "pipeline/techniques/results.h"

namespace nbsim::cli {

void add_particles_commands(CLI::App& app, Action& action) {
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

}  // namespace nbsim::cli
