// Geometry stage: clipping, perspective divide, viewport transform and the draw module's face
// cull, ahead of triangle setup. See geometry.h for what is matched in Mesa and why.
//
// The float expressions below are written in the order Mesa evaluates them and must stay
// separately rounded (no contraction into FMA, see the pragma below); the one place Mesa fuses
// (the viewport of shaded vertices) calls std::fma explicitly.
#include "model/geometry/geometry.h"

// Keep the compiler from fusing a * b + c into one FMA even when a build targets FMA hardware
// (-march): Mesa's C and JIT code round these products separately.
// GCC: -ffp-contract=off on every target (cmake/NbsimWarnings.cmake), not a `#pragma GCC optimize`,
// which would keep GCC from inlining std::min, std::max and friends into this file's functions.
#if defined(__clang__)
#pragma clang fp contract(off)
#endif

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "model/common/error.h"

namespace nbsim::geometry {

namespace {

constexpr int kMaxViewportPx = 16384;
constexpr int kMaxBatchTriangles = 1 << 20;

// The frustum planes as Mesa's draw module stores them (draw_context.c draw_init), in outcode-bit
// order; plane 4 becomes (0, 0, 1, 0) for ZERO_TO_ONE. A point is inside when dot(p, plane) >= 0.
constexpr std::array<std::array<float, 4>, 6> kPlanes = {{
    {-1.0f, 0.0f, 0.0f, 1.0f},
    {1.0f, 0.0f, 0.0f, 1.0f},
    {0.0f, -1.0f, 0.0f, 1.0f},
    {0.0f, 1.0f, 0.0f, 1.0f},
    {0.0f, 0.0f, 1.0f, 1.0f},
    {0.0f, 0.0f, -1.0f, 1.0f},
}};
constexpr std::array<float, 4> kNearPlaneZeroToOne = {0.0f, 0.0f, 1.0f, 0.0f};

// Polygons grow by at most one vertex per plane (Mesa: MAX_CLIPPED_VERTICES for 6 planes).
constexpr int kMaxPolygon = 2 * 6 + 1;
constexpr int kMaxPool = 3 + kMaxPolygon + 1;

struct PolyVertex {
  ClipPosition clip{};
  WindowVertex win;
};

float plane_distance(const ClipPosition& p, const std::array<float, 4>& plane) {
  // dot4 in Mesa's order: ((p0*q0 + p1*q1) + p2*q2) + p3*q3.
  float d = p[0] * plane[0] + p[1] * plane[1];
  d = d + p[2] * plane[2];
  d = d + p[3] * plane[3];
  return d;
}

bool inf_or_nan(float v) { return !std::isfinite(v); }

}  // namespace

GeometryCounters& GeometryCounters::operator+=(const GeometryCounters& o) {
  prims_in += o.prims_in;
  trivially_rejected += o.trivially_rejected;
  clipped += o.clipped;
  clipped_away += o.clipped_away;
  draw_culled += o.draw_culled;
  prims_out += o.prims_out;
  batches += o.batches;
  pipeline_batches += o.pipeline_batches;
  return *this;
}

GeometryStage::GeometryStage(const GeometryConfig& config) : config_(config) {
  if (config.width_px < 1 || config.width_px > kMaxViewportPx || config.height_px < 1 ||
      config.height_px > kMaxViewportPx)
    throw InputError("geometry: viewport " + std::to_string(config.width_px) + "x" + std::to_string(config.height_px) +
                     " is outside 1x1 .. 16384x16384");
  if (config.batch_triangles < 1 || config.batch_triangles > kMaxBatchTriangles)
    throw InputError("geometry: batch_triangles " + std::to_string(config.batch_triangles) +
                     " is outside 1 .. 1048576");
  // Mesa's _mesa_get_viewport_xform for glViewport(0, 0, w, h) and glDepthRange(0, 1), in float.
  const float half_w = static_cast<float>(config.width_px) * 0.5f;
  const float half_h = static_cast<float>(config.height_px) * 0.5f;
  for (int c = 0; c < 2; ++c) {
    Viewport& v = viewports_[static_cast<std::size_t>(c)];
    v.scale = {half_w, config.flip_y ? -half_h : half_h, c == 0 ? 0.5f : 1.0f};
    v.translate = {half_w, half_h, c == 0 ? 0.5f : 0.0f};
  }
}

WindowVertex GeometryStage::to_window(const ClipPosition& p, ClipControl clip) const noexcept {
  const Viewport& vp = viewport(clip);
  const float inv_w = 1.0f / p[3];
  WindowVertex v;
  float* out[3] = {&v.x, &v.y, &v.z};
  for (std::size_t i = 0; i < 3; ++i) {
    const float projected = p[i] * inv_w;
    *out[i] = config_.fused_viewport ? std::fma(projected, vp.scale[i], vp.translate[i])
                                     : projected * vp.scale[i] + vp.translate[i];
  }
  v.inv_w = inv_w;
  return v;
}

unsigned GeometryStage::outcode(const ClipPosition& p, ClipControl clip, bool depth_clamp) noexcept {
  // draw_llvm.c generate_clipmask; comparisons are ordered, so NaN sets no bit.
  const float x = p[0], y = p[1], z = p[2], w = p[3];
  unsigned m = 0;
  if (x > w) m |= 1u << 0;
  if (0.0f > x + w) m |= 1u << 1;
  if (y > w) m |= 1u << 2;
  if (0.0f > y + w) m |= 1u << 3;
  if (!depth_clamp) {
    if (clip == ClipControl::ZeroToOne ? 0.0f > z : 0.0f > z + w) m |= 1u << 4;
    if (z > w) m |= 1u << 5;
  }
  return m;
}

bool draw_module_culls(const WindowTriangle& t, const FaceState& face) noexcept {
  if (face.cull == CullFace::None) return false;
  // draw_pipe_cull.c cull_tri: e = v0 - v2, f = v1 - v2, det = ex * fy - ey * fx.
  const float ex = t.v[0].x - t.v[2].x;
  const float ey = t.v[0].y - t.v[2].y;
  const float fx = t.v[1].x - t.v[2].x;
  const float fy = t.v[1].y - t.v[2].y;
  const float det = ex * fy - ey * fx;
  if (det == 0.0f) return true;  // zero determinant: dropped (see geometry.h)
  // Gallium's front_ccw is GL's inverted for a y-up render target (st_atom_rasterizer.c), and its
  // "ccw" is det < 0 (so a NaN determinant counts as clockwise, as in Mesa).
  const bool ccw = det < 0.0f;
  const bool front = ccw == !face.front_ccw;
  const unsigned bit = front ? 2u : 1u;  // CullFace bits: Back = 1, Front = 2
  return (static_cast<unsigned>(face.cull) & bit) != 0;
}

void GeometryStage::process(std::span<const ClipPosition> clip_positions, const GeometryState& state,
                            std::vector<WindowTriangle>& out, GeometryCounters& counters) const {
  const std::size_t triangles = clip_positions.size() / 3;
  const std::size_t batch = static_cast<std::size_t>(config_.batch_triangles);
  for (std::size_t first = 0; first < triangles; first += batch) {
    const std::size_t n = std::min(batch, triangles - first);
    emit_batch(clip_positions.subspan(first * 3, n * 3), state, out, counters);
  }
}

void GeometryStage::emit_batch(std::span<const ClipPosition> batch, const GeometryState& state,
                               std::vector<WindowTriangle>& out, GeometryCounters& counters) const {
  const std::size_t triangles = batch.size() / 3;
  counters.batches += 1;
  counters.prims_in += triangles;

  // Shade the batch: outcodes and window positions of every vertex.
  bool pipeline = false;
  for (const ClipPosition& p : batch) pipeline = pipeline || outcode(p, state.clip, state.depth_clamp) != 0;
  if (pipeline) counters.pipeline_batches += 1;

  std::array<float, 4> near_plane = kPlanes[4];
  if (state.clip == ClipControl::ZeroToOne) near_plane = kNearPlaneZeroToOne;
  const Viewport& vp = viewport(state.clip);

  // With both faces culled llvmpipe's setup is a no-op that does not even count the triangle.
  const bool cull_all = state.face.cull == CullFace::FrontAndBack;
  auto emit = [&](const WindowTriangle& t) {
    if (cull_all || (pipeline && draw_module_culls(t, state.face))) {
      counters.draw_culled += 1;
      return;
    }
    counters.prims_out += 1;
    out.push_back(t);
  };

  for (std::size_t t = 0; t < triangles; ++t) {
    const ClipPosition* tri = &batch[t * 3];
    const unsigned m0 = outcode(tri[0], state.clip, state.depth_clamp);
    const unsigned m1 = outcode(tri[1], state.clip, state.depth_clamp);
    const unsigned m2 = outcode(tri[2], state.clip, state.depth_clamp);
    if ((m0 | m1 | m2) == 0) {
      emit(WindowTriangle{
          {to_window(tri[0], state.clip), to_window(tri[1], state.clip), to_window(tri[2], state.clip)}});
      continue;
    }
    if ((m0 & m1 & m2) != 0) {
      counters.trivially_rejected += 1;
      continue;
    }

    // draw_pipe_clip.c do_clip_tri.
    counters.clipped += 1;
    std::array<PolyVertex, kMaxPool> pool;
    int pool_used = 0;
    std::array<int, kMaxPolygon + 1> list_a{}, list_b{};
    int* in = list_a.data();
    int* outl = list_b.data();
    for (int k = 0; k < 3; ++k) {
      pool[static_cast<std::size_t>(k)] = {tri[k], to_window(tri[k], state.clip)};
      in[k] = k;
    }
    pool_used = 3;
    int n = 3;
    unsigned clipmask = m0 | m1 | m2;
    bool discarded = false;
    while (clipmask != 0 && n >= 3) {
      const int plane_idx = std::countr_zero(clipmask);
      clipmask &= ~(1u << plane_idx);
      const std::array<float, 4>& plane = plane_idx == 4 ? near_plane : kPlanes[static_cast<std::size_t>(plane_idx)];

      int prev = in[0];
      float dp_prev = plane_distance(pool[static_cast<std::size_t>(prev)].clip, plane);
      if (inf_or_nan(dp_prev)) {
        discarded = true;
        break;
      }
      in[n] = in[0];
      int outcount = 0;
      for (int i = 1; i <= n; ++i) {
        const int cur = in[i];
        const float dp = plane_distance(pool[static_cast<std::size_t>(cur)].clip, plane);
        if (inf_or_nan(dp)) {
          discarded = true;
          break;
        }
        bool different_sign;
        if (dp_prev >= 0.0f) {
          if (outcount >= kMaxPolygon) {
            discarded = true;
            break;
          }
          outl[outcount++] = prev;
          different_sign = dp < 0.0f;
        } else {
          different_sign = !(dp < 0.0f);
        }
        if (different_sign) {
          if (pool_used >= kMaxPool || outcount >= kMaxPolygon) {
            discarded = true;
            break;
          }
          // interp(dst, t, out, in): dst = out + t * (in - out), then divide and viewport in
          // plain float: pos * (1/w) * scale + translate.
          const float denom = dp - dp_prev;
          int from, to;  // dst = from + t * (to - from)
          float t_param;
          if (dp < 0.0f) {  // going out
            if (-dp < dp_prev) {
              t_param = dp / denom;
              from = cur;
              to = prev;
            } else {
              t_param = -dp_prev / denom;
              from = prev;
              to = cur;
            }
          } else {  // coming back in
            if (-dp_prev < dp) {
              t_param = -dp_prev / denom;
              from = prev;
              to = cur;
            } else {
              t_param = dp / denom;
              from = cur;
              to = prev;
            }
          }
          PolyVertex& nv = pool[static_cast<std::size_t>(pool_used)];
          const ClipPosition& a = pool[static_cast<std::size_t>(from)].clip;
          const ClipPosition& b = pool[static_cast<std::size_t>(to)].clip;
          for (std::size_t c = 0; c < 4; ++c) nv.clip[c] = a[c] + t_param * (b[c] - a[c]);
          const float oow = 1.0f / nv.clip[3];
          nv.win.x = nv.clip[0] * oow * vp.scale[0] + vp.translate[0];
          nv.win.y = nv.clip[1] * oow * vp.scale[1] + vp.translate[1];
          nv.win.z = nv.clip[2] * oow * vp.scale[2] + vp.translate[2];
          nv.win.inv_w = oow;
          outl[outcount++] = pool_used++;
        }
        prev = cur;
        dp_prev = dp;
      }
      if (discarded) break;
      std::swap(in, outl);
      n = outcount;
    }
    if (discarded || n < 3) {
      counters.clipped_away += 1;
      continue;
    }
    // emit_poly with the last-vertex provoking convention (GL's default).
    for (int i = 2; i < n; ++i)
      emit(WindowTriangle{{pool[static_cast<std::size_t>(in[i - 1])].win, pool[static_cast<std::size_t>(in[i])].win,
                           pool[static_cast<std::size_t>(in[0])].win}});
  }
}

void GeometryStage::process_points(std::span<const ClipPosition> clip_positions, std::span<const float> point_sizes,
                                   const GeometryState& state, std::vector<WindowPoint>& out,
                                   GeometryCounters& counters) const {
  if (point_sizes.size() != clip_positions.size())
    throw InputError("geometry: a point draw has " + std::to_string(clip_positions.size()) + " vertices but " +
                     std::to_string(point_sizes.size()) + " point sizes (one per vertex expected)");
  for (std::size_t i = 0; i < clip_positions.size(); ++i) {
    const ClipPosition& p = clip_positions[i];
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && std::isfinite(p[3])))
      throw InputError("geometry: point " + std::to_string(i) + " of a point draw has a NaN or infinite clip position");
    if (!std::isfinite(point_sizes[i]))
      throw InputError("geometry: point " + std::to_string(i) + " of a point draw has a NaN or infinite point size");
  }
  // Batches as for triangles: the same vertex budget (3 * batch_triangles vertices); only the
  // batch counters depend on it, every point is clipped on its own.
  const std::size_t batch = 3 * static_cast<std::size_t>(config_.batch_triangles);
  for (std::size_t first = 0; first < clip_positions.size(); first += batch) {
    const std::size_t n = std::min(batch, clip_positions.size() - first);
    counters.batches += 1;
    counters.prims_in += n;
    bool pipeline = false;
    for (std::size_t i = first; i < first + n; ++i) {
      const ClipPosition& p = clip_positions[i];
      if (outcode(p, state.clip, state.depth_clamp) != 0) {  // draw_pipe_clip.c clip_point
        pipeline = true;
        counters.trivially_rejected += 1;
        continue;
      }
      counters.prims_out += 1;
      out.push_back(WindowPoint{to_window(p, state.clip), point_sizes[i]});
    }
    if (pipeline) counters.pipeline_batches += 1;
  }
}

}  // namespace nbsim::geometry
