// The N-buffer unit's algorithm core (plain C++, no SystemC): level storage at full or reduced
// resolution, the update engine's policies and the query port's answers, each with the work it cost.
// model/nbuffer/unit.h wraps it into the SystemC module that turns that work into cycles.
//
// Resolution: with resolution_divisor d the levels are built over a reduced image whose texel
// (x, y) is the farthest of the depth pixels [d x, d x + d) x [d y, d y + d) inside the image, so
// any full-resolution rectangle maps to the reduced texels it touches and stays conservative.
// Policies: eager applies every change at once; batched collects changed texels and applies them
// at end_of_pass() (a change that moves some texel farther is applied at once, because stale
// levels are conservative only while the pending changes all move depth nearer); lazy applies the
// pending changes a query's squares cover just before answering it. All three reach the same
// levels once applied; in between, batched answers are conservative and possibly less tight.
// on_demand (NBuffer::set_on_demand) writes level 0 at once and only marks stale the level texels
// that read a changed pixel; a query computes the stale texels it reads (recursively, from the level
// below) and they stay until a pixel under them changes: the upkeep follows the queries, not the
// pixels, and every answer equals eager's. Square levels only.
// Dirty tracking (dirty_tile, batched and lazy): the pending changes are kept per texel (1, a flag
// per storage texel) or per dirty_tile x dirty_tile tile of texels (a flag per tile: 1/64 of the
// state for 8x8); applying a dirty tile hands all its texels to the update engine, which compares
// each with level 0 and carries only the changed ones up, so a tile costs its area at level 0 and
// nothing more above it.
// Demand-capped levels (demand_levels): between two depth clears the unit keeps current only the
// levels up to the highest one the queries since the clear before needed (plus demand_margin);
// a query that needs a higher level tiles the highest kept one (capped_max_lookups) or answers
// Incomplete. The clear is where the kept levels change: it writes (or, fast_clear, tags) exactly
// the levels the next frame keeps, so raising a level costs what clearing it costs.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "model/common/query.h"
#include "model/common/rect.h"
#include "model/common/storage.h"
#include "model/config/schema.h"
#include "model/memory/memory.h"
#include "model/nbuffer/covering.h"
#include "model/nbuffer/nbuffer.h"
#include "model/stats/stats.h"

namespace nbsim::nbuffer {

// When depth-buffer changes reach the levels. Fixed values (they may end up in run outputs).
enum class UpdatePolicy : std::uint8_t { Eager = 0, Batched = 1, Lazy = 2, OnDemand = 3 };

// Names of UpdatePolicy, indexed by its value (model/common/names.h).
inline constexpr std::array<std::string_view, 4> kUpdatePolicyNames = {"eager", "batched", "lazy", "on_demand"};
std::string_view to_string(UpdatePolicy p) noexcept;
std::optional<UpdatePolicy> parse_update_policy(std::string_view s) noexcept;

// Configuration of an N-buffer unit (config keys "<instance>.<field>", "nbuffer.<field>" for occlusion culling's). Every default is tunable;
// the timing defaults are design guesses, not measurements (see describe() for limits).
struct NBufferUnitConfig {
  int resolution_divisor = 1;   // 1, 2, 4 or 8: levels over a (W/d) x (H/d) image
  std::string format = "f32";   // level storage: f32, u24 (as D24X8) or u16
  int level_cap = -1;           // highest level built; -1 builds all
  int capped_max_lookups = 16;  // lookups allowed to tile a rectangle whose level is capped; 0: answer incomplete
  // The query's covering (covering.h): paper, corners or one, and its alignment, top or bottom;
  // "trace" takes the capture's (the header's nbuffer_covering; a trace without it was captured
  // with corners/bottom), which a program that compares its answers with GL's needs.
  std::string covering = "trace";
  std::string align = "trace";
  // Not a key: the particles program reads power-of-two sprites with one lookup (CoveringSpec).
  bool direct_squares = false;
  // The levels' neighbourhoods (nbuffer.h LevelShape): square or rect; rect: max_aspect_log2.
  std::string levels = "square";
  int max_aspect_log2 = -1;
  std::string update_policy = "eager";    // eager, batched, lazy or on_demand
  int lookup_latency_cycles = 8;          // address, tag check and data of one lookup batch
  double lookups_per_cycle = 4.0;         // the four squares of a query in one cycle
  double update_texels_per_cycle = 16.0;  // texels recomputed per cycle by the update engine
  int update_latency_cycles = 16;         // fill and drain of the update engine per batch
  double invalidations_per_cycle = 64.0;  // on_demand: stale flags the update engine clears per cycle (no texel moves)
  // A depth clear sets a per-tile clear tag on every level (as a depth buffer's fast clear, and as
  // the Hi-Z baselines clear) instead of the update engine writing every level's texels. Off: a
  // clear writes every level (the unit as first modelled).
  bool fast_clear = false;
  // Level 0: copy (the paper's: the depth map copied into the levels' storage, every depth change
  // written again) or depth (the depth buffer itself is level 0: no copy written, level 1 reads the
  // depth buffer; needs resolution_divisor 1 and format f32).
  std::string level0 = "copy";
  // batched and lazy: pending changes tracked per dirty_tile x dirty_tile texels (1: per texel).
  int dirty_tile = 1;
  // Levels kept current only up to the highest one the previous frame's queries needed (frames
  // run from depth clear to depth clear), plus demand_margin levels.
  bool demand_levels = false;
  int demand_margin = 0;
  // Texel cache of the query port: 16 KiB, 256-byte lines (an 8x8 tile of f32 texels), 4 ways.
  memory::CacheConfig cache{16 * 1024, 256, 4};

