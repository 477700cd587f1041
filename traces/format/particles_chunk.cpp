// The particles technique's chunk description; see particles_chunk.h.
#include "traces/format/particles_chunk.h"

namespace nbsim::trace {

ChunkSpec particles_chunk_spec() {
  return {kParticlesChunk,
          "particles",
          "ParticleCulling",
          {{"count", FieldKind::U32, "particles in the frame (every vector below has this many elements)"},
           {"draw", FieldKind::VecU32, "the frame's draw (role particles) that drew the particle"},
           {"x", FieldKind::VecF32, "sprite centre, window x, pixels (as the vertex shader computed it)"},
           {"y", FieldKind::VecF32, "sprite centre, window y, pixels, y up"},
           {"depth", FieldKind::VecF32, "window depth of the sprite (every fragment's), [0, 1]"},
           {"size", FieldKind::VecF32, "sprite side, pixels (gl_PointSize)"},
           {"culled", FieldKind::VecU32, "1: the vertex stage culled it (moved it outside the clip volume), 0: drawn"},
           {"lookups", FieldKind::VecU32,
            "depth texels the vertex-stage query read (0: not tested: mode none, off-screen, behind the eye, or larger "
            "than the levels built)"},
           {"reference_samples", FieldKind::VecU32,
            "samples that passed the depth test in the reference pass (every particle drawn, same depth test, early "
            "fragment tests, a counter per particle); culled with reference_samples > 0 is popping"}}};
}

}  // namespace nbsim::trace
