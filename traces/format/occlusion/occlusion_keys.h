// The occlusion-culling technique's header keys. It records no chunk type of its own: its frames
// are the core records (FrameBegin's mode, the bounds tests, the levels). Registered with the
// other techniques' keys in technique_chunks.cpp; the capture side is traces/capture/occlusion/.
#pragma once

#include <vector>

#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

// test_mode: the queries the capture's GL ran (model/scene/frame.h's TestMode names).
std::vector<HeaderKeySpec> occlusion_culling_header_keys();

}  // namespace nbsim::trace
