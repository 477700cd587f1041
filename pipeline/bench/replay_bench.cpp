// The simulator-speed benchmark; see replay_bench.h.
#include "pipeline/bench/replay_bench.h"

#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <string_view>

#include "model/common/error.h"
#include "model/common/names.h"
#include "model/particles/sprite.h"
#include "model/scene/frame.h"
#include "pipeline/sim/replay.h"
#include "traces/capture/capture.h"

namespace nbsim::bench {

nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& o) {
  capture::CaptureOptions c;
  if (std::sscanf(o.size.c_str(), "%dx%d", &c.width, &c.height) != 2) c.width = c.height = 512;
  c.frames = o.frames;
  c.technique = o.technique;
  c.scene = o.scene.empty() ? "city" : o.scene;
  const bool particles = o.technique == "particles";
  const bool ldi = o.technique == "ldi";
  if (c.scene != "city" && o.technique != "shadows")
    throw InputError(fmt::format("--scene {}: {} benches the city only (the other scenes are the shadows technique's)", c.scene,
                                 o.technique));
  std::string mode = o.mode;
  if (particles) {
    if (mode.empty()) mode = "nb";
    if (!particles::parse_mode(mode))
      throw InputError(fmt::format("--mode '{}' is not a particles mode ({})", mode, fmt::join(name_list(particles::kModeNames), ", ")));
    c.options = {{"mode", mode}, {"levels-every", "0"}, {"particles", std::to_string(o.particles)}, {"sprite", o.sprite}};
  } else if (o.technique == "occlusion_culling") {
    if (mode.empty()) mode = "oq";
    if (!parse_enum_name<scene::TestMode>(scene::kTestModeNames, mode))
      throw InputError(fmt::format("--mode '{}' is not an occlusion_culling mode ({})", mode, fmt::join(name_list(scene::kTestModeNames), ", ")));
    c.options = {{"mode", mode}, {"levels-every", "0"}};
  } else if (o.technique == "shadows") {
    if (mode.empty()) mode = "clamped";
    if (mode != "infinite" && mode != "culled" && mode != "clamped")
      throw InputError(fmt::format("--mode '{}' is not a shadows mode (infinite, culled, clamped)", mode));
    c.path = "fly";
    c.options = {{"shadow-mode", mode}, {"levels-every", "0"}};
  } else if (ldi) {
    // The LDI work does not look at the observer: the smallest scene the capture accepts.
    if (!mode.empty()) throw InputError("--mode is not an ldi option (the shape is --shape)");
    mode = o.shape.empty() ? "knot" : o.shape;
    c.scene = "boxes";
    c.path = "fly";
    c.width = c.height = 8;
    c.options = {{"boxes", "0"}, {"shape", mode}, {"ldi-size", std::to_string(o.ldi_size)}};
  } else if (o.technique == "relief") {
    // The relief box is seen from its own camera: the smallest scene the capture accepts.
    if (!mode.empty()) throw InputError("--mode is not a relief option (the heightfield is --field)");
    mode = o.field.empty() ? "fbm" : o.field;
    c.scene = "boxes";
    c.path = "fly";
    c.options = {{"boxes", "0"}, {"field", mode}, {"field-size", std::to_string(o.field_size)}};
  } else {
    throw InputError(fmt::format("--technique '{}' is not one of {}", o.technique, fmt::join(kReplayBenchTechniques, ", ")));
  }
  const auto file = std::filesystem::temp_directory_path() / ("nbsim_bench_" + std::to_string(::getpid()) + ".nbt");
  const capture::CaptureSummary cap = capture::capture(c, file.string());

  pipeline::ReplayOptions r;
  r.trace = file;
  pipeline::ReplaySummary s;
  try {
    s = pipeline::replay(r);
  } catch (...) {
    std::filesystem::remove(file);
    throw;
  }
  std::filesystem::remove(file);

  nlohmann::ordered_json j;
  j["bench"] = "replay";
  j["technique"] = o.technique;
  j["size"] = o.size;
  j["frames"] = s.frames;
  j["mode"] = mode;
  if (particles) {
    j["particles"] = o.particles;
    j["sprite"] = o.sprite;
  }
  if (o.technique == "shadows") j["scene"] = c.scene;
  if (ldi) j["ldi_size"] = o.ldi_size;
  j["draws"] = s.draws;
  j["gl_ms"] = cap.gl_ms;
  j["replay_ms"] = s.host_seconds * 1e3;
  j["ratio"] = cap.gl_ms > 0 ? s.host_seconds * 1e3 / cap.gl_ms : 0.0;
  j["depth_tests"] = s.depth_tests;
  j["depth_tests_per_s"] = s.host_seconds > 0 ? static_cast<double>(s.depth_tests) / s.host_seconds : 0.0;
  j["cycles"] = s.cycles;
  j["cycles_per_s"] = s.host_seconds > 0 ? static_cast<double>(s.cycles) / s.host_seconds : 0.0;
  j["draws_exact"] = s.draws_exact;
  j["within_thresholds"] = s.within_thresholds();
  if (particles) j["particles_summary"] = s.particles;
  if (!s.shadows.is_null()) {  // its per-frame values aside: the bench reports totals
    nlohmann::ordered_json sh = s.shadows;
    sh.erase("per_frame");
    j["shadows_summary"] = std::move(sh);
  }
  if (ldi && !s.ldi.is_null()) j["ldi_summary"] = s.ldi;
  if (o.technique == "relief") {
    j["field_size"] = o.field_size;
    if (!s.relief.is_null()) j["relief_summary"] = s.relief;
  }
  return j;
}

}  // namespace nbsim::bench