  // The keys' prefix: the instance's name (pipeline/sim/programs.h), "nbuffer" for the one
  // occlusion culling owns. Set by describe(); messages name the keys with it.
  std::string key_prefix = "nbuffer";

  // Declares every field as "<prefix>.<field>" (the cache as <prefix>.cache_size_bytes,
  // <prefix>.cache_line_bytes, <prefix>.cache_ways), bound to `c`.
  static void describe(config::Schema& schema, NBufferUnitConfig& c, const std::string& prefix = "nbuffer");
  // Throws InputError naming the key when a value is outside its limits or inconsistent.
  void validate() const;
  StorageFormat storage_format() const;  // the parsed `format` (call after validate())
  UpdatePolicy policy() const;           // the parsed `update_policy` (call after validate())
  LevelShape shape() const;              // the parsed `levels` (call after validate())
  // The covering, "trace" in either field taken from `capture` (call after validate()).
  CoveringSpec covering_spec(CoveringSpec capture = {}) const;
};

// What a query found. Fixed values: statistics buckets are in this order.
enum class QueryOutcome : std::uint8_t {
  Hidden = 0,      // the nearest depth is strictly farther than the answer: cull
  Visible = 1,     // not provably hidden
  Incomplete = 2,  // the level needed was not built and tiling it would take too many lookups
  Offscreen = 3,   // empty rectangle or none of it inside the image: no lookups, never hidden
};
std::string_view to_string(QueryOutcome o) noexcept;

// True when a primitive whose nearest depth is `nearest` is hidden behind a region whose farthest
// depth is `farthest`: strictly farther (equal depth may pass a LEQUAL/GEQUAL test). NaN: false.
constexpr bool hidden_behind(FarOp op, float nearest, float farthest) noexcept {
  return op == FarOp::Max ? nearest > farthest : nearest < farthest;
}

// Work of the update engine for one change or one batch of pending changes.
struct UpdateWork {
  std::vector<std::uint64_t> texels_recomputed;  // per level (index = level); empty: nothing done
  std::vector<std::uint64_t> texels_changed;     // per level: recomputed texels whose value changed
  std::vector<std::uint64_t> texels_invalidated; // per level: texels marked stale (on_demand: a flag, no texel moved)
  std::uint64_t depth_pixels_reduced = 0;        // depth pixels read to form reduced level-0 texels
  std::uint64_t bytes_read = 0;                  // level texels streamed in from memory
  std::uint64_t bytes_written = 0;               // changed texels written back

