// The interposer's recording (traces/apitrace/interposer.cpp): what the library loaded into
// eglretrace writes while an apitrace trace replays, and what `nbsim capture apitrace` reads back
// and turns into an nbsim trace (traces/capture/apps/convert.h). One layout, used by both sides: plain
// little-endian records, each a RecordHead then its payload, in call order.
//
//   file   := FileHead record* End
//   record := Draw | Clear | Frame | Unhandled | Note
//
// The library writes nothing it did not observe: a draw's state is what glGet* returned right
// before the draw, its positions what transform feedback wrote during it, its samples what
// GL_SAMPLES_PASSED counted for it. A draw it could not capture (fixed function, the program's own
// transform feedback, an occlusion query of the program's own open) is still recorded, with the
// reason in `skipped` and no positions.
#pragma once

#include <cstdint>

#include "model/apps/draw_flags.h"

namespace nbsim::apitrace {

using namespace nbsim::apps::flags;  // Skip, DrawFlag, ClearBuffer: model/apps/draw_flags.h

inline constexpr char kRawMagic[8] = {'N', 'B', 'S', 'I', 'M', 'I', 'P', '1'};
inline constexpr std::uint32_t kRawVersion = 1;

// A frame's end marked by a program that has no window to swap (e.g. `nbsim capture apps
// --as-program`, drawing into FBOs on a surfaceless context): glDebugMessageInsert with
// GL_DEBUG_TYPE_MARKER and this text, which the library takes as a swap.
inline constexpr char kFrameMarker[] = "nbsim: frame end";

enum class RawType : std::uint32_t {
  Draw = 1,       // DrawHead, then vertices * 4 floats (clip x, y, z, w)
  Frame = 2,      // FrameHead, then width * height floats of depth (y up) when has_depth
  Unhandled = 3,  // UnhandledHead, then name_bytes of text: a GL feature the library does not handle
  Note = 4,       // free text: the GL renderer and version, the context's profile
  End = 5,        // no payload: the recording finished cleanly
  Clear = 6,      // ClearHead: a clear of depth or stencil, in draw order
  Delta = 7,      // DeltaHead, then pixels * u32 (y * width + x) and pixels * float: the depth a draw changed
};

struct FileHead {
  char magic[8];
  std::uint32_t version;
  std::uint32_t first_frame, last_frame;  // the frames recorded (swap count from 0)
};

struct RecordHead {
  std::uint32_t type;   // RawType
  std::uint32_t bytes;  // payload bytes after this head (one record stays below 4 GiB)
};

struct StencilFaceRaw {
  std::uint32_t func, value_mask, write_mask, fail, depth_fail, pass;
  std::int32_t ref;
};

struct DrawHead {
  std::uint32_t frame;        // swap count
  std::uint32_t index;        // the draw's index in its frame (every draw call, captured or not)
  std::uint32_t call;         // the GL entry point (DrawCall)
  std::uint32_t mode;         // the draw's GL primitive mode (GL_TRIANGLES, ...)
  std::uint32_t skipped;      // Skip
  std::uint32_t primitive;    // what transform feedback captured: GL_POINTS, GL_LINES or GL_TRIANGLES
  std::uint32_t vertices;     // positions that follow
  std::uint32_t flags;        // DrawFlag
  std::uint32_t framebuffer;  // GL_DRAW_FRAMEBUFFER_BINDING
  std::int32_t target_width, target_height;  // its size (the depth attachment's, or the surface's)
  std::int32_t viewport[4];
  std::int32_t scissor[4];
  double depth_range[2];
  std::uint32_t depth_func, cull_mode, polygon_mode;
  float offset_factor, offset_units, offset_clamp;
  float point_size;           // GL_POINT_SIZE (a program may write gl_PointSize instead)
  std::uint32_t program;
  StencilFaceRaw stencil[2];  // front, back
  std::uint32_t depth_bits;   // the render target's depth bits (0: no depth buffer)
  std::uint32_t depth_float;  // 1: a float depth buffer (GL_FLOAT component type)
  std::uint64_t samples_passed;
};

// A clear of the depth or stencil buffer (glClear with GL_DEPTH_BUFFER_BIT or GL_STENCIL_BUFFER_BIT,
// glClearBuffer* of GL_DEPTH, GL_STENCIL or GL_DEPTH_STENCIL), between draw `index - 1` and draw
// `index` of its frame.
struct ClearHead {
  std::uint32_t frame;
  std::uint32_t index;        // the next draw's index
  std::uint32_t framebuffer;  // GL_DRAW_FRAMEBUFFER_BINDING
  std::uint32_t buffers;      // ClearBuffer bits
  std::uint32_t flags;        // kScissor and kDepthMask as DrawHead's (glClear obeys both)
  std::int32_t scissor[4];
  std::uint32_t stencil_write_mask;  // GL_STENCIL_WRITEMASK (glClear obeys the front face's)
  std::int32_t stencil;       // the stencil value it writes
  double depth;               // the depth it writes (GL_DEPTH_CLEAR_VALUE, or glClearBuffer's value)
};

// The depth a draw changed in its render target, for a draw that may write depth and that a model
// cannot be expected to redo exactly (DrawHead of the same index; see interposer.cpp, plain_draw):
// every pixel whose stored depth differs, bit for bit, after the draw from before it.
struct DeltaHead {
  std::uint32_t frame;
  std::uint32_t index;  // the draw's index
  std::uint32_t framebuffer;
  std::int32_t width, height;
  std::uint32_t pixels;
};

struct FrameHead {
  std::uint32_t frame;
  std::uint32_t draws;          // draw calls in the frame
  std::uint32_t framebuffer;    // the render target read: the one that passed the most samples
  std::int32_t width, height;
  std::uint32_t has_depth;      // 0 when it has no depth to read
};

struct UnhandledHead {
  std::uint32_t frame;
  std::uint32_t index;  // the draw index the feature was met at
  std::uint32_t count;  // how many times in that frame (written once a frame per name)
  std::uint32_t name_bytes;
};

// The draw entry points the library wraps (DrawHead::call).
enum class DrawCall : std::uint32_t {
  Arrays = 0,
  Elements,
  RangeElements,
  ArraysInstanced,
  ElementsInstanced,
  ElementsBaseVertex,
  RangeElementsBaseVertex,
  ElementsInstancedBaseVertex,
  ArraysInstancedBaseInstance,
  ElementsInstancedBaseInstance,
  ElementsInstancedBaseVertexBaseInstance,
  MultiArrays,
  MultiElements,
  MultiElementsBaseVertex,
  ArraysIndirect,
  ElementsIndirect,
  MultiArraysIndirect,
  MultiElementsIndirect,
  Count
};

}  // namespace nbsim::apitrace
