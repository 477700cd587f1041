// Capture driver: city, path, renderer, trace writer; see capture.h.
#include "traces/capture/capture.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <regex>

#include "model/common/error.h"
#include "traces/capture/renderer.h"
#include "traces/format/writer.h"

namespace nbsim::capture {

trace::TestMode parse_test_mode(const std::string& s) {
  if (const auto m = scene::parse_test_mode(s)) return *m;
  throw InputError(fmt::format("unknown test mode '{}': expected oq, oq_hier, nb, nb_hier or none", s));
}

CaptureSummary capture_city(const CaptureOptions& o, const std::string& out_path, const Progress& progress) {
  if (o.width < 1 || o.height < 1 || o.width > 4096 || o.height > 4096)
    throw InputError(fmt::format("capture size {}x{} is out of range (1x1 to 4096x4096)", o.width, o.height));
  if (o.frames < 1) throw InputError("--frames must be at least 1");
  if (o.objects < 2) throw InputError("--objects must be at least 2");
  const auto t0 = std::chrono::steady_clock::now();
  CityParams cp;
  cp.seed = o.seed;
  cp.objects = o.objects;
  const City city = make_city(cp);
  const auto poses = make_path(city, o.path, o.frames, o.seed);
  RendererOptions ro;
  ro.width = o.width;
  ro.height = o.height;
  ro.mode = o.mode;
  ro.projection.reversed_z = o.reversed_z;
  Renderer renderer(city, ro);

  const auto& gl = renderer.gl_info();
  std::smatch m;
  const std::string mesa = std::regex_search(gl.version, m, std::regex("Mesa ([0-9][^ ]*)")) ? m[1].str() : "unknown";
  trace::Properties props = {
      {"gl_renderer", gl.renderer},
      {"gl_version", gl.version},
      {"gl_vendor", gl.vendor},
      {"mesa_version", mesa},
      {"viewport", fmt::format("{}x{}", o.width, o.height)},
      {"depth_format", "DEPTH_COMPONENT32F"},
      {"depth_func", o.reversed_z ? "GREATER" : "LESS"},
      {"clip_control", o.reversed_z ? "ZERO_TO_ONE" : "NEGATIVE_ONE_TO_ONE"},
      {"depth_clear", o.reversed_z ? "0" : "1"},
      {"technique", "occlusion_culling"},
      {"test_mode", std::string(scene::to_string(o.mode))},
      {"scene", "city"},
      {"seed", std::to_string(o.seed)},
      {"objects", std::to_string(city.objects.size())},
      {"path", o.path == PathKind::Walk ? "walk" : "fly"},
      {"frames", std::to_string(o.frames)},
      {"fov_y_deg", fmt::format("{}", ro.projection.fov_y_deg)},
      {"near", fmt::format("{}", ro.projection.near_m)},
      {"far", fmt::format("{}", ro.projection.far_m)},
      {"nearest_margin", fmt::format("{}", ro.nearest_margin)},
      {"levels_every", std::to_string(o.levels_every)},
      {"nbsim_version", NBSIM_VERSION},
      {"command_line", o.command_line},
  };
  trace::TraceWriter writer(out_path, props);
  writer.write(city.scene);
  CaptureSummary sum;
  for (int f = 0; f < o.frames; ++f) {
    const bool keep_levels = o.levels_every > 0 && f % o.levels_every == 0;
    const CapturedFrame fr = renderer.render(static_cast<std::uint32_t>(f), poses[static_cast<std::size_t>(f)], keep_levels);
    writer.begin_frame(fr.begin);
    for (const auto& d : fr.draws) writer.write(d);
    for (const auto& d : fr.depth) writer.write(d);
    if (fr.levels) writer.write(*fr.levels);
    writer.write(fr.truth);
    writer.end_frame(fr.end);
    sum.frames++;
    sum.gl_ms += fr.end.gl_ms;
    sum.draws += fr.draws.size();
    sum.objects_rendered += fr.rendered_objects.size();
    for (std::size_t obj = 0; obj < fr.truth.visible_pixels.size(); ++obj) {
      if (!fr.truth.visible_pixels[obj]) continue;
      ++sum.objects_visible;
      if (!std::binary_search(fr.rendered_objects.begin(), fr.rendered_objects.end(), static_cast<std::uint32_t>(obj)))
        ++sum.visible_not_rendered;
    }
    if (progress) progress(f + 1, o.frames);
  }
  writer.close();
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sum.bytes = std::filesystem::file_size(out_path);
  return sum;
}

}  // namespace nbsim::capture
