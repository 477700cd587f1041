// The apps program's plain core (no SystemC; model/apps/unit.h wraps it with timing and
// statistics): a recorded program's frames (traces/format/apps/apps_chunk.h) replayed draw by draw.
//
// Every render target the frames draw into (a framebuffer, at the size and depth format its draws
// report) has its own depth and stencil buffer in the model, kept from frame to frame as GL keeps
// them. Before each draw the frame's clears that precede it are applied (depth and stencil, under
// their write masks and scissor). Then the draw is either
//  - replayed: its captured triangles through the model's raster path (the target's size as the
//    viewport), with its depth, cull, clip-control, depth-clamp and stencil state, and its samples
//    passed compared with GL's; or
//  - flagged, by the first reason the model cannot redo it exactly (Reason: not captured, points or
//    lines, discard or alpha test (named only when nothing else applies), a written fragment depth, polygon offset or mode, multisampling,
//    a viewport, depth range or scissor smaller than the target, a depth format the model does not
//    store, a non-finite position). A flagged draw is never compared; when the recording holds the
//    depth it changed (AppDepthChange), that change is applied to the target, so the draws after it
//    still compare exactly. A draw flagged only because its shader may discard (the flag comes
//    from the source, not from what the draw did) is first replayed as if nothing was discarded
//    and checked against GL: equal samples passed and, when it may write depth, a depth change
//    equal to GL's recorded one, pixel for pixel: then it counts as replayed and matched (its
//    may_discard set); else GL's change stands and it stays flagged; when it may have written depth or stencil and the recording has no
//    change, the target is marked stale: the draws after it, until a clear of the whole target, are
//    replayed and counted apart (after_stale), never among the compared ones.
// At the frame's end the depth of the frame's main target (AppFrame) is compared with GL's "final"
// image pixel by pixel (when the target is not stale).
//
// The window's framebuffer (0) is drawn as Mesa draws it: upside down, relative to an FBO. The
// state tracker keeps a window-system buffer with its first row at the top, so llvmpipe rasterizes
// it with the rows the other way round and reads it back right side up; the model negates the
// viewport's y scale (after clipping: the positions are clipped as given, plane by plane in GL's
// order) and flips the winding, and keeps its rows in that order. The
// depth plane of each triangle, and so every stored depth, is then the one llvmpipe computes (drawn
// right side up, the Z24 depths differ by a few units in a quarter of the pixels). Such a buffer is
// also rasterized with the bottom-edge fill rule (raster/setup.h, SetupConfig::bottom_edge_rule):
// without it the pixels on a horizontal edge through their centres differ.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "model/raster/raster_path.h"
#include "model/raster/stencil_test.h"
#include "model/scene/frame.h"

namespace nbsim::apps {

// Why a draw is not replayed (0: it is). Fixed values: they are in draws.csv.
enum class Reason : std::uint8_t {
  Replayed = 0,
  NotCaptured,    // the interposer recorded no positions (fixed function, the program's own feedback or query, ...)
  Points,
  Lines,
  Discard,        // the fragment shader may discard, or the alpha test is on
  FragDepth,      // the fragment shader writes gl_FragDepth
  PolygonOffset,
  PolygonMode,    // lines or points fill
  Multisample,
  Viewport,       // a viewport other than the whole target
  DepthRange,     // a depth range other than [0, 1]
  Scissor,        // a scissor box inside the target
  DepthFormat,    // a depth buffer the model does not store (16 bits, 32-bit integer)
  NonFinite,      // a NaN or infinite clip position
  NoTarget,       // a render target of size 0
};
inline constexpr int kReasons = 15;
std::string_view to_string(Reason r) noexcept;

// One draw's counts.
struct AppDrawCounts {
  std::uint32_t frame = 0, draw = 0;
  Reason reason = Reason::Replayed;
  bool stale = false;         // replayed after a stale change of its target (not compared)
  bool may_discard = false;   // its shader may discard: replayed as if nothing was, and checked (reason Replayed when equal)
  bool depth_change = false;  // flagged, and GL's depth change applied
  std::uint32_t framebuffer = 0;
  std::uint64_t triangles = 0;  // captured triangles
  std::uint64_t fragments = 0, depth_tests = 0, samples = 0, written = 0;  // the model's (replayed draws)
  std::uint64_t gl_samples = 0;
  bool mismatch() const noexcept { return reason == Reason::Replayed && !stale && samples != gl_samples; }
};

struct AppFrameCounts {
  std::vector<AppDrawCounts> draws;
  std::uint64_t clears = 0;
  std::uint64_t depth_pixels = 0;          // pixels of the frame's main target compared with GL's final image
  std::uint64_t depth_mismatches = 0;      // of those, the ones whose depth differs (bits)
  bool depth_compared = false;             // false: no final image, or its target stale or unknown
  std::string unhandled;                   // the AppFrame record's
};

class AppsReplay {
 public:
  AppsReplay() = default;
  // Replays one frame. InputError when its records are missing or do not fit its draws.
  AppFrameCounts run_frame(const scene::Frame& f);

 private:
  struct Target {
    int width = 0, height = 0;
    raster::DepthFormat format = raster::DepthFormat::Float32;
    DepthImage depth;
    raster::StencilImage stencil;
    std::unique_ptr<raster::RasterPath> path;
    bool stale = false;
    // The window's framebuffer (0): Mesa renders it upside down (rows from the top, the winding
    // mirrored), so the model does too and stores its rows flipped; GL reads it back bottom up.
    bool flipped = false;
    // The stored index of pixel `i` as GL reads it back (y * width + x, y up).
    std::size_t stored(std::size_t i) const noexcept {
      if (!flipped) return i;
      const std::size_t w = static_cast<std::size_t>(width);
      return (static_cast<std::size_t>(height) - 1 - i / w) * w + i % w;
    }
  };
  // The target of framebuffer `fb` at this size and format (made, or remade when they changed:
  // stale until a whole clear when it has a depth buffer).
  Target& target(std::uint32_t fb, int width, int height, raster::DepthFormat format, bool has_depth);

  // One draw through the target's raster path with its recorded state.
  raster::DrawCounters replay(Target& t, const scene::DrawRecord& draw, bool has_depth);
  // Whether the depth the model's draw changed (`before` -> the target now) is GL's recorded change,
  // pixel for pixel and bit for bit.
  bool same_change(const Target& t, const std::vector<float>& before, const scene::TechniqueRecord& change, std::uint64_t frame,
                   std::size_t k) const;

  std::map<std::uint32_t, Target> targets_;
  std::vector<float> scratch_;  // a target's depth before a draw that may discard
};

}  // namespace nbsim::apps
