// The occlusion-culling technique's header keys; see occlusion_keys.h.
#include "traces/format/occlusion/occlusion_keys.h"

#include <string>

#include "model/scene/frame.h"

namespace nbsim::trace {

std::vector<HeaderKeySpec> occlusion_culling_header_keys() {
  return {choice_key("occlusion_culling", "test_mode", std::vector<std::string>(scene::kTestModeNames.begin(), scene::kTestModeNames.end()),
                     "nb_hier", "the test mode the capture's GL ran")};
}

// This technique's part of the format (technique_chunks.h): its header keys; no chunk types of its
// own (its draws and queries are core records).
TechniqueFormat occlusion_format() { return {{}, occlusion_culling_header_keys()}; }

}  // namespace nbsim::trace
