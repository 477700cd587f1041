// The apps technique's chunk types: a real OpenGL program's frames, recorded from an apitrace trace
// by the interposer (traces/apitrace/interposer.cpp) and turned into a trace by `nbsim capture
// apitrace` (traces/capture/apps/). The frame's draws (role app_draw) carry what the core DRAW
// record holds (clip positions of triangles, depth, cull and stencil state, GL's samples passed,
// the discard and fragment-depth flags); these records add the GL state a real program sets and
// the core record has no field for, the clears between the draws, and the depth a draw changed when
// a model cannot be expected to redo it. Built into the format library (technique_chunks.cpp
// registers it).
#pragma once

#include <cstdint>

#include "traces/format/records.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

inline constexpr std::uint32_t kAppDrawsChunk = fourcc("APDS");
inline constexpr std::uint32_t kAppClearsChunk = fourcc("APCL");
inline constexpr std::uint32_t kAppDepthChangeChunk = fourcc("APDC");
inline constexpr std::uint32_t kAppFrameChunk = fourcc("APFR");

// AppDraws (one per frame): count U32 (the frame's draws; every vector has this many), then per
// draw: mode (the GL primitive mode it was called with), call (traces/apitrace/raw.h DrawCall),
// skipped (raw.h Skip: why its positions were not captured, 0 when they were), primitive (what
// transform feedback captured: GL_POINTS, GL_LINES or GL_TRIANGLES), flags (raw.h DrawFlag bits),
// framebuffer, target_width, target_height, depth_bits, depth_float (0 or 1), polygon_mode (VecU32);
// viewport_x, viewport_y, viewport_w, viewport_h, scissor_x, scissor_y, scissor_w, scissor_h
// (VecI32); depth_near, depth_far, offset_factor, offset_units (VecF32). Rule: vector lengths,
// skipped and call in range, depth_float 0 or 1, no NaN.
ChunkSpec app_draws_chunk_spec();

// AppClears (one per frame): count U32, then per clear: before_draw (it runs before that draw; the
// frame's draw count when after the last), framebuffer, buffers (1 depth, 2 stencil), flags (raw.h
// kScissor, kDepthMask), stencil_write_mask (VecU32); scissor_x, scissor_y, scissor_w, scissor_h,
// stencil (VecI32); depth (VecF32). Rule: vector lengths, buffers 1 to 3, before_draw not
// decreasing, depth in [0, 1].
ChunkSpec app_clears_chunk_spec();

// AppDepthChange (one per draw that has one): draw U32, framebuffer U32, width U32, height U32,
// pixel VecU32 (y * width + x, strictly increasing), depth VecF32 (the stored depth after the draw,
// as GL reads it back as float). Rule: equal lengths, pixels inside and increasing, no NaN.
ChunkSpec app_depth_change_chunk_spec();

// AppFrame (one per frame): framebuffer U32 (the render target whose depth the frame's "final"
// depth image holds: the one its draws passed the most samples in), width U32, height U32,
// unhandled String (GL features the interposer met and did not capture, "name x count" joined by
// "; ", empty when none).
ChunkSpec app_frame_chunk_spec();

std::vector<HeaderKeySpec> apps_header_keys();

}  // namespace nbsim::trace
