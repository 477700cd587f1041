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
//    store, a non-finite position, a user clip plane). A flagged draw is never compared; when the recording holds the
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
// Culling a program's draw calls (set_culling): the program never asked for it, so each draw call
// is an object, tested in submission order against the depth its target holds at that moment, as a
// unit beside the depth buffer would test it. A draw is tested when
//  - it is one the model replays (not flagged; a may-discard draw too: discard only removes
//    fragments) into the frame's main target, at the size of the tester's structure, not stale;
//  - its depth test is on with a func that fails behind (LESS or LEQUAL; GREATER or GEQUAL under a
//    reversed structure), and it writes no stencil (a stencil op on a failed test would change the
//    target even when nothing passes).
// Its bounds are those of the triangles setup accepts (cull/primitive.h: a rectangle that holds
// every pixel the rasterizer may cover, and a depth no fragment is nearer than, bit for bit; for a
// 24-bit target that depth as the buffer stores it, which keeps the bound since storing is
// monotone). The tester (DrawTester) says whether the rectangle is hidden; a hidden draw is not
// drawn. Ground truth is GL's samples passed: a culled draw with GL samples is a false cull. With
// per-primitive granularity the triangles of a draw found visible are each tested too, and the
// hidden ones skipped before the tile walk (the draw's samples are still compared with GL's, which
// catches a wrong drop). Every change of the main target (clears, replayed draws' written blocks,
// GL's applied changes) reaches the tester, which is brought up to date before a query when it
// changed since the last one.
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
#include <span>
#include <memory>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "model/common/rect.h"
#include "model/query/structure.h"
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
  ClipDistance,   // a user clip plane or clip distance is enabled (the model clips at the view volume only)
};
inline constexpr int kReasons = 16;
std::string_view to_string(Reason r) noexcept;

// What tests draws for culling (model/apps/unit.h makes one over a query structure, or the
// occlusion query's full-resolution test): told of every change of the target it mirrors.
class DrawTester {
 public:
  virtual ~DrawTester() = default;
  // The mirrored target is now `depth` (another target, or the same one remade): the structure is
  // made from it whole.
  virtual void rebuild(const DepthImage& depth) = 0;
  virtual void cleared(const DepthImage& depth, float value) = 0;        // a whole clear to `value`
  virtual void changed(const DepthImage& depth, const Rect& dirty) = 0;  // the pixels in `dirty` changed
  // Queries come next and something changed since the last ones.
  virtual void prepare(const DepthImage& depth) = 0;
  // One query per rectangle (rects[i] with nearest[i], non-empty, inside the target), answers in order.
  virtual void query(const DepthImage& depth, std::span<const Rect> rects, std::span<const float> nearest,
                     std::vector<query::Answer>& answers) = 0;
};

// The occlusion query's answer at full resolution: a box at `nearest` over `r`, drawn with a test
// that passes where the buffer holds a farther depth (under `op`); hidden when no pixel passes. Its
// lookups are the box's fragments (the rectangle's pixels).
query::Answer full_depth_query(const DepthImage& depth, const Rect& r, float nearest, FarOp op) noexcept;

// Which draws are tested, and how.
struct CullSettings {
  DrawTester* tester = nullptr;  // null: no culling
  int width = 0, height = 0;     // the tester's target size: draws into a main target of another size are not tested
  FarOp op = FarOp::Max;
  bool primitives = false;       // also test each triangle of a draw found visible
  bool fused_interpolation = true;
};

// Why a draw is not tested in a cull mode. Fixed values.
enum class Untested : std::uint8_t {
  Tested = 0,
  Flagged,       // a draw the model does not replay
  OtherTarget,   // not the frame's main target, or not at the tester's size
  Stale,         // its target's depth is not known to the model
  DepthFunc,     // the depth test off, or a func that does not fail behind
  StencilWrites, // it may write stencil
  NoTriangles,   // setup accepts none of its triangles, or rasterization is discarded: nothing to draw
};
inline constexpr int kUntested = 7;
std::string_view to_string(Untested u) noexcept;

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
  // Culling (set_culling): whether it was tested and why not, culled, the query's lookups; its
  // triangles tested and dropped (per-primitive) and their lookups.
  Untested untested = Untested::Flagged;
  bool culled = false;
  std::uint64_t query_lookups = 0;
  std::uint64_t primitive_tests = 0, primitives_culled = 0, primitive_lookups = 0;
  bool false_cull() const noexcept { return culled && gl_samples > 0; }
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
  // Culls the draws in every frame from now on (settings.tester must outlive the replay).
  void set_culling(const CullSettings& settings) { cull_ = settings; }
  // The depth the model holds for framebuffer `fb` (rows as stored), or null when it has none.
  const DepthImage* depth_of(std::uint32_t fb) const {
    const auto it = targets_.find(fb);
    return it == targets_.end() ? nullptr : &it->second.depth;
  }
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
    bool tester_dirty = false;  // changed since the tester's last prepare (the tester mirrors it)
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

  // One draw through the target's raster path with its recorded state (skip: per-primitive culls,
  // RasterPath::draw), its written blocks told to the tester; replay_untold tells nothing (the
  // may-discard check tells them only when the draw is found equal to GL's).
  raster::DrawCounters replay(Target& t, const scene::DrawRecord& draw, bool has_depth, std::span<const char> skip = {});
  raster::DrawCounters replay_untold(Target& t, const scene::DrawRecord& draw, bool has_depth, std::span<const char> skip = {});
  // The path's state for a recorded draw into `t` (its depth, cull, winding mirrored in the window,
  // stencil).
  static raster::DrawState draw_state_of(const Target& t, const scene::DrawRecord& draw, bool has_depth);
  // Whether the depth the model's draw changed (`before` -> the target now) is GL's recorded change,
  // pixel for pixel and bit for bit.
  bool same_change(const Target& t, const std::vector<float>& before, const scene::TechniqueRecord& change, std::uint64_t frame,
                   std::size_t k) const;

  // Tells the tester of a change of `t` when it mirrors it.
  void touched(Target& t, const Rect& stored_rect);
  // The cull test of draw `draw` into `t` (tested: c.untested is Tested); fills c's cull counts and
  // `skip` (per-primitive). Returns whether the draw is culled.
  bool cull_test(Target& t, const scene::DrawRecord& draw, AppDrawCounts& c, std::vector<char>& skip);

  std::map<std::uint32_t, Target> targets_;
  CullSettings cull_;
  const Target* mirrored_ = nullptr;  // the target the tester holds
  std::vector<Rect> rects_;  // cull_test's scratch: each accepted triangle's query, then the batch
  std::vector<float> nearest_;
  std::vector<std::size_t> index_;
  std::vector<query::Answer> answers_;
  std::vector<char> skip_;
  std::vector<float> scratch_;  // a target's depth before a draw that may discard
};

}  // namespace nbsim::apps
