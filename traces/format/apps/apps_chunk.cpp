// The apps technique's chunk types; see apps_chunk.h.
#include "traces/format/apps/apps_chunk.h"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <variant>

namespace nbsim::trace {

namespace {

std::uint64_t whole(const TechniqueRecord& r, std::string_view name) { return std::get<std::uint64_t>(find_field(r, name)->value); }
const std::vector<std::uint32_t>& u32s(const TechniqueRecord& r, std::string_view name) {
  return std::get<std::vector<std::uint32_t>>(find_field(r, name)->value);
}
const std::vector<float>& f32s(const TechniqueRecord& r, std::string_view name) { return std::get<std::vector<float>>(find_field(r, name)->value); }

// The first NaN of any float vector, or empty.
std::string nan_problem(const TechniqueRecord& r, std::string_view one_a) {
  for (const TechniqueField& f : r.fields) {
    const auto* v = std::get_if<std::vector<float>>(&f.value);
    if (!v) continue;
    for (std::size_t i = 0; i < v->size(); ++i)
      if (std::isnan((*v)[i])) return fmt::format("field '{}' of {} {} is NaN", f.name, one_a, i);
  }
  return {};
}

std::string draws_rule(const TechniqueRecord& r) {
  if (std::string p = vector_lengths_problem(r, whole(r, "count"), {"count"}, "draw"); !p.empty()) return p;
  const auto& skipped = u32s(r, "skipped");
  const auto& call = u32s(r, "call");
  const auto& depth_float = u32s(r, "depth_float");
  for (std::size_t i = 0; i < skipped.size(); ++i) {
    if (skipped[i] > 6) return fmt::format("field 'skipped' of draw {} is {}, above 6", i, skipped[i]);
    if (call[i] > 17) return fmt::format("field 'call' of draw {} is {}, above 17", i, call[i]);
    if (depth_float[i] > 1) return fmt::format("field 'depth_float' of draw {} is {}, not 0 or 1", i, depth_float[i]);
  }
  return nan_problem(r, "draw");
}

std::string clears_rule(const TechniqueRecord& r) {
  if (std::string p = vector_lengths_problem(r, whole(r, "count"), {"count"}, "clear"); !p.empty()) return p;
  const auto& before = u32s(r, "before_draw");
  const auto& buffers = u32s(r, "buffers");
  const auto& depth = f32s(r, "depth");
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (buffers[i] < 1 || buffers[i] > 3) return fmt::format("field 'buffers' of clear {} is {}, not 1 to 3", i, buffers[i]);
    if (i > 0 && before[i] < before[i - 1]) return fmt::format("clear {} runs before draw {}, earlier than the clear before it", i, before[i]);
    if (!(depth[i] >= 0.0f && depth[i] <= 1.0f)) return fmt::format("field 'depth' of clear {} is {}, outside [0, 1]", i, depth[i]);
  }
  return {};
}

std::string depth_change_rule(const TechniqueRecord& r) {
  const auto& pixel = u32s(r, "pixel");
  const auto& depth = f32s(r, "depth");
  if (pixel.size() != depth.size()) return fmt::format("{} pixels but {} depths", pixel.size(), depth.size());
  const std::uint64_t w = whole(r, "width"), h = whole(r, "height");
  if (w < 1 || h < 1 || w > 16384 || h > 16384) return fmt::format("a {}x{} render target", w, h);
  for (std::size_t i = 0; i < pixel.size(); ++i) {
    if (pixel[i] >= w * h) return fmt::format("pixel {} is outside the {}x{} target", pixel[i], w, h);
    if (i > 0 && pixel[i] <= pixel[i - 1]) return fmt::format("pixel {} does not follow pixel {}", pixel[i], pixel[i - 1]);
  }
  return nan_problem(r, "pixel");
}

std::string frame_rule(const TechniqueRecord& r) {
  const std::uint64_t w = whole(r, "width"), h = whole(r, "height");
  if (w > 16384 || h > 16384) return fmt::format("a {}x{} render target", w, h);
  return {};
}

}  // namespace

