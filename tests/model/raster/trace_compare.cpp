// Counter comparison of the raster path against GL on a captured trace; see trace_compare.h.
#include "tests/model/raster/trace_compare.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "model/common/error.h"
#include "traces/format/reader.h"

namespace nbsim::raster_compare {

namespace {

static_assert(static_cast<int>(trace::DepthFunc::Always) == static_cast<int>(raster::DepthFunc::Always));
static_assert(static_cast<int>(trace::DepthFunc::Gequal) == static_cast<int>(raster::DepthFunc::Gequal));
static_assert(static_cast<int>(trace::CullFace::FrontAndBack) == static_cast<int>(geometry::CullFace::FrontAndBack));
static_assert(static_cast<int>(trace::ClipControl::ZeroToOne) == static_cast<int>(geometry::ClipControl::ZeroToOne));

void compare_depth(const DepthImage& model, const trace::DepthSnapshot& gl, double tolerance, CompareSummary& s) {
  if (gl.width != model.width || gl.height != model.height)
    throw InputError("trace: depth snapshot size does not match the viewport");
  s.depth_snapshots += 1;
  for (std::size_t i = 0; i < model.texels.size(); ++i) {
    const float a = model.texels[i], b = gl.texels[i];
    const double d = std::fabs(static_cast<double>(a) - static_cast<double>(b));
    s.depth_pixels += 1;
    if (d <= tolerance) s.depth_pixels_matching += 1;
    if (std::memcmp(&a, &b, sizeof a) == 0 || a == b) s.depth_pixels_identical += 1;
    s.depth_max_abs_error = std::max(s.depth_max_abs_error, d);
  }
}

}  // namespace

bool CompareSummary::within_thresholds() const {
  const auto rel = [](std::uint64_t a, std::uint64_t b) {
    return b == 0 ? (a == 0 ? 0.0 : 1.0)
                  : std::fabs(static_cast<double>(a) - static_cast<double>(b)) / static_cast<double>(b);
  };
  return draws > 0 && static_cast<double>(draws_exact) >= 0.99 * static_cast<double>(draws) &&
         rel(fragments_model, fragments_gl) <= 1e-4 && rel(passed_model, passed_gl) <= 1e-4 &&
         static_cast<double>(depth_pixels_matching) >= 0.9999 * static_cast<double>(depth_pixels) &&
         stencil_pixels_matching == stencil_pixels;
}

CompareSummary compare_trace(const std::filesystem::path& path, const CompareOptions& options) {
  trace::FrameReader frames(path);
  const trace::Header& head = frames.trace().header();
  if (!head.viewport) throw InputError("trace: no viewport property");
  const int width = head.viewport->width, height = head.viewport->height;
  const float clear = head.depth_clear;

  raster::RasterPathConfig config;
  config.width_px = width;
  config.height_px = height;
  config.batch_triangles = options.batch_triangles;
  config.fused_viewport = options.fused_viewport;
  config.fused_interpolation = options.fused_interpolation;
  for (const auto& [k, v] : frames.trace().properties())
    if (k == "depth_format")
      if (const auto f = raster::parse_depth_format(v)) config.depth_format = *f;
  DepthImage depth(width, height, clear);
  raster::StencilImage stencil(width, height, 0);
  raster::RasterPath path_core(config, depth, stencil);

  CompareSummary s;
  const std::uint64_t full_screen = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  while (auto f = frames.next()) {
    s.frames += 1;
    std::fill(depth.texels.begin(), depth.texels.end(), clear);
    std::fill(stencil.texels.begin(), stencil.texels.end(), std::uint8_t{0});  // glClearStencil(0)
    std::size_t occluders_end = 0;
    for (std::size_t i = 0; i < f->draws.size(); ++i)
      if (f->draws[i].role == trace::DrawRole::Occluder) occluders_end = i + 1;
    const trace::DepthSnapshot* after_occluders = f->depth(trace::DepthWhich::AfterOccluders);
    for (std::size_t i = 0; i <= f->draws.size(); ++i) {
      if (i == occluders_end && after_occluders) compare_depth(depth, *after_occluders, options.depth_tolerance, s);
      if (i == f->draws.size()) break;
      const trace::DrawRecord& d = f->draws[i];
      if (d.clip_positions.empty()) {
        if (d.role == trace::DrawRole::NBufferBuild) {
          s.fullscreen_draws += 1;
          if (d.gl.fragments == full_screen) s.fullscreen_exact += 1;
        } else {
          s.other_draws += 1;
        }
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      raster::DrawState state = draw_state(d.state);
      if (d.stencil.test) state.stencil = raster::stencil_state(d.stencil);
      const raster::DrawCounters k = d.topology == trace::Topology::Points
                                         ? path_core.draw_points(d.clip_positions, d.point_sizes, state)
                                         : path_core.draw(d.clip_positions, state);
      s.model_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      s.totals += k;
      s.draws += 1;
      const bool frag_ok = k.depth.fragments == d.gl.fragments;
      const bool pass_ok = k.depth.passed == d.gl.samples_passed;
      const bool clip_ok = k.geometry.prims_in == d.gl.clip_prims_in && k.geometry.prims_out == d.gl.clip_prims_out;
      s.draws_fragments_exact += frag_ok ? 1 : 0;
      s.draws_passed_exact += pass_ok ? 1 : 0;
      s.draws_exact += frag_ok && pass_ok ? 1 : 0;
      s.draws_clip_exact += clip_ok ? 1 : 0;
      s.fragments_model += k.depth.fragments;
      s.fragments_gl += d.gl.fragments;
      s.passed_model += k.depth.passed;
      s.passed_gl += d.gl.samples_passed;
      s.clip_in_model += k.geometry.prims_in;
      s.clip_in_gl += d.gl.clip_prims_in;
      s.clip_out_model += k.geometry.prims_out;
      s.clip_out_gl += d.gl.clip_prims_out;
      if ((!frag_ok || !pass_ok || !clip_ok) && static_cast<int>(s.mismatches.size()) < options.max_mismatches) {
        DrawMismatch m;
        m.frame = f->begin.frame;
        m.draw = d.index;
        m.role = d.role;
        m.object = d.object;
        m.triangles = d.clip_positions.size() / 3;
        m.gl_fragments = d.gl.fragments;
        m.model_fragments = k.depth.fragments;
        m.gl_passed = d.gl.samples_passed;
        m.model_passed = k.depth.passed;
        m.gl_clip_out = d.gl.clip_prims_out;
        m.model_clip_out = k.geometry.prims_out;
        s.mismatches.push_back(m);
      }
    }
    if (const trace::DepthSnapshot* fin = f->depth(trace::DepthWhich::Final))
      compare_depth(depth, *fin, options.depth_tolerance, s);
    if (const trace::StencilSnapshot* gl = f->stencil("stencil"); gl && gl->texels.size() == stencil.texels.size()) {
      s.stencil_pixels += gl->texels.size();
      for (std::size_t i = 0; i < gl->texels.size(); ++i) s.stencil_pixels_matching += gl->texels[i] == stencil.texels[i] ? 1 : 0;
    }
  }
  return s;
}

std::string to_json(const CompareSummary& s) {
  std::ostringstream o;
  o.precision(9);
  const raster::DrawCounters& t = s.totals;
  o << "{\"frames\":" << s.frames << ",\"draws\":" << s.draws << ",\"draws_exact\":" << s.draws_exact
    << ",\"draws_fragments_exact\":" << s.draws_fragments_exact << ",\"draws_passed_exact\":" << s.draws_passed_exact
    << ",\"draws_clip_exact\":" << s.draws_clip_exact << ",\"fullscreen_draws\":" << s.fullscreen_draws
    << ",\"fullscreen_exact\":" << s.fullscreen_exact << ",\"other_draws\":" << s.other_draws
    << ",\"fragments_model\":" << s.fragments_model << ",\"fragments_gl\":" << s.fragments_gl
    << ",\"passed_model\":" << s.passed_model << ",\"passed_gl\":" << s.passed_gl
    << ",\"clip_in_model\":" << s.clip_in_model << ",\"clip_in_gl\":" << s.clip_in_gl
    << ",\"clip_out_model\":" << s.clip_out_model << ",\"clip_out_gl\":" << s.clip_out_gl
    << ",\"depth_snapshots\":" << s.depth_snapshots << ",\"depth_pixels\":" << s.depth_pixels
    << ",\"depth_pixels_matching\":" << s.depth_pixels_matching
    << ",\"depth_pixels_identical\":" << s.depth_pixels_identical
    << ",\"depth_max_abs_error\":" << s.depth_max_abs_error << ",\"stencil_pixels\":" << s.stencil_pixels
    << ",\"stencil_pixels_matching\":" << s.stencil_pixels_matching
    << ",\"within_thresholds\":" << (s.within_thresholds() ? "true" : "false")
    << ",\"model_seconds\":" << s.model_seconds << ",\"model_fragments_per_second\":"
    << (s.model_seconds > 0 ? static_cast<double>(t.depth.fragments) / s.model_seconds : 0.0)
    << ",\"triangles_in\":" << t.geometry.prims_in << ",\"trivially_rejected\":" << t.geometry.trivially_rejected
    << ",\"clipped\":" << t.geometry.clipped << ",\"draw_culled\":" << t.geometry.draw_culled
    << ",\"setup_zero_area\":" << t.setup.zero_area << ",\"setup_culled\":" << t.setup.culled
    << ",\"setup_offscreen\":" << t.setup.offscreen << ",\"setup_accepted\":" << t.setup.accepted
    << ",\"tiles_empty\":" << t.tiles.tiles_empty << ",\"tiles_partial\":" << t.tiles.tiles_partial
    << ",\"tiles_full\":" << t.tiles.tiles_full << ",\"blocks16_empty\":" << t.tiles.blocks16_empty
    << ",\"blocks16_partial\":" << t.tiles.blocks16_partial << ",\"blocks16_full\":" << t.tiles.blocks16_full
    << ",\"blocks4_empty\":" << t.tiles.blocks4_empty << ",\"blocks4_partial\":" << t.tiles.blocks4_partial
    << ",\"blocks4_full\":" << t.tiles.blocks4_full << ",\"tri_stamp4\":" << t.tiles.tri_stamp4
    << ",\"tri_block16\":" << t.tiles.tri_block16 << ",\"tri_tile\":" << t.tiles.tri_tile
    << ",\"tri_binned\":" << t.tiles.tri_binned << ",\"depth_tests\":" << t.depth.depth_tests << "}";
  return o.str();
}

}  // namespace nbsim::raster_compare
