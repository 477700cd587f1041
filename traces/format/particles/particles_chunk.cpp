// The particles technique's chunk description; see particles_chunk.h.
#include "traces/format/particles/particles_chunk.h"

#include <fmt/format.h>

#include <charconv>
#include <string>
#include <variant>

namespace nbsim::trace {

namespace {

// The rule of particles_chunk_spec(): what a reader refuses beyond the field types.
std::string particles_rule(const TechniqueRecord& r) {
  const std::uint64_t count = std::get<std::uint64_t>(r.fields.at(0).value);
  if (std::string problem = vector_lengths_problem(r, count, {"count"}, "particle"); !problem.empty()) return problem;
  for (const TechniqueField& f : r.fields) {
    if (f.name != "culled" && f.name != "lookups") continue;
    const auto& v = std::get<std::vector<std::uint32_t>>(f.value);
    const std::uint32_t limit = f.name == "culled" ? 1u : 4u;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i] > limit) return fmt::format("field '{}' of particle {} is {}, above {}", f.name, i, v[i], limit);
  }
  return {};
}

}  // namespace

ChunkSpec particles_chunk_spec() {
  ChunkSpec spec{kParticlesChunk,
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
  spec.rule = particles_rule;
  return spec;
}

namespace {

// A sprite side the vertex stage can size: 1 to 4096 pixels, or atten (distance-attenuated).
bool valid_sprite(std::string_view v) {
  if (v == "atten") return true;
  unsigned side = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), side);
  return ec == std::errc() && end == v.data() + v.size() && !v.starts_with('+') && side >= 1 && side <= 4096;
}

}  // namespace

std::vector<HeaderKeySpec> particles_header_keys() {
  const std::string t = "particles";
  return {choice_key(t, "particle_mode", {"none", "center", "nb", "hiz"}, "nb", "the vertex stage's culling test"),
          custom_key(t, "sprite", valid_sprite, "a side in pixels, 1 .. 4096, or atten (distance-attenuated, 1 to 64 pixels)", "16",
                     "the sprites' side"),
          whole_key(t, "particles", 0, 0xFFFFFFFFu, "10000", "particles a frame"),
          text_key(t, "emitters", "auto", "auto, or the emitters' ground positions X:Z,X:Z,... in metres"),
          whole_key(t, "level_cap", 0, 31, "5", "the highest N-buffer or Hi-Z level the capture may build"),
          whole_key(t, "levels_built", 0, 31, "5", "the levels the capture built (the vertex stage reads levels 0 .. levels_built - 1)"),
          real_key(t, "cull_margin", 0.0, 0.01, false, "1e-06", "depth margin of the vertex stage's test")};
}

// This technique's part of the format (technique_chunks.h): its chunk type and header keys.
TechniqueFormat particles_format() { return {{particles_chunk_spec()}, particles_header_keys()}; }

}  // namespace nbsim::trace
