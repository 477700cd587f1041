// The particles technique's chunk type (N-buffer paper, 3.2/4.3): per frame, one record of every
// particle with where it landed on screen, what the vertex stage decided and what the reference
// pass saw (ground truth for popping). Built into the format library (technique_chunks.cpp
// registers it with the other techniques' types), so every reader decodes it. The capture side is
// traces/capture/particles/.
#pragma once

#include <cstdint>

#include "traces/format/records.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

inline constexpr std::uint32_t kParticlesChunk = fourcc("PRTC");

// Its description: fields in this order (the vectors have `count` elements each, particle p's
// values at index p; particles are numbered across the frame's particle draws in draw order).
// Its rule: every vector has `count` elements, culled is 0 or 1, lookups at most 4.
ChunkSpec particles_chunk_spec();

// Its header keys (what the replay reads to run the vertex stage's test again).
std::vector<HeaderKeySpec> particles_header_keys();

}  // namespace nbsim::trace
