// Capture driver: scene, camera path, renderer with its technique, trace writer; see capture.h.
#include "traces/capture/capture.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <regex>

#include "model/common/error.h"
#include "traces/capture/paths.h"
#include "traces/capture/renderer.h"
#include "traces/capture/scenes.h"
#include "traces/capture/technique.h"
#include "traces/format/header.h"
#include "traces/format/writer.h"

namespace nbsim::capture {

namespace {

void append(trace::Properties& to, const trace::Properties& from) { to.insert(to.end(), from.begin(), from.end()); }

// The chosen rows' options, each name once, in the order scene, path, technique.
std::vector<const OptionSpec*> chosen_options(const SceneRow& s, const PathRow& p, const TechniqueRow& t) {
  std::vector<const OptionSpec*> out;
  for (const PluginInfo* info : {&s.info, &p.info, &t.info})
    for (const OptionSpec& o : info->options)
      if (std::none_of(out.begin(), out.end(), [&](const OptionSpec* x) { return x->name == o.name; })) out.push_back(&o);
  return out;
}

// Why the capture draws no scene (the technique's answer), or empty when it draws one.
std::string no_scene_reason(const TechniqueRow& t, const OptionValues& options) { return t.no_scene ? t.no_scene(options) : ""; }

bool declared_by(const PluginInfo& info, const std::string& name) {
  return std::any_of(info.options.begin(), info.options.end(), [&](const OptionSpec& o) { return o.name == name; });
}

// A capture that draws no scene takes no --scene, --path or option only they read, except in the
// spelling older captures were recorded with (the empty box scene along the fly path).
void refuse_scene_options(const CaptureOptions& o, const SceneRow& s, const PathRow& p, const TechniqueRow& t,
                          const std::string& why) {
  const auto& given = o.options.values();
  const auto boxes = given.find("boxes");
  const bool old_spelling = o.scene == "boxes" && o.path == "fly" && boxes != given.end() && boxes->second == "0";
  if (old_spelling) return;
  const auto refuse = [&](const std::string& what) {
    return InputError(fmt::format("{}: the {} capture draws no scene ({}), so it takes no {}", what, t.info.name, why, what));
  };
  if (o.scene_given) throw refuse("--scene " + o.scene);
  if (o.path_given) throw refuse("--path " + o.path);
  for (const auto& [name, value] : o.options.values())
    if (!declared_by(t.info, name) && (declared_by(s.info, name) || declared_by(p.info, name))) throw refuse("--" + name + " " + value);
}

}  // namespace

std::string canonical_command_line(const CaptureOptions& o, const std::string& out_path) {
  const SceneRow& s = find_scene(o.scene);
  const PathRow& p = find_path(o.path);
  const TechniqueRow& t = find_technique(o.technique);
  if (!no_scene_reason(t, o.options).empty()) {  // no scene: its options and the path's are not the capture's
    std::string line = fmt::format("nbsim capture {} --size {}x{} --frames {}", t.info.name, o.width, o.height, o.frames);
    for (const OptionSpec& spec : t.info.options) line += fmt::format(" --{} {}", spec.name, o.options.text(spec));
    if (o.reversed_z) line += " --reversed-z";
    return line + " -o " + out_path;
  }
  std::string line = fmt::format("nbsim capture {} --scene {} --path {} --size {}x{} --frames {}", t.info.name, s.info.name,
                                 p.info.name, o.width, o.height, o.frames);
  for (const OptionSpec* spec : chosen_options(s, p, t)) line += fmt::format(" --{} {}", spec->name, o.options.text(*spec));
  if (o.reversed_z) line += " --reversed-z";
  return line + " -o " + out_path;
}

CaptureSummary capture(const CaptureOptions& o, const std::string& out_path, const Progress& progress) {
  if (o.width < 1 || o.height < 1 || o.width > 4096 || o.height > 4096)
    throw InputError(fmt::format("capture size {}x{} is out of range (1x1 to 4096x4096)", o.width, o.height));
  if (o.frames < 1) throw InputError("--frames must be at least 1");
  const SceneRow& scene_row = find_scene(o.scene);
  const PathRow& path_row = find_path(o.path);
  const TechniqueRow& technique_row = find_technique(o.technique);
  check_options_declared(o.options, {&scene_row.info, &path_row.info, &technique_row.info});
  // Every value checked before the (slow) scene is built.
  for (const OptionSpec* spec : chosen_options(scene_row, path_row, technique_row)) o.options.text(*spec);

  const std::string no_scene = no_scene_reason(technique_row, o.options);
  if (!no_scene.empty()) refuse_scene_options(o, scene_row, path_row, technique_row, no_scene);

  const auto t0 = std::chrono::steady_clock::now();
  // Only a capture that draws the scene builds it and walks the camera path.
  const CaptureScene scene = no_scene.empty() ? scene_row.make(o.options) : CaptureScene{};
  if (!o.poses.empty() && o.poses.size() != static_cast<std::size_t>(o.frames))
    throw InputError(fmt::format("{} camera poses given for {} frames", o.poses.size(), o.frames));
  const auto poses = !o.poses.empty()    ? o.poses
                     : no_scene.empty() ? path_row.make(scene, o.frames, o.options)
                                        : std::vector<CameraPose>(static_cast<std::size_t>(o.frames));
  RendererOptions ro;
  ro.technique = o.technique;
  ro.width = o.width;
  ro.height = o.height;
  ro.projection.reversed_z = o.reversed_z;
  ro.options = o.options;
  Renderer renderer(scene, ro);

  const auto& gl = renderer.gl_info();
  std::smatch m;
  const std::string mesa = std::regex_search(gl.version, m, std::regex("Mesa ([0-9][^ ]*)")) ? m[1].str() : "unknown";
  trace::Properties props = {
      {"gl_renderer", gl.renderer},
      {"gl_version", gl.version},
      {"gl_vendor", gl.vendor},
      {"mesa_version", mesa},
      {"viewport", fmt::format("{}x{}", o.width, o.height)},
      {"depth_format", renderer.technique().depth_format()},
      {"depth_func", trace::gl_name(o.reversed_z ? trace::DepthFunc::Greater : trace::DepthFunc::Less)},
      {"clip_control", trace::gl_name(o.reversed_z ? trace::ClipControl::ZeroToOne : trace::ClipControl::NegativeOneToOne)},
      {"depth_clear", o.reversed_z ? "0" : "1"},
      {"technique", technique_row.info.name},
  };
  append(props, renderer.technique().variant_properties());
  props.emplace_back("scene", no_scene.empty() ? scene_row.info.name : "none");
  append(props, scene.properties);
  props.emplace_back("path", no_scene.empty() ? path_row.info.name : "none");
  props.emplace_back("frames", std::to_string(o.frames));
  props.emplace_back("fov_y_deg", fmt::format("{}", ro.projection.fov_y_deg));
  props.emplace_back("near", fmt::format("{}", ro.projection.near_m));
  props.emplace_back("far", fmt::format("{}", ro.projection.far_m));
  append(props, renderer.technique().setting_properties());
  props.emplace_back("nbsim_version", NBSIM_VERSION);
  props.emplace_back("command_line", o.command_line.empty() ? canonical_command_line(o, out_path) : o.command_line);

  // Written under a temporary name, renamed when whole; removed on any failure.
  const std::filesystem::path final_path(out_path), partial(out_path + ".partial");
  CaptureSummary sum;
  try {
    trace::TraceWriter writer(partial.string(), props);
    writer.write(scene.scene);
    for (int f = 0; f < o.frames; ++f) {
      const CapturedFrame cf = renderer.render(static_cast<std::uint32_t>(f), poses[static_cast<std::size_t>(f)]);
      const scene::Frame& fr = cf.frame;
      writer.begin_frame(fr.begin);
      for (const auto& d : fr.draws) writer.write(d);
      for (const auto& d : fr.depths) writer.write(d);
      for (const auto& l : fr.levels) writer.write(l);
      for (const auto& s : fr.stencils) writer.write(s);
      if (fr.light) writer.write_light(*fr.light);
      for (const auto& r : fr.technique_records) writer.write(r);
      if (fr.truth) writer.write(*fr.truth);
      writer.end_frame(fr.end);
      sum.frames++;
      sum.gl_ms += fr.end.gl_ms;
      sum.draws += fr.draws.size();
      for (const auto& [name, value] : cf.counts) {
        auto it = std::find_if(sum.technique_counts.begin(), sum.technique_counts.end(), [&](const auto& c) { return c.first == name; });
        if (it == sum.technique_counts.end()) it = sum.technique_counts.insert(it, {name, 0});
        it->second += value;
      }
      if (cf.rendered_objects && fr.truth) {
        const auto& rendered = *cf.rendered_objects;
        sum.objects_rendered += rendered.size();
        for (std::size_t obj = 0; obj < fr.truth->visible_pixels.size(); ++obj) {
          if (!fr.truth->visible_pixels[obj]) continue;
          ++sum.objects_visible;
          if (!std::binary_search(rendered.begin(), rendered.end(), static_cast<std::uint32_t>(obj))) ++sum.visible_not_rendered;
        }
      }
      if (progress) progress(f + 1, o.frames);
    }
    writer.close();
    std::error_code renamed;
    std::filesystem::rename(partial, final_path, renamed);
    if (renamed) throw InputError(fmt::format("cannot write trace '{}': renaming '{}' to it: {}", out_path, partial.string(), renamed.message()));
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw;
  }
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sum.bytes = std::filesystem::file_size(out_path);
  return sum;
}

}  // namespace nbsim::capture
