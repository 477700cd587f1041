// `nbsim shadows`: the shadows table, from one replay of each trace (pipeline/cli/table_command.h).
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

void add_shadows_commands(CLI::App& app, Action& action) {
  // One replay per shadows trace (one capture per shadow_mode: GL's volumes depend on it), in
  // child processes, and a row each from its run.json's /summary/shadows beside the paper's
  // figures (fill 20 M -> 512 K px in the city, 2.5%; about 20% on simpler scenes). The ratio to
  // infinite divides by the trace's own reference fill (SHDC reference_fill: GL's infinite volumes
  // of the same frames); a trace captured before that field gets the fill per frame of an
  // `infinite` row of the same scene, seed, viewport and frames given in the same command ("-"
  // when there is none); `ratio_reference` says which.
  auto* cmd = app.add_subcommand(
      "shadows", "Replay shadows traces (one per shadow mode) and print the shadows table; exit 1 when a mask pixel differs from the "
                 "reference of the volumes drawn (mask_errors: GL's masks for GL's volumes, the model's own infinite volumes for its own)");
  auto a = std::make_shared<TableCommandArgs>();
  a->add_options(cmd, "Shadows traces (nbsim capture shadows), e.g. one per --shadow-mode", "shadows.json");
  auto breakdown = std::make_shared<bool>(false);
  cmd->add_flag("--breakdown", *breakdown,
                "Also print where each trace's fill goes: per caster class and reason kept (the JSON rows always hold it as fill_breakdown)");
  cmd->callback([&action, a, breakdown] {
    action = [a, breakdown] {
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
        for (const char* k : {"scene", "path", "shadow_mode", "clamp_rule", "litmap_size"}) r[k] = p->contains(k) ? (*p)[k] : nlohmann::json("");
        if (p->contains("replayed_litmap_size")) r["litmap_size"] = std::to_string((*p)["replayed_litmap_size"].get<int>());
        r["settings"] = settings_of(a->mo);
        for (const char* k : {"frames", "casters_per_frame", "culled_per_frame", "gl_culled_per_frame", "outside_per_frame", "fill_per_frame",
                              "gl_fill_per_frame", "reference_fill_per_frame", "fill_ratio_to_infinite", "build_texels_per_frame", "lookups_per_frame", "stencil_tests_per_frame",
                              "litmap_reprojections_per_frame", "receiver_splats_per_frame", "cycles_per_frame", "nbuffer_memory_bytes", "mask_diff",
                              "mask_diff_infinite", "decision_mismatches", "zmin_mismatches", "zmax_mismatches",
                              "not_conservative", "unsafe_culls", "kept_by_slab", "model_volumes", "own_mask_diff", "mask_errors", "litmap_texel_diff"})
          r[k] = (*p)[k];
        r["fill_breakdown"] = p->value("fill_breakdown", nlohmann::json::array());
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
        differing += r["mask_errors"].get<std::uint64_t>();
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
      fmt::print("{:<8} {:<7} {:<9} {:>12} {:>8} {:>7} {:>14} {:>10} {:>8} {:>11} {:>8} {:>8} {:>10}\n", "scene", "path", "mode",
                 "fill/frame", "ratio", "paper", "culled/casters", "build", "lookups", "cycles", "mask", "mask_inf", "mismatches");
      for (const auto& r : list) {
        const auto num = [&](const char* k) { return r[k].is_number() ? r[k].get<double>() : 0.0; };
        const std::string scene = r["scene"].get<std::string>();
        const std::string paper = r["shadow_mode"] == "clamped" ? (scene == "boxes" ? "~20%" : "2.5%") : "-";
        const std::string path = r["path"].is_string() && !r["path"].get<std::string>().empty() ? r["path"].get<std::string>() : "-";
        fmt::print("{:<8} {:<7} {:<9} {:>12.0f} {:>8} {:>7} {:>14} {:>10.0f} {:>8.0f} {:>11.0f} {:>8} {:>8} {:>10}\n", scene, path,
                   r["shadow_mode"].get<std::string>(), num("fill_per_frame"),
                   r["ratio_to_infinite"].is_number() ? fmt::format("{:.1f}%", 100.0 * num("ratio_to_infinite")) : std::string("-"),
                   paper, fmt::format("{:.1f}/{:.0f}", num("gl_culled_per_frame") + num("outside_per_frame"), num("casters_per_frame")),
                   num("build_texels_per_frame"), num("lookups_per_frame"), num("cycles_per_frame"), r["mask_diff"].dump(),
                   r["mask_diff_infinite"].dump(),
                   r["decision_mismatches"].get<std::uint64_t>() + r["zmin_mismatches"].get<std::uint64_t>() +
                       r["zmax_mismatches"].get<std::uint64_t>());
      }
      if (*breakdown)
        for (const auto& r : list) {
          fmt::print("\n{} ({} {}, rule {}): fill per frame by caster class and reason kept\n", r["trace"].get<std::string>(),
                     r["scene"].get<std::string>(), r["shadow_mode"].get<std::string>(), r["clamp_rule"].get<std::string>());
          fmt::print("  {:<10} {:<13} {:>10} {:>12} {:>14} {:>8}\n", "class", "kept", "casters", "fill", "fill infinite", "share");
          double total = 0.0;
          for (const auto& b : r["fill_breakdown"]) total += b["fill_per_frame"].get<double>();
          for (const auto& b : r["fill_breakdown"])
            fmt::print("  {:<10} {:<13} {:>10.1f} {:>12.0f} {:>14.0f} {:>7.1f}%\n", b["class"].get<std::string>(), b["kept"].get<std::string>(),
                       b["casters_per_frame"].get<double>(), b["fill_per_frame"].get<double>(), b["fill_infinite_per_frame"].get<double>(),
                       total > 0.0 ? 100.0 * b["fill_per_frame"].get<double>() / total : 0.0);
        }
      if (differing) fmt::print("mask pixels differing from the reference of the volumes drawn: {}\n", differing);
      return differing == 0 ? 0 : 1;
    };
  });
}

}  // namespace nbsim::cli
