// The litmap passes (N-buffer paper 3.3) on the CPU, shared by the capture and the model. The
// capture takes its shaders' uniforms from here; the model runs the same arithmetic as their twin,
// so that it draws the min and max litmaps of a frame bit for bit as llvmpipe does, at the trace's
// litmap size or another one:
//  - the litmap draws: each scene object the observer and the light both see, from the light
//    (shaders/shadows/litmap.vert: clip_position() with the light's float view_proj), every
//    fragment reprojected into the observer's view from its gl_FragCoord and discarded when the
//    observer cannot see it (shaders/shadows/litmap.frag, LitmapReprojection below);
//  - the receiver splat: every observer pixel's surface point in the light's frustum as a one-pixel
//    point (shaders/shadows/splat.vert, ReceiverSplat below).
// Both shaders compute with `precise` scalar expressions in the order written here (every product
// and sum rounded, none fused; the model builds with -ffp-contract=off), so the float and double
// results are the same on both sides.
#pragma once

#include <glm/mat4x4.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "model/common/depth.h"
#include "model/geometry/geometry.h"
#include "model/raster/depth_test.h"
#include "model/raster/raster_path.h"
#include "model/scene/frame.h"
#include "model/shadows/caster.h"
#include "model/shadows/volume.h"

namespace nbsim::shadows {

// The light's view_proj as litmap.vert receives it: the frame's light camera (LGHT, float) as
// proj * view in float.
glm::mat4 light_view_proj(const scene::Camera& light);

// What the reprojection test reads besides the matrices: the observer's near and far planes
// (metres, the header's `near` and `far` rounded to float) and the reprojection tolerance (the
// header's reproject_tolerance: a fragment up to rel * distance + metres behind the farthest
// observer depth around its pixel still counts as seen).
struct ReprojectSettings {
  float near_m = 0.5f, far_m = 4000.0f;
  float tolerance_rel = 0.01f, tolerance_m = 0.05f;
};

// The litmap fragment shader's test. Observer clip c = rows * (x_w, y_w, z_w, 1) from the
// fragment's litmap window position (gl_FragCoord: pixel centre, depth); the rows are the
// observer's view_proj times the inverse of the light's float view_proj times the litmap's
// window-to-NDC map, computed in double and rounded to float once. A fragment is discarded when
// c.w <= 0, when c / c.w lies outside [-1, 1]^3, or when its observer view distance is farther than
// the farthest observer depth of the 3x3 pixels around it (window depth -> distance), plus the
// tolerance.
class LitmapReprojection final : public raster::FragmentShader {
 public:
  // `observer` (the frame's observer depth, window depth, y up) must outlive the test.
  LitmapReprojection(const glm::mat4& observer_view_proj, const glm::mat4& light_view_proj, int litmap_size,
                     const ReprojectSettings& settings, const DepthImage& observer);

  bool discards(int x, int y, float frag_z) const override;

  // The rows the shader receives as uniforms reproject_x .. reproject_w.
  const std::array<std::array<float, 4>, 4>& rows() const noexcept { return rows_; }

 private:
  std::array<std::array<float, 4>, 4> rows_{};
  ReprojectSettings settings_;
  const DepthImage* observer_;
  // Per observer pixel, made once: the view distance of the farthest depth of its 3x3 neighbourhood
  // (edges repeated) times (1 + tolerance_rel) plus tolerance_m; a fragment landing there is unseen
  // when its own view distance is larger (the same floats as computing it per fragment).
  std::vector<float> unseen_beyond_;
};

// The reprojection rows alone (the capture's uniforms).
std::array<std::array<float, 4>, 4> reprojection_rows(const glm::mat4& observer_view_proj, const glm::mat4& light_view_proj,
                                                       int litmap_size);

// The receiver splat's vertex shader. Light clip q = rows * (x + 0.5, y + 0.5, d, 1) in double from
// an observer pixel (x, y) and its window depth d, rows = the light's (double) proj * view times the
// inverse of the observer's float view_proj times the observer's window-to-NDC map. No point where
// d >= 1 (no surface) or q lies outside the light's frustum (q.w <= 0 or |q.xyz| > q.w); else q.xyz
// clamped to +-q.w (1 - 2^-20) so that rounding to float cannot clip it, then rounded to float.
class ReceiverSplat {
 public:
  ReceiverSplat(const glm::mat4& observer_view_proj, const glm::dmat4& light_clip, int width, int height);

