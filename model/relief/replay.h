// The relief program's plain core (no SystemC; model/relief/unit.h wraps it with timing, the
// heightfield texel cache and statistics). Per frame: GL's RLFH record (records.h: the heightfield,
// its safety radius and GL's max N-buffer, checked against the model's own build) and, for every
// relief_box draw in order with its RLFF record,
//  1. the box's triangles through the model's raster path at the viewport's size, early depth test
//     LESS with depth writes off (relief.frag's state) against the frame's depth buffer: cleared to
//     1.0 at the frame's start, then the frame's scene draws (role scene: boxes placed in the city)
//     in order with their recorded state; the fragments that pass run the walk (one a pixel: the box
//     is convex and back faces are culled);
//  2. every such fragment's walk (walk.h) with the draw's method, compared with GL's fragment by
//     fragment: the same pixels, and the same hit, t (bits), lookups, steps and bisections;
//  3. every walk scored against the exact reference (score.h): the method's hit error;
//  4. what the draw leaves in the depth buffer (box_depth.h, the header's relief_box_depth): with
//     box, the hits' interpolated box depth (early test, late write); with exact, the hits' own
//     depth (the test after the walk: step 1 then tests nothing and every rasterized fragment
//     walks), the buffer then compared with GL's by its CRC (RLFD). Every box draw starts from the
//     depth as it was before the frame's first box draw; scene draws after a box draw are that
//     draw's "scene after": their samples, and the fragments the box's depth hid (the same draws
//     replayed against the depth without the box).
// Every scene draw's samples passed are compared with GL's.
// GL's counters of the draw: fragments (relief.frag counts after the early test) and samples passed
// (fragments that were not discarded: the hits).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "model/common/depth.h"
#include "model/memory/memory.h"
#include "model/nbuffer/nbuffer.h"
#include "model/raster/raster_path.h"
#include "model/relief/box_depth.h"
#include "model/relief/records.h"
#include "model/relief/score.h"
#include "model/relief/walk.h"
#include "model/relief/workers.h"
#include "model/scene/frame.h"

namespace nbsim::relief {

// One box draw's counts.
struct BoxDrawCounts {
  Method method = Method::Binary;
  std::uint64_t triangles = 0, blocks = 0, depth_tests = 0;
  std::uint64_t fragments = 0, gl_fragments = 0;  // the model's (after the early test) and GL's counter
  std::uint64_t rasterized = 0;                    // the model's fragments before the early test (hidden ones culled)
  std::uint64_t samples = 0, gl_samples = 0;      // the model's hits and GL_SAMPLES_PASSED
  std::uint64_t pixel_mismatches = 0;  // pixels in the model's fragments or GL's RLFF but not both
  std::uint64_t walk_mismatches = 0;   // fragments of both whose hit, t, lookups, steps or bisections differ
  std::uint64_t lookups = 0, steps = 0, bisections = 0, hits = 0, capped = 0;
  std::uint64_t gl_lookups = 0;
  std::uint64_t longest_walk = 0;  // most lookups of one fragment
  bool scored = true;  // the walks were scored against the reference (ReliefReplay::set_scoring); else the five below are 0
  std::uint64_t reference_hits = 0, wrong_hit = 0, wrong_miss = 0, far_hit = 0;
  std::uint64_t errors() const noexcept { return wrong_hit + wrong_miss + far_hit; }
  double distance_sum = 0.0;  // texels between the hit and the reference's, summed over fragments where both hit
  // The textures the method reads, bytes (4 a texel, as GL's R32F textures): the heights; the safety
  // radii (robust, robust_clamp); every N-buffer level (nbuffer).
  std::uint64_t storage_bytes = 0;
  // The box's depth (box_depth.h): depth values the draw wrote; 1 when the depth buffer after it
  // differs from GL's (its RLFD CRC), else 0; the scene draws after it (placement city), the samples
  // they passed and the fragments of theirs the box's depth hid.
  std::uint64_t depth_written = 0, depth_mismatches = 0;
  // The N-buffer walk (method nbuffer) against an on-demand N-buffer of the heightfield: the level
  // texels above 0 a full build computes (eager: (levels - 1) N^2, charged to the frame's first
  // nbuffer draw), those an on-demand build computes for the texels the walks read (each from the
  // level below, recursively, kept for the frame's later draws; from a cleared N-buffer), and read
  // texels whose on-demand value differs from the full build's the walks read (expected 0).
  std::uint64_t levels_eager_texels = 0, levels_on_demand_texels = 0, levels_on_demand_mismatches = 0;
  std::uint64_t scene_after_draws = 0, scene_after_samples = 0, scene_hidden = 0;
};

// Where a replay's lookups go (the unit's texel cache), in the walks' order: the fragments of a draw
// walk in parallel (workers.h), in runs of consecutive fragments in pixel order, and the runs come
// here one after another on the calling thread, each run's lookups as LookupLines (walk.h) recorded
// with this sink's geometry.
class LookupSink {
 public:
  virtual LineGeometry geometry() const = 0;
  virtual void take(const LookupLines& run) = 0;

 protected:
  ~LookupSink() = default;
};

// The relief unit's heightfield texel cache (unit.h) as a LookupSink: fed the walks' lookups in
// their order, it counts the current box draw's hits and misses (the caller resets them). The same
// hits and misses as a memory::Cache that sees every lookup of a texel in memory, at address
// texel_address, except that with a cache of more than 0 bytes a lookup of the line just before
// always counts as a hit (what a cache with sets does anyway, and the unit has counted so since
// before its sets could be fewer than one).
class TexelCache final : public LookupSink {
 public:
  explicit TexelCache(const memory::CacheConfig& c);  // c.line_bytes a power of two
  LineGeometry geometry() const override;
  void take(const LookupLines& run) override;
  void invalidate();  // a new frame: empty, and no lookup before
  std::uint64_t draw_hits = 0, draw_misses = 0;

