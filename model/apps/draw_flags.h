// The bits and codes a recorded program's draws and clears carry (the apps technique): written by
// the interposer (traces/apitrace/raw.h, interposer.cpp), stored in the AppDraws and AppClears
// records (traces/format/apps/apps_chunk.h) and read by the model (model/apps/replay.h). Fixed
// values: they are in files. Header only, no dependencies (the interposer includes it).
#pragma once

#include <cstdint>

namespace nbsim::apps::flags {

// Why a draw was not captured (0: captured).
enum class Skip : std::uint32_t {
  None = 0,
  FixedFunction = 1,     // no program: positions come from the fixed-function pipeline
  NoPosition = 2,        // the program's last vertex stage does not write gl_Position (or its link needed it off)
  OwnFeedback = 3,       // the program's own transform feedback is active or its program declares varyings
  OwnQuery = 4,          // an occlusion or primitive query of the program's own is open
  SeparablePipeline = 5, // a program pipeline object (glCreateShaderProgramv): never relinked
  Indirect = 6,          // the draw's parameters are in a buffer (indirect draw): not captured yet
};

// GL state bits of a draw (DrawHead::flags).
enum DrawFlag : std::uint32_t {
  kDepthTest = 1u << 0,
  kDepthMask = 1u << 1,
  kCullFace = 1u << 2,
  kFrontCcw = 1u << 3,
  kPolygonOffsetFill = 1u << 4,
  kScissor = 1u << 5,
  kStencilTest = 1u << 6,
  kDepthClamp = 1u << 7,
  kRasterizerDiscard = 1u << 8,
  kAlphaTest = 1u << 9,        // compatibility profile's alpha test (fragments discarded by alpha)
  kDiscards = 1u << 10,        // the fragment shader's source has `discard` (comments removed)
  kWritesDepth = 1u << 11,     // the fragment shader's source writes gl_FragDepth
  kPolygonModeNotFill = 1u << 12,
  kClipZeroToOne = 1u << 13,   // glClipControl depth mode ZERO_TO_ONE
  kOverflow = 1u << 14,        // fewer primitives written than generated: positions incomplete
  kMultisample = 1u << 15,     // the render target has samples > 1
  kColorWrite = 1u << 16,      // any colour channel writes
  kClipDistance = 1u << 17,    // a clip distance (or a fixed-function user clip plane) is enabled
};


enum ClearBuffer : std::uint32_t { kClearDepth = 1u << 0, kClearStencil = 1u << 1 };

}  // namespace nbsim::apps::flags