  std::uint64_t recomputed() const noexcept;
  std::uint64_t changed() const noexcept;
  std::uint64_t invalidated() const noexcept;
  // The engine's texel slots this work takes: the recomputed texels, and the stale flags at
  // `invalidations_per_cycle` where the texels go at `texels_per_cycle`.
  std::uint64_t engine_texels(double texels_per_cycle, double invalidations_per_cycle) const noexcept;
  UpdateWork& operator+=(const UpdateWork& o);
};

// The answer of the query port and the work it cost.
struct QueryAnswer {
  QueryOutcome outcome = QueryOutcome::Offscreen;
  bool hidden = false;
  float value = 0.0f;                       // conservative farthest depth of the rectangle (far limit when !complete)
  int level = 0;                            // level read, or the level needed when !complete
  bool complete = true;                     // false: the level needed was not built (value is the far limit)
  bool tiled = false;                       // the level was capped: the rectangle was tiled with top-level squares
  CoveringCase kase = CoveringCase::FourQuadrants;  // the rectangle's case of Fig. 3
  Rect reduced;                             // the rectangle at the storage resolution (clipped to it)
  int lookups = 0;                          // texels read: at most 4, or capped_max_lookups when tiled
  int texel_count = 0;                      // texels recorded below: min(lookups, 4), in level coordinates
  std::array<Texel, 4> texels{};
  std::uint64_t cache_hits = 0, cache_misses = 0;
  std::uint64_t bytes_read = 0;  // cache-line fills for the misses
  UpdateWork update;             // lazy policy: pending changes applied before answering; on_demand: stale texels computed
};

// Bytes per storage texel as the unit moves them (u24 as a 32-bit D24X8 word).
int texel_bytes(StorageFormat f) noexcept;

class NBufferUnitCore {
 public:
  // A unit for a width_px x height_px depth buffer, cleared to the far limit of `op`. `config` is
  // validated here (InputError). Statistics are declared in `stats`, which must outlive the core.
  NBufferUnitCore(const NBufferUnitConfig& config, int width_px, int height_px, FarOp op, stats::Group& stats);

  // The pixels of `depth` (the whole depth buffer, width_px x height_px) inside `dirty` changed.
  UpdateWork depth_changed(const DepthImage& depth, const Rect& dirty);
  // Each write replaces one depth pixel, in order. Throws InputError (and changes nothing) when a
  // write lies outside the depth buffer.
  UpdateWork depth_changed(std::span<const PixelWrite> writes);
  // The whole depth buffer was cleared to `depth`: every level is refilled, nothing stays pending.
  UpdateWork depth_cleared(float depth);
  // A pass ended: the batched policy applies its pending changes; the others do nothing.
  UpdateWork end_of_pass();
  // A frame ended: like end_of_pass(), and the frame is counted.
  UpdateWork end_of_frame();
  // Applies every pending change whatever the policy (before reading levels out, e.g. to compare).
  UpdateWork flush();

  // Farthest depth of the full-resolution rectangle r and whether a primitive whose nearest depth
  // is `nearest_depth` is hidden behind it. Never throws: empty and off-screen rectangles answer
  // Offscreen with no lookups.
  // The covering is the config's (covering_spec(): "trace" left unresolved is the paper's).
  QueryAnswer query(const Rect& r, float nearest_depth);

  const NBufferUnitConfig& config() const noexcept { return config_; }
  CoveringSpec covering() const noexcept { return covering_; }
  FarOp op() const noexcept { return op_; }
  int width_px() const noexcept { return depth_.width; }
  int height_px() const noexcept { return depth_.height; }
  int divisor() const noexcept { return divisor_; }
  // The levels as stored (they lag the depth buffer while changes are pending).
  const NBuffer& levels() const noexcept { return nb_; }
  // The model's copy of the depth buffer, and the image level 0 is built from (itself when d = 1).
  const DepthImage& depth() const noexcept { return depth_; }
  const DepthImage& level0_source() const noexcept { return divisor_ == 1 ? depth_ : reduced_; }
  // The storage-resolution rectangle covering every reduced texel that r's pixels fall in.
  Rect to_reduced(const Rect& r) const noexcept;
  // Texels the pending changes will hand to the update engine (per-tile tracking: the dirty tiles' texels).
  std::uint64_t pending_texels() const noexcept { return pending_count_; }
  // The highest level kept current (demand_levels: this frame's cap; otherwise the top level).
  int kept_top_level() const noexcept { return kept_top_; }
  // Bits of state the unit keeps to know what is stale: pending flags (batched, lazy; per texel or
  // per dirty tile) or current flags of every level above 0 (on_demand); 0 for eager.
  std::uint64_t tracking_bits() const noexcept;
  // Byte address of a level texel in the unit's memory: planes of cache-line-sized tiles.
  std::uint64_t texel_address(int level, int x, int y) const noexcept;
  std::uint64_t cache_hits() const noexcept { return cache_.hits(); }
  std::uint64_t cache_misses() const noexcept { return cache_.misses(); }

