// `nbsim bench replay`: the simulator's own speed. Captures a walkthrough with llvmpipe (timing
// the GL technique passes) and replays the same trace through the SystemC model in the same run,
// so the ratio of the two compares like with like on this machine, now.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace nbsim::bench {

struct ReplayBenchOptions {
  std::string size = "512x512";
  int frames = 20;
  std::string mode = "oq";  // the capture's test mode (oq draws every candidate's box: the most raster work)
};

// One JSON object: frames, gl_ms (llvmpipe, technique passes), replay_ms, ratio replay/gl,
// depth tests and cycles per host second, and whether the comparison stayed within thresholds.
nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& options);

}  // namespace nbsim::bench
