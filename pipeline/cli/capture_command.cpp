// `nbsim capture TECHNIQUE --scene NAME --path NAME ...`: record a depth trace with the real GL
// renderer. One subcommand per row of the technique table; the scene, camera path and technique
// options come from their tables (traces/capture/technique.h, scenes.h, paths.h). A row's aliases
// (CaptureAlias) are subcommands too: another name with the scene fixed.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <map>
#include <memory>
#include <vector>

#include "model/common/error.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "traces/capture/capture.h"
#include "traces/capture/paths.h"
#include "traces/capture/scenes.h"
#include "traces/capture/technique.h"

namespace nbsim::cli {

namespace {

// "Scenes (--scene): ...\nCamera paths (--path): ..." from the tables (without the scenes for an
// alias, whose scene is fixed).
std::string tables_footer(bool scenes = true) {
  std::string out;
  if (scenes) {
    out += "Scenes (--scene):\n";
    for (const auto& s : capture::scene_table()) out += fmt::format("  {:<18} {}\n", s.info.name, s.info.description);
  }
  out += "Camera paths (--path):\n";
  for (const auto& p : capture::path_table()) out += fmt::format("  {:<18} {}\n", p.info.name, p.info.description);
  return out;
}

struct Args {
  std::string scene = "city", path = "walk", size = "512x512", out;
  int frames = 60;
  bool reversed_z = false;
  // Registry options by name, with the CLI11 option that fills each.
  std::map<std::string, std::string> values;
  std::map<std::string, CLI::Option*> given;
  CLI::Option *scene_opt = nullptr, *path_opt = nullptr;  // --scene (not for an alias) and --path
};

// Adds --NAME once for every option the plug-ins in `owners` (row, kind) declare, grouped by the
// kind of the first that declares it, naming every plug-in that reads it.
void add_plugin_options(CLI::App* cmd, Args& a, const std::vector<std::pair<const capture::PluginInfo*, std::string>>& owners) {
  for (const auto& [info, kind] : owners)
    for (const capture::OptionSpec& spec : info->options) {
      if (a.given.count(spec.name)) continue;
      std::string readers;
      for (const auto& [other, other_kind] : owners)
        for (const capture::OptionSpec& o : other->options)
          if (o.name == spec.name) readers += (readers.empty() ? "" : ", ") + other_kind + " " + other->name;
      std::string& value = a.values[spec.name];
      value = spec.default_value;
      CLI::Option* opt = cmd->add_option("--" + spec.name, value, fmt::format("{} [{}]", spec.help, readers));
      opt->type_name(spec.kind == capture::OptionSpec::Kind::Integer ? fmt::format("INT in [{} - {}]", spec.min, spec.max)
                     : spec.kind == capture::OptionSpec::Kind::Text  ? std::string("TEXT")
                                                                      : "{" + fmt::format("{}", fmt::join(spec.choices, ",")) + "}");
      opt->capture_default_str()->group(kind == "scene" ? "Scene options" : kind == "path" ? "Camera path options" : "Technique options");
      a.given[spec.name] = opt;
    }
}

// One capture subcommand. technique: the row it runs; alias: one of its aliases (scene fixed, no
// --scene), or null for the technique's own subcommand.
void add_capture_subcommand(CLI::App* cap, Action& action, const capture::TechniqueRow& technique,
                            const capture::CaptureAlias* alias) {
  auto a = std::make_shared<Args>();
  const bool legacy = alias != nullptr;
  const std::string same = legacy ? fmt::format("nbsim capture {} --scene {}", technique.info.name, alias->scene) : "";
  if (legacy) a->scene = alias->scene;
  CLI::App* cmd = legacy ? cap->add_subcommand(alias->name, fmt::format("Old spelling of `{}`, kept for recorded command lines", same))
                         : cap->add_subcommand(technique.info.name, technique.info.description);
  if (!legacy) a->scene_opt = cmd->add_option("--scene", a->scene, "Scene, by name (below); a capture that draws no scene takes none")->capture_default_str();
  a->path_opt = cmd->add_option("--path", a->path, "Camera path, by name (below); a capture that draws no scene takes none")->capture_default_str();
  cmd->add_option("--size", a->size, "Viewport, WxH")->capture_default_str();
  cmd->add_option("--frames", a->frames, "Frames along the camera path")->check(CLI::Range(1, 100000))->capture_default_str();
  cmd->add_flag("--reversed-z", a->reversed_z, "Reversed Z: ZERO_TO_ONE clip control, depth func GREATER, clear 0");
  cmd->add_option("-o,--out", a->out, "Trace file to write")->required();
  std::vector<std::pair<const capture::PluginInfo*, std::string>> owners;
  for (const auto& s : capture::scene_table())
    if (!legacy || s.info.name == alias->scene) owners.emplace_back(&s.info, "scene");
  for (const auto& p : capture::path_table()) owners.emplace_back(&p.info, "path");
  owners.emplace_back(&technique.info, "technique");
  add_plugin_options(cmd, *a, owners);
  cmd->footer(legacy ? "Same as: " + same + " [options]; traces are identical.\n" + tables_footer(false)
                     : tables_footer());
  const std::string technique_name = technique.info.name;
  cmd->callback([&action, a, technique_name] {
    action = [a, technique_name] {
      capture::CaptureOptions c;
      c.technique = technique_name;
      c.scene = a->scene;
      c.path = a->path;
      c.scene_given = a->scene_opt && a->scene_opt->count() > 0;
      c.path_given = a->path_opt->count() > 0;
      std::tie(c.width, c.height) = parse_size(a->size, "--size");
      c.frames = a->frames;
      c.reversed_z = a->reversed_z;
      for (const auto& [name, opt] : a->given)
        if (opt->count() > 0) c.options.set(name, a->values.at(name));
      // Both spellings record the current one, every option spelled out.
      c.command_line = capture::canonical_command_line(c, a->out);
      ProgressBar bar("capture", c.frames);
      const auto s = capture::capture(c, a->out, [&](int done, int) { bar.update(done); });
      bar.finish();
      fmt::print("captured {} frames at {} in {:.1f} s ({:.2f} frames/s, GL technique {:.1f} ms/frame): {} ({:.2f} MB, {:.0f} KB/frame)\n",
                 s.frames, a->size, s.seconds, s.frames / s.seconds, s.gl_ms / s.frames, a->out,
                 static_cast<double>(s.bytes) / 1e6, static_cast<double>(s.bytes) / 1e3 / s.frames);
      fmt::print("  {} draws; objects rendered {}, visible by ground truth {}, visible but not rendered {}\n", s.draws,
                 s.objects_rendered, s.objects_visible, s.visible_not_rendered);
      if (!s.technique_counts.empty()) {
        std::string counts;
        for (const auto& [name, value] : s.technique_counts) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", name, value);
        fmt::print("  {} (summed over the frames)\n", counts);
      }
      return s.visible_not_rendered == 0 ? 0 : 1;
    };
  });
}

}  // namespace

void add_capture_command(CLI::App& app, Action& action) {
  auto* cap = app.add_subcommand("capture", "Record depth traces with the headless GL renderer on Mesa");
  cap->require_subcommand(1);
  std::string aliases;
  for (const auto& t : capture::technique_table()) add_capture_subcommand(cap, action, t, nullptr);
  for (const auto& t : capture::technique_table())
    for (const capture::CaptureAlias& alias : t.aliases) {
      add_capture_subcommand(cap, action, t, &alias);
      aliases += fmt::format("`nbsim capture {} ...` is the old spelling of `nbsim capture {} --scene {} ...`.\n", alias.name,
                             t.info.name, alias.scene);
    }
  cap->footer("Usage: nbsim capture TECHNIQUE [--scene NAME] [--path NAME] [options] -o OUT  (TECHNIQUE --help lists its options)\n" +
              aliases + tables_footer());
}

}  // namespace nbsim::cli