  // The point of pixel (x, y) at window depth `d`, or nullopt.
  std::optional<geometry::ClipPosition> point(int x, int y, float d) const noexcept;
  // Every observer pixel's point, in gl_VertexID order (y * width + x), skipping the clipped ones.
  void points(const DepthImage& observer, std::vector<geometry::ClipPosition>& out) const;

  const std::array<std::array<double, 4>, 4>& rows() const noexcept { return rows_; }

 private:
  std::array<std::array<double, 4>, 4> rows_{};
};

// The meshes of the objects a frame's litmap draws may draw (SHDM, the trace's first frame): each
// object's triangles in the order GL draws them, its vertices numbered anew.
struct LitmapMeshes {
  std::vector<glm::vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  // object id -> (first triangle, triangle count); objects the record does not hold: count 0.
  std::vector<std::array<std::uint32_t, 2>> range;
  std::vector<bool> held;
};
inline constexpr std::uint32_t kLitmapMeshesRecordType = 0x4d444853u;  // fourcc "SHDM" (traces/format/shadows/shadows_chunk.h)
// Decodes and checks a frame's SHDM record, or nullopt when the frame has none; throws InputError
// for a damaged record.
std::optional<LitmapMeshes> read_litmap_meshes(const scene::Frame& f);

// What the model's litmap passes counted, per frame.
struct LitmapCounters {
  std::uint64_t draws = 0;          // litmap draws (both litmaps)
  std::uint64_t fragments = 0;      // their rasterized fragments (each reprojected)
  std::uint64_t discarded = 0;      // of those, discarded as unseen by the observer
  std::uint64_t splat_points = 0;   // receiver-splat points drawn (both litmaps)
  std::uint64_t splat_fragments = 0;
  std::uint64_t fragment_diff = 0;  // draws whose fragments differ from GL's counter (same size only)
};

// The observer depth as the litmap shaders' texelFetch reads it: the buffer's floats for a float
// buffer; for DEPTH24_STENCIL8, llvmpipe's unorm-to-float conversion of the stored 24-bit value q
// (lp_build_unsigned_norm_to_float, 24 bits: float(q) times 1 / (2^24 - 1) rounded to float), which
// is not always the float the model keeps for q (raster::from_unorm24).
DepthImage sampled_depth_image(const DepthImage& stored, raster::DepthFormat format);

// Threads drawing the model's litmaps (draw_litmaps): 2 (the min and the max litmap at once) when
// the host has two cores or more, else 1; the environment variable NBSIM_SHADOWS_THREADS=1 or 2
// sets it. Counts and images never depend on it.
int litmap_threads();

// Draws a frame's min and max litmaps of side `litmap_size` as the capture drew them: the frame's
// Litmap and ReceiverSplat draws in order (LEQUAL: the min litmap, cleared to 1; GEQUAL: the max
// litmap, cleared to 0), from `meshes`, the frame's light camera (LGHT for the litmap draws' float
// transform, `light` for the splat's double one) and the observer's depth as sampled (`sampled`).
// `path` gives the replay's raster settings (its size is replaced by the litmap's). Throws
// InputError when a litmap draw names an object the meshes do not hold.
struct LitmapImages {
  DepthImage min, max;
};
LitmapImages draw_litmaps(const scene::Frame& f, const LitmapMeshes& meshes, const LightFrustum& light, int litmap_size,
                          const ReprojectSettings& settings, const DepthImage& sampled, raster::RasterPathConfig path, bool compare_gl_counts, LitmapCounters& counters);

}  // namespace nbsim::shadows
