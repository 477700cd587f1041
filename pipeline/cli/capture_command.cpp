// `nbsim capture city`: record a depth trace of the city walkthrough with the real GL renderer.
#include <fmt/format.h>

#include <memory>

#include "model/common/error.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "traces/capture/capture.h"

namespace nbsim::cli {

void add_capture_command(CLI::App& app, Action& action) {
  auto* cap = app.add_subcommand("capture", "Record depth traces with the headless GL renderer on Mesa");
  cap->require_subcommand(1);
  auto* cmd = cap->add_subcommand("city", "Occlusion culling in a procedural city walkthrough (N-buffer paper, 4.2)");
  struct Opts {
    std::string size = "512x512", path = "walk", mode = "nb_hier", out;
    int frames = 60, objects = 6000, levels_every = 10;
    unsigned seed = 1;
    bool reversed_z = false;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--size", o->size, "Viewport, WxH")->capture_default_str();
  cmd->add_option("--frames", o->frames, "Frames along the camera path")->check(CLI::Range(1, 100000))->capture_default_str();
  cmd->add_option("--path", o->path, "walk (street level) or fly (flyover)")->check(CLI::IsMember({"walk", "fly"}))->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the city and the path")->capture_default_str();
  cmd->add_option("--objects", o->objects, "Objects in the city, ground included")->check(CLI::Range(2, 1000000))->capture_default_str();
  cmd->add_option("--mode", o->mode, "Visibility test: oq, oq_hier (occlusion queries, flat or over the BVH), nb, nb_hier (GLSL N-buffer), none")
      ->check(CLI::IsMember({"oq", "oq_hier", "nb", "nb_hier", "none"}))
      ->capture_default_str();
  cmd->add_option("--levels-every", o->levels_every, "Record the GLSL N-buffer levels every K-th frame (0: never)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  cmd->add_flag("--reversed-z", o->reversed_z, "Reversed Z: ZERO_TO_ONE clip control, depth func GREATER, clear 0");
  cmd->add_option("-o,--out", o->out, "Trace file to write")->required();
  cmd->footer("Per frame: occluders (last frame's visible objects), bounds tests of every other object in the\n"
              "view frustum, visible objects, depth after occluders and at the end, ground truth from an ID buffer.");
  cmd->callback([&action, o] {
    action = [o] {
      capture::CaptureOptions c;
      std::tie(c.width, c.height) = parse_size(o->size, "--size");
      c.frames = o->frames;
      c.path = o->path == "walk" ? capture::PathKind::Walk : capture::PathKind::Fly;
      c.seed = o->seed;
      c.objects = o->objects;
      c.mode = capture::parse_test_mode(o->mode);
      c.levels_every = o->levels_every;
      c.reversed_z = o->reversed_z;
      c.command_line = "nbsim capture city --size " + o->size + " --frames " + std::to_string(o->frames) + " --path " +
                       o->path + " --seed " + std::to_string(o->seed) + " --objects " + std::to_string(o->objects) +
                       " --mode " + o->mode + " --levels-every " + std::to_string(o->levels_every) +
                       (o->reversed_z ? " --reversed-z" : "") + " -o " + o->out;
      ProgressBar bar("capture", c.frames);
      const auto s = capture::capture_city(c, o->out, [&](int done, int) { bar.update(done); });
      bar.finish();
      fmt::print("captured {} frames at {} in {:.1f} s ({:.2f} frames/s, GL technique {:.1f} ms/frame): {} ({:.2f} MB, {:.0f} KB/frame)\n",
                 s.frames, o->size, s.seconds, s.frames / s.seconds, s.gl_ms / s.frames, o->out,
                 static_cast<double>(s.bytes) / 1e6, static_cast<double>(s.bytes) / 1e3 / s.frames);
      fmt::print("  {} draws; objects rendered {}, visible by ground truth {}, visible but not rendered {}\n", s.draws,
                 s.objects_rendered, s.objects_visible, s.visible_not_rendered);
      return s.visible_not_rendered == 0 ? 0 : 1;
    };
  });
}

}  // namespace nbsim::cli