ChunkSpec app_draws_chunk_spec() {
  ChunkSpec spec{kAppDrawsChunk,
                 "apps",
                 "AppDraws",
                 {{"count", FieldKind::U32, "draws in the frame (every vector below has this many elements)"},
                  {"mode", FieldKind::VecU32, "the GL primitive mode the draw was called with (GL_TRIANGLES, GL_TRIANGLE_STRIP, ...)"},
                  {"call", FieldKind::VecU32, "the draw entry point (traces/apitrace/raw.h DrawCall: 0 glDrawArrays, 1 glDrawElements, ...)"},
                  {"skipped", FieldKind::VecU32,
                   "why its positions were not captured (raw.h Skip): 0 captured, 1 fixed function, 2 no gl_Position, 3 the "
                   "program's own transform feedback, 4 the program's own query open, 5 a separable program, 6 an indirect draw"},
                  {"primitive", FieldKind::VecU32, "what transform feedback captured: GL_POINTS, GL_LINES or GL_TRIANGLES (0 when skipped)"},
                  {"flags", FieldKind::VecU32, "GL state bits (raw.h DrawFlag: depth test, depth mask, cull, scissor, discard, ...)"},
                  {"framebuffer", FieldKind::VecU32, "the draw framebuffer (0: the window's)"},
                  {"target_width", FieldKind::VecU32, "its size, pixels"},
                  {"target_height", FieldKind::VecU32, "its size, pixels"},
                  {"depth_bits", FieldKind::VecU32, "its depth buffer's bits (0: none)"},
                  {"depth_float", FieldKind::VecU32, "1: a float depth buffer"},
                  {"polygon_mode", FieldKind::VecU32, "GL_POLYGON_MODE (GL_FILL, GL_LINE, GL_POINT)"},
                  {"viewport_x", FieldKind::VecI32, "GL_VIEWPORT"},
                  {"viewport_y", FieldKind::VecI32, "GL_VIEWPORT"},
                  {"viewport_w", FieldKind::VecI32, "GL_VIEWPORT"},
                  {"viewport_h", FieldKind::VecI32, "GL_VIEWPORT"},
                  {"scissor_x", FieldKind::VecI32, "GL_SCISSOR_BOX (flags say whether the test is on)"},
                  {"scissor_y", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"scissor_w", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"scissor_h", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"depth_near", FieldKind::VecF32, "GL_DEPTH_RANGE near"},
                  {"depth_far", FieldKind::VecF32, "GL_DEPTH_RANGE far"},
                  {"offset_factor", FieldKind::VecF32, "GL_POLYGON_OFFSET_FACTOR"},
                  {"offset_units", FieldKind::VecF32, "GL_POLYGON_OFFSET_UNITS"}}};
  spec.rule = draws_rule;
  return spec;
}

ChunkSpec app_clears_chunk_spec() {
  ChunkSpec spec{kAppClearsChunk,
                 "apps",
                 "AppClears",
                 {{"count", FieldKind::U32, "clears of depth or stencil in the frame (every vector below has this many elements)"},
                  {"before_draw", FieldKind::VecU32, "the draw it runs before (the frame's draw count: after the last)"},
                  {"framebuffer", FieldKind::VecU32, "the draw framebuffer it clears"},
                  {"buffers", FieldKind::VecU32, "1 depth, 2 stencil, 3 both"},
                  {"flags", FieldKind::VecU32, "raw.h kScissor (the scissor test limits it) and kDepthMask (depth writes on)"},
                  {"stencil_write_mask", FieldKind::VecU32, "GL_STENCIL_WRITEMASK"},
                  {"scissor_x", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"scissor_y", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"scissor_w", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"scissor_h", FieldKind::VecI32, "GL_SCISSOR_BOX"},
                  {"stencil", FieldKind::VecI32, "the stencil value written"},
                  {"depth", FieldKind::VecF32, "the depth value written, [0, 1]"}}};
  spec.rule = clears_rule;
  return spec;
}

ChunkSpec app_depth_change_chunk_spec() {
  ChunkSpec spec{kAppDepthChangeChunk,
                 "apps",
                 "AppDepthChange",
                 {{"draw", FieldKind::U32, "the draw (its index in the frame)"},
                  {"framebuffer", FieldKind::U32, "its draw framebuffer"},
                  {"width", FieldKind::U32, "the target's width, pixels"},
                  {"height", FieldKind::U32, "the target's height, pixels"},
                  {"pixel", FieldKind::VecU32, "y * width + x of every pixel whose stored depth the draw changed, increasing"},
                  {"depth", FieldKind::VecF32, "its depth after the draw, as GL reads it back in float"}}};
  spec.rule = depth_change_rule;
  return spec;
}

ChunkSpec app_frame_chunk_spec() {
  ChunkSpec spec{kAppFrameChunk,
                 "apps",
                 "AppFrame",
                 {{"framebuffer", FieldKind::U32, "the render target of the frame's final depth image (the one its draws passed the most samples in)"},
                  {"width", FieldKind::U32, "its size, pixels"},
                  {"height", FieldKind::U32, "its size, pixels"},
                  {"unhandled", FieldKind::String, "GL features met and not captured, 'name x count' joined by '; ' (empty: none)"}}};
  spec.rule = frame_rule;
  return spec;
}

std::vector<HeaderKeySpec> apps_header_keys() {
  const std::string t = "apps";
  return {text_key(t, "apitrace", "glmark2-shadow.trace", "the apitrace trace the frames were recorded from (its file name)"),
          text_key(t, "app_frames", "10:29", "the trace's frames recorded, FIRST:LAST (swap buffers counted from 0)")};
}

TechniqueFormat apps_format() {
  return {{app_draws_chunk_spec(), app_clears_chunk_spec(), app_depth_change_chunk_spec(), app_frame_chunk_spec()}, apps_header_keys()};
}

}  // namespace nbsim::trace
