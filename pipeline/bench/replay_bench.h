// `nbsim bench replay`: the simulator's own speed. Captures a walkthrough with llvmpipe (timing
// the GL technique passes) and replays the same trace through the SystemC model in the same run,
// so the ratio of the two compares like with like on this machine, now. Techniques: occlusion
// culling (the city walk), particles (scene, partial N-buffer or Hi-Z build, culled sprites) and
// shadows (observer depth, litmaps, min and max N-buffers, the mode's stencil shadow volumes) and
// layered depth images (viewpoint selection, the peel, crop, compression and the parity tests).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace nbsim::bench {

struct ReplayBenchOptions {
  std::string technique = "occlusion_culling";  // or "particles"
  std::string size = "512x512";
  int frames = 20;
  // The capture's test mode: occlusion_culling's (default oq, which draws every candidate's box: the
  // most raster work), particles' particle_mode (default nb) or shadows' shadow_mode (default
  // clamped). Empty: the technique's default.
  std::string mode;
  int particles = 10000;      // particles only: --particles of the capture
  std::string sprite = "16";  // particles only: 16, 24 or atten
  // The scene (city, or for shadows also terrain and boxes); empty: city. Shadows fly over it (the
  // terrain and the boxes have no streets to walk).
  std::string scene;
  // The ldi technique: the shape (model/mesh/shapes.h's table; empty: knot) and the LDI's side.
  std::string shape;
  int ldi_size = 256;
  // The relief technique: the heightfield kind (model/relief/heightfield.h; empty: fbm) and its side;
  // --size is the viewport, every method a box draw a frame, the frames cycling 0, 45, 80, 89 degrees.
  std::string field;
  int field_size = 128;
};

// The technique names the bench accepts (the capture's plug-in names).
inline constexpr const char* kReplayBenchTechniques[] = {"occlusion_culling", "particles", "shadows", "ldi", "relief"};

// One JSON object: technique, frames, gl_ms (llvmpipe, technique passes), replay_ms, ratio replay/gl,
// depth tests and cycles per host second, and whether the comparison stayed within thresholds;
// for particles also the particle count, sprite and the replay's particles summary; for shadows
// the scene and the replay's shadows summary when the replay has one; for ldi the shape, the LDI's
// side and the replay's ldi summary. Throws
// InputError for an unknown technique or mode, or options the capture refuses.
nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& options);

}  // namespace nbsim::bench
