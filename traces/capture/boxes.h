// The N-buffer paper's "simpler scenes" (4.4): boxes of
// random size standing on a square plane (one open quad, a receiver only). Deterministic for a seed.
#pragma once

#include <cstdint>

#include "traces/capture/scenes.h"

namespace nbsim::capture {

struct BoxesParams {
  std::uint32_t seed = 1;
  int boxes = 30;
  double extent_m = 120.0;  // side of the plane (tunable)
};

// Object 0 is the plane, then the boxes.
CaptureScene make_boxes(const BoxesParams& params);

}  // namespace nbsim::capture