 private:
  UpdateWork new_work() const;
  void account(const UpdateStats& s, UpdateWork& w);
  void reduce_block(int rx, int ry, UpdateWork& w);
  float stored(float d) const noexcept { return quantize_toward_far(d, format_, op_); }
  // Marks the reduced texels whose value differs from level 0 as pending; true when one of them
  // moves farther than level 0 holds (stale levels would then no longer be conservative).
  bool mark(const Rect& rr);
  bool mark(std::span<const Texel> texels);
  void unmark(const Rect& rr);
  void unmark(std::span<const Texel> texels);
  void mark_one(int x, int y);
  void mark_tile(int x, int y);
  std::uint64_t tile_area(int tx, int ty) const noexcept;
  // Per-tile tracking: hands every texel of each dirty tile that meets `region` (storage
  // coordinates, clipped) to the update engine and clears those tiles.
  UpdateWork apply_tiles(const Rect& region);
  // Clears dirty tile (tx, ty) and appends its texels to `take` (nothing when it is clean).
  void take_tile(int tx, int ty, std::vector<Texel>& take);
  // Applies the pending texels of every bin that meets `region` (storage coordinates).
  UpdateWork apply_pending(const Rect& region);
  UpdateWork apply_writes(std::span<const Texel> texels);
  void read_texel(QueryAnswer& a, int level, int x, int y);

  NBufferUnitConfig config_;
  FarOp op_;
  StorageFormat format_;
  UpdatePolicy policy_;
  CoveringSpec covering_;
  int divisor_;
  DepthImage depth_;    // full resolution, the model's copy of the depth buffer
  DepthImage reduced_;  // storage resolution when divisor_ > 1 (else unused)
  NBuffer nb_;
  memory::Cache cache_;
  int tile_w_ = 8, tile_h_ = 8, tiles_x_ = 1, tiles_y_ = 1;  // texel tiles of one cache line

  // Pending changes: a flag per storage texel and, per bin of kBinPx x kBinPx texels, the texels
  // flagged in it (entries whose flag was cleared since are skipped).
  static constexpr int kBinPx = 16;  // tunable: smaller bins let lazy queries apply less
  std::vector<std::uint8_t> pending_;
  std::vector<std::vector<Texel>> bins_;
  int bins_x_ = 1, bins_y_ = 1;
  std::uint64_t pending_count_ = 0;
  std::vector<std::uint32_t> stamp_;  // per storage texel, dedups the texels of one write batch
  std::uint32_t epoch_ = 0;
  std::vector<Texel> scratch_;
  std::vector<PixelWrite> writes_;
  // Per-tile tracking (dirty_tile > 1): a flag per tile of dirty_tile x dirty_tile texels.
  int dirty_tile_ = 1, dtiles_x_ = 1, dtiles_y_ = 1;
  std::vector<std::uint8_t> tile_dirty_;
  // Demand-capped levels: the levels kept this frame, and the highest level needed since the last clear.
  int kept_top_ = 0;
  int demand_seen_ = -1;

  // Statistics (declared in the unit's group).
  stats::VectorCounter& queries_;
  stats::VectorCounter& cases_;
  stats::VectorCounter& lookups_;
  stats::Counter& tiled_queries_;
  stats::Counter& hits_;
  stats::Counter& misses_;
  stats::Counter& bytes_read_;
  stats::Counter& bytes_written_;
  stats::VectorCounter& recomputed_;
  stats::VectorCounter& changed_;
  stats::VectorCounter& invalidated_;
  stats::Counter& reduced_pixels_;
  stats::VectorCounter& changes_;
  stats::VectorCounter& applied_;
  stats::Counter& frames_;
  stats::Counter& fast_clears_;
  stats::Counter& kept_levels_;
  stats::Counter& demand_frames_;
};

}  // namespace nbsim::nbuffer