 private:
  memory::LineCache cache_;
  int line_shift_ = 0;  // log2 of the line's bytes
  bool merge_ = false;
  std::uint64_t last_line_ = ~std::uint64_t{0};  // the cache line of the last lookup
};

struct ReliefFrameCounts {
  int size = 0;  // the heightfield's N
  // The frame's safety radii (RLFH): their sum and the texels at 0, over its N * N texels.
  std::uint64_t radius_sum = 0, radius_zero = 0;
  std::uint64_t scene_draws = 0, scene_depth_tests = 0;  // the scene's draws (placement city), before and after the boxes
  std::uint64_t scene_mismatches = 0;                    // scene draws whose samples passed differ from GL's (expected 0)
  double view_angle = 0.0;
  std::vector<BoxDrawCounts> draws;  // relief_box draws in order
};

class ReliefReplay {
 public:
  // The viewport (1 .. 16384 a side; InputError otherwise). `covering`: the N-buffer walk's, the
  // capture's (the trace header's nbuffer_covering).
  // `box_depth`: the header's relief_box_depth (none for a trace without it). `threads`: the walks'
  // (workers.h; every count is the same for any number).
  ReliefReplay(int width, int height, bool fused_interpolation = true, CoveringSpec covering = {}, BoxDepth box_depth = BoxDepth::None,
               int threads = relief_threads());
  ReliefReplay(const ReliefReplay&) = delete;
  ReliefReplay& operator=(const ReliefReplay&) = delete;

  // Whether walks are scored against the exact reference (default yes). Off, no reference is
  // computed and every BoxDrawCounts score field (reference_hits, wrong_hit, wrong_miss, far_hit,
  // distance_sum) stays 0, with `scored` false.
  void set_scoring(bool on) noexcept { scoring_ = on; }

  // Runs the frame. `tolerance`: score.h's, texels; `box_height`: the box's height over its width
  // (the trace header's relief_box_height). `lookups` (may be null) sees every lookup of every walk;
  // `draw_done` (may be null) is called after each box draw's walks with its counts.
  // InputError naming the frame for a damaged record, a box draw without its RLFF or the reverse, or
  // a box draw that is not triangles.
  ReliefFrameCounts run_frame(const scene::Frame& f, double tolerance, double box_height, LookupSink* lookups = nullptr,
                              void* context = nullptr, void (*draw_done)(void* context, const BoxDrawCounts& draw) = nullptr);

 private:
  int width_, height_;
  CoveringSpec covering_;
  BoxDepth box_depth_;
  bool scoring_ = true;
  DepthImage depth_;
  std::vector<float> before_boxes_;  // the depth before the frame's first box draw
  DepthImage without_box_;           // the scene after a box drawn without it (box_depth_ not none)
  // Per pixel: a box draw's walk hit there, and its exact depth (box_depth_ exact); two of each, for
  // the frame's even and odd box draws (a draw's write runs beside the next draw's walks).
  std::array<std::vector<std::uint8_t>, 2> hit_;
  std::array<std::vector<float>, 2> hit_depth_;
  std::vector<std::uint8_t> passed_;
  // The early depth test of the frame's last box draw that ran it: its draw (clip positions and
  // state) and counts; passed_ and fragment_pixels_ hold its fragments.
  struct EarlyTest {
    bool valid = false;
    scene::DepthState state;
    std::vector<std::array<float, 4>> positions;
    raster::DrawCounters counts;
  };
  EarlyTest early_;
  // The frame's rays and references by pixel (the methods' draws share the frame's ray frame):
  // computed at the first draw that walks the pixel, which pixel_state_ records.
  static constexpr std::uint8_t kPixelUnknown = 0, kPixelNoRay = 1, kPixelRay = 2, kPixelReference = 3;
  std::vector<FragmentRay> rays_;
  std::vector<ReferenceHit> reference_;
  std::vector<std::uint8_t> pixel_state_;
  raster::RasterPath path_;
  raster::RasterPath without_box_path_;
  // A draw's fragments (pixels in order), and by run of kRunFragments fragments their lookups and
  // counts (with the distances of the scored hits, summed by the draw in fragment order): filled by
  // the workers, read in order by the calling thread.
  struct Tally {
    BoxDrawCounts counts;
    std::vector<double> distances;
  };
  static constexpr std::size_t kRunFragments = 256;
  std::vector<std::uint32_t> fragment_pixels_;
  std::vector<LookupLines> runs_;
  std::vector<Tally> tallies_;
  WorkerPool pool_;
  // The frame's on-demand N-buffer of the heights (made at its first nbuffer draw); the level texels
  // the current draw's walks read (a byte each), per thread of the pool; those computed and compared
  // so far (a byte each), and the build's counts over the draw.
  std::optional<NBuffer> on_demand_;
  bool on_demand_fresh_ = false;  // on_demand_ holds this frame's heights
  std::vector<std::vector<std::uint8_t>> level_marks_;
  std::vector<std::uint8_t> levels_checked_;
  UpdateStats demand_;
  // Per thread of the pool: a run's rays to walk (walk_each), their fragments and their walks.
  struct RunScratch {
    std::vector<const FragmentRay*> rays;
    std::vector<std::size_t> fragments;
    std::vector<WalkResult> results;
  };
  std::vector<RunScratch> scratch_;
  void begin_levels(const GlReliefField& gl, BoxDrawCounts& c);
  void run_levels(const GlReliefField& gl, std::span<const std::uint32_t> texels, BoxDrawCounts& c);
  void end_levels(BoxDrawCounts& c) const;
};

}  // namespace nbsim::relief
