// Particles (N-buffer paper 3.2/4.3), the model side's plain core (no SystemC): a point sprite's
// pixel rectangle and the vertex-stage tests of the capture's shader (shaders/particles/particles.vert),
// recomputed from the particle's window position, size and depth as the PRTC record holds them,
// with the same float operations, so that the model's decisions can be compared with GL's one by
// one. The unit (unit.h) times them and counts; the depth convention is model/common/depth.h's.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "model/common/rect.h"
#include "model/hiz/pyramid.h"
#include "model/scene/frame.h"

namespace nbsim::particles {

// The vertex-stage test (the trace's "particle_mode"). Fixed values.
enum class Mode : std::uint8_t { None = 0, Center = 1, NBuffer = 2, HiZ = 3 };
inline constexpr std::array<std::string_view, 4> kModeNames = {"none", "center", "nb", "hiz"};
std::optional<Mode> parse_mode(std::string_view s);
std::string_view to_string(Mode m) noexcept;

// The shader's tie widening: a rectangle corner within 1/64 px of a pixel centre may start one
// pixel lower after the rasterizer's snap (fixed by the capture's shader).
inline constexpr float kTiePx = 1.0f / 64.0f;

struct Particle {
  float x = 0, y = 0;     // window position of the centre, pixels, y up
  float depth = 0;        // window depth
  float size = 0;         // sprite side, pixels
};

// The pixels whose centres the sprite may cover, as the shader computes them.
struct SpriteRect {
  int lo_x = 0, lo_y = 0, hi_x = 0, hi_y = 0;  // unclipped, exclusive hi (one wider at a tie)
  Rect clipped;                                 // clipped to the viewport
  bool on_screen = false;                       // depth inside [0, 1] and a non-empty clipped rectangle
  int side() const noexcept { return std::max(hi_x - lo_x, hi_y - lo_y); }  // longer unclipped side
};
SpriteRect sprite_rect(const Particle& p, int width_px, int height_px);

// HIDDEN(d, f) of the shader: the sprite at d is behind the farthest depth f by more than `margin`.
inline bool hidden_behind(float d, float f, float margin, FarOp op) noexcept {
  return op == FarOp::Max ? (d - margin) > f : (d + margin) < f;
}
// The depth a structure query is given as the rectangle's nearest (d moved toward the eye by the margin).
inline float query_nearest(float d, float margin, FarOp op) noexcept { return op == FarOp::Max ? d - margin : d + margin; }

int floor_log2(int v) noexcept;  // v >= 1

// The largest distance-attenuated sprite side (--sprite atten: 1 to 64 px), fixed by the capture.
inline constexpr float kMaxAttenuatedPx = 64.0f;
// The highest level mode m builds for sprites of at most `largest_side_px` pixels (one more near a
// pixel-centre tie: the shader's rectangle), capped at level_cap: nb floor_log2(side + 1) (one
// lookup per power of two), hiz ceil_log2(side) (a 2x2 texel footprint); -1 for none and center,
// which build nothing. The capture builds exactly these levels, and a replay in another mode than
// the capture's (particles.mode) builds them from the trace's sprite and level_cap properties.
int top_level_needed(Mode m, int largest_side_px, int level_cap) noexcept;

// One particle's test, as decided by the model.
struct Decision {
  bool culled = false;
  bool tested = false;        // a query was made (lookups > 0)
  bool too_large = false;     // on screen, but its rectangle needs a level above the ones built: kept
  std::uint32_t lookups = 0;  // distinct texels read (the query's depth tests)
};

// mode center: one lookup of the depth buffer at the centre pixel.
Decision center_test(const Particle& p, const SpriteRect& r, const DepthImage& depth, float margin, FarOp op);
// mode nb: whether the sprite is tested (not too large for levels 0..top_level); the query itself
// goes to the N-buffer structure with r.clipped and query_nearest().
bool nb_testable(const SpriteRect& r, int top_level) noexcept;
// mode hiz: the lowest level k <= top_level where the clipped rectangle spans at most 2x2 texels of
// the pyramid, up to four texels read; kept (too_large) when there is none.
Decision hiz_test(const Particle& p, const SpriteRect& r, const HiZPyramid& pyramid, int top_level, float margin, FarOp op);
// Texels a partial Hi-Z build writes: levels 0..top_level of ceil(W / 2^k) x ceil(H / 2^k).
std::uint64_t hiz_build_texels(int width_px, int height_px, int top_level) noexcept;

// The pixels GL's rasterizer covers for the sprite at the record's window position (llvmpipe's
// point square, model/raster/point_setup.h: snapped corner, left/bottom fill rule), clipped to the
// viewport; empty when GL draws nothing (the centre outside the viewport or the depth range: the
// geometry stage clips points by their centre). Computed from the shader's window position, which
// may differ from the geometry stage's by a rounding step.
Rect drawn_rect(const Particle& p, int width_px, int height_px) noexcept;

// The exact sprite test: some pixel of `r` (drawn_rect) passes the depth test against the depth
// buffer (LESS under Max, GREATER under Min) at the sprite's depth. A sprite culled while this
// holds is a false cull.
bool sprite_passes(const Rect& r, float d, const DepthImage& depth, FarOp op) noexcept;

// A frame's particles, read from its PRTC record ("ParticleCulling") and checked against the
// frame's particle draws: the count equals the points of the draws with role Particles, and every
// particle names the draw that drew it, in draw order. Throws InputError naming the frame and the
// field otherwise (a damaged trace).
struct FrameParticles {
  std::vector<Particle> particles;
  std::vector<std::uint32_t> draw, culled, lookups, reference_samples;
};
inline constexpr std::uint32_t kParticlesRecordType = 0x43545250u;  // fourcc "PRTC" (traces/format/particles/particles_chunk.h)
FrameParticles read_particles(const scene::Frame& f);

}  // namespace nbsim::particles
