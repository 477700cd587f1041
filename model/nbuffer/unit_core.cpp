// The N-buffer unit's algorithm core: configuration, reduced-resolution level storage, update
// policies and queries with their work; see unit_core.h.
#include "model/nbuffer/unit_core.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "model/common/error.h"
#include "model/common/names.h"

namespace nbsim::nbuffer {

namespace {

// Limits shared by the schema and validate(), so that a config built in code obeys the same ones.
constexpr int kMaxLevelCap = 30;
constexpr int kMaxCappedLookups = 4096;
constexpr int kMaxLatencyCycles = 1'000'000;
constexpr double kMinRate = 1.0 / 64.0, kMaxLookupRate = 1024.0, kMaxUpdateRate = 65536.0;
constexpr int kMaxCacheBytes = 1 << 30, kMinLineBytes = 4, kMaxLineBytes = 4096, kMaxWays = 64;
constexpr int kMaxSidePx = 16384;
constexpr int kMaxAspectLog2 = 14;
constexpr int kMaxDirtyTile = 64;

constexpr std::string_view kOutcomeLabels[] = {"hidden", "visible", "incomplete", "offscreen"};

// "0", "1", ... for square levels; "1x1", "2x1", ... (the neighbourhood) for rectangle levels.
std::vector<std::string> level_labels(const NBuffer& nb) {
  std::vector<std::string> l;
  for (int i = 0; i < nb.level_count(); ++i) l.push_back(nb.level_label(i));
  return l;
}

std::vector<std::string> case_labels() {
  std::vector<std::string> l;
  return name_list(kCoveringCaseNames);
}

const NBufferUnitConfig& validated(const NBufferUnitConfig& c) {
  c.validate();
  return c;
}

int checked_side(int v, const char* what) {
  if (v < 1 || v > kMaxSidePx)
    throw InputError(fmt::format("N-buffer unit: depth buffer {} must be 1 to {} pixels, got {}", what, kMaxSidePx, v));
  return v;
}

int ceil_div(int a, int b) noexcept { return (a + b - 1) / b; }

// Trigger buckets of the texels_applied statistic.
enum Trigger : std::size_t { kEager = 0, kForced = 1, kEndOfPass = 2, kLazy = 3, kFlush = 4 };

}  // namespace

std::string_view to_string(UpdatePolicy p) noexcept { return enum_name(kUpdatePolicyNames, p); }

std::optional<UpdatePolicy> parse_update_policy(std::string_view s) noexcept {
  return parse_enum_name<UpdatePolicy>(kUpdatePolicyNames, s);
}

std::string_view to_string(QueryOutcome o) noexcept { return kOutcomeLabels[static_cast<std::size_t>(o)]; }

int texel_bytes(StorageFormat f) noexcept { return nbsim::storage_bytes(f); }

// ---------------------------------------------------------------------------------------------
// Configuration

void NBufferUnitConfig::describe(config::Schema& s, NBufferUnitConfig& c, const std::string& prefix) {
  c.key_prefix = prefix;
  const auto key = [&prefix](const char* field) { return prefix + "." + field; };
  s.add(key("resolution_divisor"), c.resolution_divisor, "",
        "levels are built over a reduced image whose texel is the farthest of a divisor x divisor block of depth "
        "pixels (conservative); 1, 2, 4 or 8",
        1, 8);
  s.add(key("format"), c.format, "level storage format, rounded toward far (u24 stored as 32-bit D24X8)",
        name_list(kStorageFormatNames));
  s.add(key("level_cap"), c.level_cap, "level",
        "highest level built, -1 builds all; larger rectangles are tiled with top-level squares", -1, kMaxLevelCap);
  s.add(key("capped_max_lookups"), c.capped_max_lookups, "lookups",
        "most lookups spent tiling a rectangle whose level is above level_cap; beyond, or 0, the query answers "
        "incomplete (never hidden)",
        0, kMaxCappedLookups);
  {
    std::vector<std::string> kinds{"trace"}, aligns{"trace"};
    for (std::string_view k : kCoveringKindNames) kinds.emplace_back(k);
    for (std::string_view a : kCoveringAlignNames) aligns.emplace_back(a);
    s.add(key("covering"), c.covering,
          "squares a query reads (Fig. 3): paper (the paper's five cases), corners (squares of side "
          "2^floor(log2 max(w, h)) at the corners), one (a single square); trace: the capture's",
          kinds);
    s.add(key("align"), c.align,
          "where a square taller than the rectangle sits: top (flush with its top edge, the paper's), bottom; trace: "
          "the capture's",
          aligns);
  }
  s.add(key("levels"), c.levels,
        "the levels' neighbourhoods: square (2^i x 2^i, the paper's N-buffer) or rect (2^i x 2^j, the paper's future "
        "work: every rectangle exact in at most four lookups, about log2(height) times the memory; the covering key "
        "does not apply, align does)",
        name_list(kLevelShapeNames));
  s.add(key("max_aspect_log2"), c.max_aspect_log2, "",
        "levels=rect: only the levels whose sides differ by at most 2^this (-1: all); thinner rectangles read taller ones",
        -1, kMaxAspectLog2);
  s.add(key("update_policy"), c.update_policy,
        "when depth changes reach the levels: eager (at once), batched (at the end of a pass), lazy (when a query "
        "reads them), on_demand (level 0 at once; a level texel computed when a query reads it, kept until a pixel under "
        "it changes; square levels only)",
        name_list(kUpdatePolicyNames));
  s.add(key("lookup_latency_cycles"), c.lookup_latency_cycles, "cycles",
        "latency of a query's lookups (address, tag check, data, compare) on cache hits", 0, kMaxLatencyCycles);
  s.add(key("lookups_per_cycle"), c.lookups_per_cycle, "lookups/cycle",
        "texel lookups the query port issues per cycle", kMinRate, kMaxLookupRate);
  s.add(key("update_texels_per_cycle"), c.update_texels_per_cycle, "texels/cycle",
        "texels the update engine recomputes per cycle", kMinRate, kMaxUpdateRate);
  s.add(key("update_latency_cycles"), c.update_latency_cycles, "cycles",
        "fill and drain latency of one batch of the update engine", 0, kMaxLatencyCycles);
  s.add(key("invalidations_per_cycle"), c.invalidations_per_cycle, "flags/cycle",
        "update_policy=on_demand: stale flags the update engine clears per cycle when a pixel under them changes",
        kMinRate, kMaxUpdateRate * 16);
  s.add(key("fast_clear"), c.fast_clear,
        "a depth clear tags every level's tiles cleared (no texel written, as a depth buffer's fast clear and the Hi-Z "
        "baselines' clear) instead of writing every level");
  s.add(key("level0"), c.level0,
        "level 0: copy (the paper's: the depth map copied into the levels, every change written again) or depth (the "
        "depth buffer is level 0, nothing copied; needs resolution_divisor 1 and format f32)",
        std::vector<std::string>{"copy", "depth"});
  s.add(key("dirty_tile"), c.dirty_tile, "texels",
        "update_policy batched or lazy: pending changes tracked per dirty_tile x dirty_tile tile of level-0 texels (1: a "
        "flag per texel); a dirty tile hands all its texels to the update engine; a power of two",
        1, kMaxDirtyTile);
  s.add(key("demand_levels"), c.demand_levels,
        "keep current only the levels up to the highest one the previous frame's queries needed (a frame runs from "
        "depth clear to depth clear); a query needing more tiles the highest kept level (capped_max_lookups)");
  s.add(key("demand_margin"), c.demand_margin, "levels", "demand_levels: levels kept above the previous frame's highest",
        0, kMaxLevelCap);
  s.add(key("cache_size_bytes"), c.cache.size_bytes, "bytes",
        "texel cache of the query port, a multiple of cache_line_bytes x cache_ways; 0 disables it", 0, kMaxCacheBytes);
  s.add(key("cache_line_bytes"), c.cache.line_bytes, "bytes",
        "cache line, also the memory burst of a miss and one tile of texels; a power of two", kMinLineBytes,
        kMaxLineBytes);
  s.add(key("cache_ways"), c.cache.ways, "ways", "associativity of the texel cache", 1, kMaxWays);
}

void NBufferUnitConfig::validate() const {
  auto bad = [](const std::string& msg) { throw InputError(msg); };
  if (resolution_divisor != 1 && resolution_divisor != 2 && resolution_divisor != 4 && resolution_divisor != 8)
    bad(fmt::format("{}.resolution_divisor must be 1, 2, 4 or 8, got {}", key_prefix, resolution_divisor));
  if (!parse_storage_format(format)) bad(fmt::format("{}.format must be one of f32, u24, u16, got '{}'", key_prefix, format));
  if (covering != "trace" && !parse_covering_kind(covering))
    bad(fmt::format("{}.covering must be one of trace, paper, corners, one, got '{}'", key_prefix, covering));
  if (align != "trace" && !parse_covering_align(align))
    bad(fmt::format("{}.align must be one of trace, top, bottom, got '{}'", key_prefix, align));
  if (!parse_enum_name<LevelShape>(kLevelShapeNames, levels))
    bad(fmt::format("{}.levels must be square or rect, got '{}'", key_prefix, levels));
  if (max_aspect_log2 == 0 || max_aspect_log2 < -1 || max_aspect_log2 > kMaxAspectLog2)
    bad(fmt::format("{}.max_aspect_log2 must be -1 (every rectangle level) or 1 to {}, got {} (0 would be the square levels: "
                    "{}.levels=square)",
                    key_prefix, kMaxAspectLog2, max_aspect_log2, key_prefix));
  if (levels == "rect" && level_cap != -1)
    bad(fmt::format("{}.levels=rect builds every level: {}.level_cap must be -1, got {}", key_prefix, key_prefix, level_cap));
  if (!parse_update_policy(update_policy))
    bad(fmt::format("{}.update_policy must be one of eager, batched, lazy, on_demand, got '{}'", key_prefix, update_policy));
  if (level0 != "copy" && level0 != "depth") bad(fmt::format("{}.level0 must be copy or depth, got '{}'", key_prefix, level0));
  if (level0 == "depth" && (resolution_divisor != 1 || format != "f32"))
    bad(fmt::format("{}.level0=depth reads the depth buffer as level 0: it needs {}.resolution_divisor=1 and {}.format=f32 (got {} "
                    "and {})",
                    key_prefix, key_prefix, key_prefix, resolution_divisor, format));
  if (update_policy == "on_demand" && levels == "rect")
    bad(fmt::format("{}.update_policy=on_demand computes square levels only: {}.levels must be square", key_prefix, key_prefix));
  if (dirty_tile < 1 || dirty_tile > kMaxDirtyTile || (dirty_tile & (dirty_tile - 1)) != 0)
    bad(fmt::format("{}.dirty_tile must be a power of two from 1 to {}, got {}", key_prefix, kMaxDirtyTile, dirty_tile));
  if (dirty_tile != 1 && update_policy != "batched" && update_policy != "lazy")
    bad(fmt::format("{}.dirty_tile={} tracks pending changes, which only update_policy batched or lazy keeps: {}.update_policy={} "
                    "needs {}.dirty_tile=1",
                    key_prefix, dirty_tile, key_prefix, update_policy, key_prefix));
  if (demand_levels && update_policy == "on_demand")
    bad(fmt::format("{}.demand_levels has nothing to cap under {}.update_policy=on_demand, which computes only the texels "
                    "queries read",
                    key_prefix, key_prefix));
  if (demand_levels && levels == "rect")
    bad(fmt::format("{}.levels=rect builds every level: {}.demand_levels must be false", key_prefix, key_prefix));
  if (demand_margin < 0 || demand_margin > kMaxLevelCap)
    bad(fmt::format("{}.demand_margin must be 0 to {}, got {}", key_prefix, kMaxLevelCap, demand_margin));
  if (level_cap < -1 || level_cap > kMaxLevelCap)
    bad(fmt::format("{}.level_cap must be -1 (all levels) or 0 to {}, got {}", key_prefix, kMaxLevelCap, level_cap));
  if (capped_max_lookups < 0 || capped_max_lookups > kMaxCappedLookups)
    bad(fmt::format("{}.capped_max_lookups must be 0 to {}, got {}", key_prefix, kMaxCappedLookups, capped_max_lookups));
  if (lookup_latency_cycles < 0 || lookup_latency_cycles > kMaxLatencyCycles)
    bad(fmt::format("{}.lookup_latency_cycles must be 0 to {}, got {}", key_prefix, kMaxLatencyCycles, lookup_latency_cycles));
  if (update_latency_cycles < 0 || update_latency_cycles > kMaxLatencyCycles)
    bad(fmt::format("{}.update_latency_cycles must be 0 to {}, got {}", key_prefix, kMaxLatencyCycles, update_latency_cycles));
  if (!std::isfinite(lookups_per_cycle) || lookups_per_cycle < kMinRate || lookups_per_cycle > kMaxLookupRate)
    bad(fmt::format("{}.lookups_per_cycle must be {} to {}, got {}", key_prefix, kMinRate, kMaxLookupRate, lookups_per_cycle));
  if (!std::isfinite(update_texels_per_cycle) || update_texels_per_cycle < kMinRate ||
      update_texels_per_cycle > kMaxUpdateRate)
    bad(fmt::format("{}.update_texels_per_cycle must be {} to {}, got {}", key_prefix, kMinRate, kMaxUpdateRate,
                    update_texels_per_cycle));
  if (!std::isfinite(invalidations_per_cycle) || invalidations_per_cycle < kMinRate || invalidations_per_cycle > kMaxUpdateRate * 16)
    bad(fmt::format("{}.invalidations_per_cycle must be {} to {}, got {}", key_prefix, kMinRate, kMaxUpdateRate * 16,
                    invalidations_per_cycle));
  const int line = cache.line_bytes;
  if (line < kMinLineBytes || line > kMaxLineBytes || (line & (line - 1)) != 0)
    bad(fmt::format("{}.cache_line_bytes must be a power of two from {} to {}, got {}", key_prefix, kMinLineBytes,
                    kMaxLineBytes, line));
  if (cache.ways < 1 || cache.ways > kMaxWays)
    bad(fmt::format("{}.cache_ways must be 1 to {}, got {}", key_prefix, kMaxWays, cache.ways));
  if (cache.size_bytes < 0 || cache.size_bytes > kMaxCacheBytes || cache.size_bytes % (line * cache.ways) != 0)
    bad(fmt::format(
        "{}.cache_size_bytes must be 0 or a multiple of cache_line_bytes x cache_ways = {} up to {}, got {}", key_prefix,
        line * cache.ways, kMaxCacheBytes, cache.size_bytes));
}

StorageFormat NBufferUnitConfig::storage_format() const {
  const auto f = parse_storage_format(format);
  NBSIM_CHECK(f.has_value(), "nbuffer config used before validate()");
  return *f;
}

CoveringSpec NBufferUnitConfig::covering_spec(CoveringSpec capture) const {
  CoveringSpec s = capture;
  s.direct_squares = direct_squares;
  if (covering != "trace") s.kind = *parse_covering_kind(covering);
  if (align != "trace") s.align = *parse_covering_align(align);
  return s;
}

LevelShape NBufferUnitConfig::shape() const {
  const auto s = parse_enum_name<LevelShape>(kLevelShapeNames, levels);
  NBSIM_CHECK(s.has_value(), "nbuffer config used before validate()");
  return *s;
}

UpdatePolicy NBufferUnitConfig::policy() const {
  const auto p = parse_update_policy(update_policy);
  NBSIM_CHECK(p.has_value(), "nbuffer config used before validate()");
  return *p;
}

// ---------------------------------------------------------------------------------------------
// Work

std::uint64_t UpdateWork::invalidated() const noexcept {
  std::uint64_t n = 0;
  for (auto v : texels_invalidated) n += v;
  return n;
}

std::uint64_t UpdateWork::engine_texels(double texels_per_cycle, double invalidations_per_cycle) const noexcept {
  const std::uint64_t flags = invalidated();
  if (flags == 0) return recomputed();
  return recomputed() + static_cast<std::uint64_t>(std::ceil(static_cast<double>(flags) * texels_per_cycle / invalidations_per_cycle));
}

std::uint64_t UpdateWork::recomputed() const noexcept {
  std::uint64_t n = 0;
  for (auto v : texels_recomputed) n += v;
  return n;
}

std::uint64_t UpdateWork::changed() const noexcept {
  std::uint64_t n = 0;
  for (auto v : texels_changed) n += v;
  return n;
}

UpdateWork& UpdateWork::operator+=(const UpdateWork& o) {
  auto add = [](std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
    if (a.size() < b.size()) a.resize(b.size(), 0);
    for (std::size_t i = 0; i < b.size(); ++i) a[i] += b[i];
  };
  add(texels_recomputed, o.texels_recomputed);
  add(texels_changed, o.texels_changed);
  add(texels_invalidated, o.texels_invalidated);
  depth_pixels_reduced += o.depth_pixels_reduced;
  bytes_read += o.bytes_read;
  bytes_written += o.bytes_written;
  return *this;
}

// ---------------------------------------------------------------------------------------------
// Core

NBufferUnitCore::NBufferUnitCore(const NBufferUnitConfig& config, int width_px, int height_px, FarOp op,
                                 stats::Group& g)
    : config_(validated(config)),
      op_(op),
      format_(config_.storage_format()),
      policy_(config_.policy()),
      covering_(config_.covering_spec()),
      divisor_(config_.resolution_divisor),
      depth_(checked_side(width_px, "width"), checked_side(height_px, "height"), far_limit(op)),
      reduced_(divisor_ > 1 ? DepthImage(ceil_div(width_px, divisor_), ceil_div(height_px, divisor_), far_limit(op))
                            : DepthImage()),
      nb_(ceil_div(width_px, divisor_), ceil_div(height_px, divisor_),
          NBufferConfig{op, format_, config_.level_cap, config_.shape(), config_.max_aspect_log2}),
      cache_(config_.cache),
      queries_(g.vector(
          "queries", "queries", "queries by outcome",
          {kOutcomeLabels[0].data(), kOutcomeLabels[1].data(), kOutcomeLabels[2].data(), kOutcomeLabels[3].data()})),
      cases_(
          g.vector("query_cases", "queries", "queries by the case of the covering they need (Fig. 3)", case_labels())),
      lookups_(g.vector("lookups", "lookups", "texels read by queries (depth tests of the query port), per level",
                        level_labels(nb_))),
      tiled_queries_(
          g.counter("tiled_queries", "queries", "queries whose level was capped, answered by tiling the top level")),
      hits_(g.counter("cache_hits", "lookups", "lookups that hit the texel cache")),
      misses_(g.counter("cache_misses", "lookups", "lookups that missed the texel cache")),
      bytes_read_(g.counter("bytes_read", "bytes",
                            "bytes read from memory: cache-line fills and level texels streamed by updates")),
      bytes_written_(g.counter("bytes_written", "bytes", "level texels written to memory by updates and clears")),
      recomputed_(g.vector("texels_recomputed", "texels", "texels the update engine recomputed, per level",
                           level_labels(nb_))),
      changed_(g.vector("texels_changed", "texels", "recomputed texels whose stored value changed, per level",
                        level_labels(nb_))),
      invalidated_(g.vector("texels_invalidated", "texels",
                            "update_policy=on_demand: level texels marked stale (a flag cleared), per level", level_labels(nb_))),
      reduced_pixels_(
          g.counter("depth_pixels_reduced", "pixels",
                    "depth pixels read to form reduced-resolution level-0 texels (resolution_divisor > 1)")),
      changes_(
          g.vector("depth_changes", "changes", "depth-buffer changes reported, by kind", {"rect", "writes", "clear"})),
      applied_(g.vector("texels_applied", "texels", "level-0 texels handed to the update engine, by what triggered it",
                        {"eager", "forced", "end_of_pass", "lazy", "flush"})),
      frames_(g.counter("frames", "frames", "frames ended")),
      fast_clears_(g.counter("fast_clears", "clears", "depth clears taken as a tag on every level (fast_clear): no texel written")),
      kept_levels_(g.counter("levels_kept", "levels", "levels kept current after each depth clear, summed over the clears")),
      demand_frames_(g.counter("level_frames", "clears", "depth clears after which the kept levels were chosen")) {
  g.formula("lookups_per_query", "lookups/query", "lookups per query that reached the levels", [this] {
    return stats::ratio(
        static_cast<double>(lookups_.total()),
        static_cast<double>(queries_.total() - queries_.value(static_cast<std::size_t>(QueryOutcome::Offscreen))));
  });
  g.formula("cache_hit_rate", "", "texel cache hits per lookup", [this] {
    return stats::ratio(static_cast<double>(hits_.value()), static_cast<double>(hits_.value() + misses_.value()));
  });
  g.formula("tracking_bits", "bits", "state kept to know what is stale (pending or current flags)",
            [this] { return static_cast<double>(tracking_bits()); });
  g.formula("levels_kept_per_frame", "levels", "levels kept current per depth clear (demand_levels)", [this] {
    return stats::ratio(static_cast<double>(kept_levels_.value()), static_cast<double>(demand_frames_.value()));
  });
  g.formula("hidden_fraction", "", "queries answered hidden per query", [this] {
    return stats::ratio(static_cast<double>(queries_.value(0)), static_cast<double>(queries_.total()));
  });

  // Memory layout: each level a plane of tiles, one tile per cache line (8x8 f32 texels for 256 B).
  const int per_line = std::max(1, config_.cache.line_bytes / texel_bytes(format_));
  const int lg = floor_log2(static_cast<unsigned>(per_line));
  tile_w_ = 1 << ((lg + 1) / 2);
  tile_h_ = 1 << (lg / 2);
  tiles_x_ = ceil_div(nb_.width(), tile_w_);
  tiles_y_ = ceil_div(nb_.height(), tile_h_);

  const std::size_t texels = static_cast<std::size_t>(nb_.width()) * static_cast<std::size_t>(nb_.height());
  pending_.assign(texels, 0);
  stamp_.assign(texels, 0);
  bins_x_ = ceil_div(nb_.width(), kBinPx);
  bins_y_ = ceil_div(nb_.height(), kBinPx);
  bins_.resize(static_cast<std::size_t>(bins_x_) * static_cast<std::size_t>(bins_y_));
  if (policy_ == UpdatePolicy::OnDemand) nb_.set_on_demand(true);
  dirty_tile_ = config_.dirty_tile;
  if (dirty_tile_ > 1) {
    dtiles_x_ = ceil_div(nb_.width(), dirty_tile_);
    dtiles_y_ = ceil_div(nb_.height(), dirty_tile_);
    tile_dirty_.assign(static_cast<std::size_t>(dtiles_x_) * static_cast<std::size_t>(dtiles_y_), 0);
  }
  kept_top_ = nb_.top_level();
}

std::uint64_t NBufferUnitCore::tracking_bits() const noexcept {
  const auto plane = static_cast<std::uint64_t>(nb_.width()) * static_cast<std::uint64_t>(nb_.height());
  switch (policy_) {
    case UpdatePolicy::Eager: return 0;
    case UpdatePolicy::OnDemand: return plane * static_cast<std::uint64_t>(nb_.level_count() - 1);
    default: return dirty_tile_ > 1 ? tile_dirty_.size() : plane;
  }
}

Rect NBufferUnitCore::to_reduced(const Rect& r) const noexcept {
  const Rect c = clip(r, depth_.width, depth_.height);
  if (c.empty()) return {};
  const int d = divisor_;
  const int x0 = c.x / d, y0 = c.y / d, x1 = ceil_div(c.x1(), d), y1 = ceil_div(c.y1(), d);
  return {x0, y0, x1 - x0, y1 - y0};
}

std::uint64_t NBufferUnitCore::texel_address(int level, int x, int y) const noexcept {
  const auto line = static_cast<std::uint64_t>(config_.cache.line_bytes);
  const auto tile = (static_cast<std::uint64_t>(level) * static_cast<std::uint64_t>(tiles_y_) +
                     static_cast<std::uint64_t>(y / tile_h_)) *
                        static_cast<std::uint64_t>(tiles_x_) +
                    static_cast<std::uint64_t>(x / tile_w_);
  const auto within = static_cast<std::uint64_t>((y % tile_h_) * tile_w_ + x % tile_w_);
  return tile * line + within * static_cast<std::uint64_t>(texel_bytes(format_));
}

UpdateWork NBufferUnitCore::new_work() const {
  UpdateWork w;
  w.texels_recomputed.assign(static_cast<std::size_t>(nb_.level_count()), 0);
  w.texels_changed.assign(static_cast<std::size_t>(nb_.level_count()), 0);
  w.texels_invalidated.assign(static_cast<std::size_t>(nb_.level_count()), 0);
  return w;
}

// Memory traffic of an update (a model, not a trace of accesses): level 0's changed texels are
// written (their values come from the depth unit, which forwards the tiles it writes); a level
// above reads one new source texel per recomputed texel (the other three taps come from the line
// buffer of the rows it streams) and writes the texels that changed.
void NBufferUnitCore::account(const UpdateStats& s, UpdateWork& w) {
  const auto bpt = static_cast<std::uint64_t>(texel_bytes(format_));
  const bool shared_level0 = config_.level0 == "depth";  // level 0 is the depth buffer: no copy to write
  const std::size_t kept = std::min(s.texels_recomputed.size(), static_cast<std::size_t>(kept_top_) + 1);
  for (std::size_t i = 0; i < kept; ++i) {  // levels above the kept ones are not maintained (demand_levels)
    if (i == 0 && shared_level0) continue;
    const auto rec = static_cast<std::uint64_t>(s.texels_recomputed[i]);
    const auto chg = static_cast<std::uint64_t>(s.texels_changed[i]);
    w.texels_recomputed[i] += rec;
    w.texels_changed[i] += chg;
    recomputed_.add(i, rec);
    changed_.add(i, chg);
    if (i < s.texels_invalidated.size()) {
      const auto inv = static_cast<std::uint64_t>(s.texels_invalidated[i]);
      w.texels_invalidated[i] += inv;
      invalidated_.add(i, inv);
    }
    const std::uint64_t rd = i > 0 ? rec * bpt : 0, wr = chg * bpt;
    w.bytes_read += rd;
    w.bytes_written += wr;
    bytes_read_ += rd;
    bytes_written_ += wr;
  }
}

void NBufferUnitCore::reduce_block(int rx, int ry, UpdateWork& w) {
  const int d = divisor_;
  const int x1 = std::min((rx + 1) * d, depth_.width), y1 = std::min((ry + 1) * d, depth_.height);
  float v = neutral_depth(op_);
  for (int y = ry * d; y < y1; ++y)
    for (int x = rx * d; x < x1; ++x) v = farther(op_, v, depth_.at(x, y));
  reduced_.at(rx, ry) = v;
  w.depth_pixels_reduced += static_cast<std::uint64_t>(x1 - rx * d) * static_cast<std::uint64_t>(y1 - ry * d);
}

std::uint64_t NBufferUnitCore::tile_area(int tx, int ty) const noexcept {
  const int w = std::min(dirty_tile_, nb_.width() - tx * dirty_tile_), h = std::min(dirty_tile_, nb_.height() - ty * dirty_tile_);
  return static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
}

void NBufferUnitCore::mark_tile(int x, int y) {
  const int tx = x / dirty_tile_, ty = y / dirty_tile_;
  std::uint8_t& f = tile_dirty_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(dtiles_x_) + static_cast<std::size_t>(tx)];
  if (f) return;
  f = 1;
  pending_count_ += tile_area(tx, ty);
}

void NBufferUnitCore::take_tile(int tx, int ty, std::vector<Texel>& take) {
  std::uint8_t& f = tile_dirty_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(dtiles_x_) + static_cast<std::size_t>(tx)];
  if (!f) return;
  f = 0;
  pending_count_ -= tile_area(tx, ty);
  const int x1 = std::min((tx + 1) * dirty_tile_, nb_.width()), y1 = std::min((ty + 1) * dirty_tile_, nb_.height());
  for (int y = ty * dirty_tile_; y < y1; ++y)
    for (int x = tx * dirty_tile_; x < x1; ++x) take.push_back({x, y});
}

UpdateWork NBufferUnitCore::apply_tiles(const Rect& r) {
  std::vector<Texel> take;
  const int tx1 = (r.x1() - 1) / dirty_tile_, ty1 = (r.y1() - 1) / dirty_tile_;
  for (int ty = r.y / dirty_tile_; ty <= ty1; ++ty)
    for (int tx = r.x / dirty_tile_; tx <= tx1; ++tx) take_tile(tx, ty, take);
  return apply_writes(take);
}

void NBufferUnitCore::mark_one(int x, int y) {
  if (dirty_tile_ > 1) return mark_tile(x, y);
  const std::size_t k =
      static_cast<std::size_t>(y) * static_cast<std::size_t>(nb_.width()) + static_cast<std::size_t>(x);
  if (pending_[k]) return;
  pending_[k] = 1;
  ++pending_count_;
  const int bx = x / kBinPx, by = y / kBinPx;
  std::vector<Texel>& bin =
      bins_[static_cast<std::size_t>(by) * static_cast<std::size_t>(bins_x_) + static_cast<std::size_t>(bx)];
  if (bin.size() >= 2 * static_cast<std::size_t>(kBinPx * kBinPx)) {
    // Entries unmarked since (forced applies) piled up: rebuild the list from the flags.
    bin.clear();
    const int x1 = std::min((bx + 1) * kBinPx, nb_.width()), y1 = std::min((by + 1) * kBinPx, nb_.height());
    for (int ty = by * kBinPx; ty < y1; ++ty)
      for (int tx = bx * kBinPx; tx < x1; ++tx)
        if (pending_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(nb_.width()) +
                     static_cast<std::size_t>(tx)])
          bin.push_back({tx, ty});
    return;  // (x, y) is flagged, so the rebuilt list holds it
  }
  bin.push_back({x, y});
}

bool NBufferUnitCore::mark(const Rect& rr) {
  const DepthImage& src = level0_source();
  bool raises = false;
  for (int y = rr.y; y < rr.y1(); ++y)
    for (int x = rr.x; x < rr.x1(); ++x) {
      const float v = stored(src.at(x, y)), held = nb_.texel(0, x, y);
      if (v == held) continue;
      raises = raises || hidden_behind(op_, v, held);  // v strictly farther than what level 0 holds
      mark_one(x, y);
    }
  return raises;
}

bool NBufferUnitCore::mark(std::span<const Texel> texels) {
  const DepthImage& src = level0_source();
  bool raises = false;
  for (const Texel& t : texels) {
    const float v = stored(src.at(t.x, t.y)), held = nb_.texel(0, t.x, t.y);
    if (v == held) continue;
    raises = raises || hidden_behind(op_, v, held);
    mark_one(t.x, t.y);
  }
  return raises;
}

void NBufferUnitCore::unmark(const Rect& rr) {
  for (int y = rr.y; y < rr.y1(); ++y)
    for (int x = rr.x; x < rr.x1(); ++x) {
      std::uint8_t& p =
          pending_[static_cast<std::size_t>(y) * static_cast<std::size_t>(nb_.width()) + static_cast<std::size_t>(x)];
      if (p) p = 0, --pending_count_;
    }
}

void NBufferUnitCore::unmark(std::span<const Texel> texels) {
  for (const Texel& t : texels) {
    std::uint8_t& p =
        pending_[static_cast<std::size_t>(t.y) * static_cast<std::size_t>(nb_.width()) + static_cast<std::size_t>(t.x)];
    if (p) p = 0, --pending_count_;
  }
}

UpdateWork NBufferUnitCore::apply_writes(std::span<const Texel> texels) {
  UpdateWork w = new_work();
  if (texels.empty()) return w;
  const DepthImage& src = level0_source();
  writes_.clear();
  for (const Texel& t : texels) writes_.push_back({t.x, t.y, src.at(t.x, t.y)});
  account(nb_.update(writes_), w);
  return w;
}

UpdateWork NBufferUnitCore::apply_pending(const Rect& region) {
  const Rect r = clip(region, nb_.width(), nb_.height());
  if (r.empty() || pending_count_ == 0) return new_work();
  if (dirty_tile_ > 1) return apply_tiles(r);
  std::vector<Texel> take;
  const int bx1 = (r.x1() - 1) / kBinPx, by1 = (r.y1() - 1) / kBinPx;
  for (int by = r.y / kBinPx; by <= by1; ++by)
    for (int bx = r.x / kBinPx; bx <= bx1; ++bx) {
      auto& bin =
          bins_[static_cast<std::size_t>(by) * static_cast<std::size_t>(bins_x_) + static_cast<std::size_t>(bx)];
      for (const Texel& t : bin) {
        std::uint8_t& p = pending_[static_cast<std::size_t>(t.y) * static_cast<std::size_t>(nb_.width()) +
                                   static_cast<std::size_t>(t.x)];
        if (p) p = 0, --pending_count_, take.push_back(t);
      }
      bin.clear();
    }
  return apply_writes(take);
}

UpdateWork NBufferUnitCore::depth_changed(const DepthImage& depth, const Rect& dirty) {
  NBSIM_CHECK(depth.width == depth_.width && depth.height == depth_.height,
              "depth image handed to the N-buffer unit differs from its depth buffer size");
  changes_.add(0);
  UpdateWork w = new_work();
  const Rect c = clip(dirty, depth_.width, depth_.height);
  if (c.empty()) return w;
  if (&depth != &depth_)
    for (int y = c.y; y < c.y1(); ++y) {
      const auto row = static_cast<std::size_t>(y) * static_cast<std::size_t>(depth_.width);
      std::copy(depth.texels.begin() + static_cast<std::ptrdiff_t>(row + static_cast<std::size_t>(c.x)),
                depth.texels.begin() + static_cast<std::ptrdiff_t>(row + static_cast<std::size_t>(c.x1())),
                depth_.texels.begin() + static_cast<std::ptrdiff_t>(row + static_cast<std::size_t>(c.x)));
    }
  const Rect rr = to_reduced(c);
  if (divisor_ > 1)
    for (int y = rr.y; y < rr.y1(); ++y)
      for (int x = rr.x; x < rr.x1(); ++x) reduce_block(x, y, w);
  reduced_pixels_ += w.depth_pixels_reduced;

  const auto area = static_cast<std::uint64_t>(rr.area());
  if (policy_ == UpdatePolicy::Eager || policy_ == UpdatePolicy::OnDemand) {
    account(nb_.update(level0_source(), rr), w);
    applied_.add(kEager, area);
  } else if (mark(rr) && policy_ == UpdatePolicy::Batched) {
    if (dirty_tile_ > 1) {
      const std::uint64_t before = pending_count_;
      w += apply_tiles(rr);  // the dirty tiles the rectangle meets, which hold every texel it changed
      applied_.add(kForced, before - pending_count_);
    } else {
      unmark(rr);  // the rectangle is applied whole, its pending texels with it
      account(nb_.update(level0_source(), rr), w);
      applied_.add(kForced, area);
    }
  }
  return w;
}

UpdateWork NBufferUnitCore::depth_changed(std::span<const PixelWrite> writes) {
  for (const PixelWrite& pw : writes)
    if (pw.x < 0 || pw.y < 0 || pw.x >= depth_.width || pw.y >= depth_.height)
      throw InputError(fmt::format("N-buffer unit: pixel write at ({}, {}) outside the {}x{} depth buffer", pw.x, pw.y,
                                   depth_.width, depth_.height));
  changes_.add(1);
  UpdateWork w = new_work();
  // The distinct storage texels the writes fall in.
  if (++epoch_ == 0) std::fill(stamp_.begin(), stamp_.end(), 0u), epoch_ = 1;
  scratch_.clear();
  for (const PixelWrite& pw : writes) {
    depth_.at(pw.x, pw.y) = pw.depth;
    const int x = pw.x / divisor_, y = pw.y / divisor_;
    std::uint32_t& s =
        stamp_[static_cast<std::size_t>(y) * static_cast<std::size_t>(nb_.width()) + static_cast<std::size_t>(x)];
    if (s != epoch_) s = epoch_, scratch_.push_back({x, y});
  }
  if (divisor_ > 1)
    for (const Texel& t : scratch_) reduce_block(t.x, t.y, w);
  reduced_pixels_ += w.depth_pixels_reduced;

  if (policy_ == UpdatePolicy::Eager || policy_ == UpdatePolicy::OnDemand) {
    w += apply_writes(scratch_);
    applied_.add(kEager, scratch_.size());
  } else if (mark(scratch_) && policy_ == UpdatePolicy::Batched) {
    if (dirty_tile_ > 1) {
      const std::uint64_t before = pending_count_;
      std::vector<Texel> take;  // the written texels' dirty tiles, applied as one batch
      for (const Texel& t : scratch_) take_tile(t.x / dirty_tile_, t.y / dirty_tile_, take);
      w += apply_writes(take);
      applied_.add(kForced, before - pending_count_);
    } else {
      unmark(scratch_);
      w += apply_writes(scratch_);
      applied_.add(kForced, scratch_.size());
    }
  }
  return w;
}

UpdateWork NBufferUnitCore::depth_cleared(float depth) {
  changes_.add(2);
  std::fill(depth_.texels.begin(), depth_.texels.end(), depth);
  if (divisor_ > 1) std::fill(reduced_.texels.begin(), reduced_.texels.end(), depth);
  std::fill(pending_.begin(), pending_.end(), std::uint8_t{0});
  for (auto& bin : bins_) bin.clear();
  std::fill(tile_dirty_.begin(), tile_dirty_.end(), std::uint8_t{0});
  pending_count_ = 0;
  nb_.build(level0_source());
  // A frame ends at a clear: the next keeps the levels this one's queries needed (none asked: as
  // they were). The clear below writes exactly those levels, so a level kept again costs its clear.
  if (config_.demand_levels && demand_seen_ >= 0)
    kept_top_ = std::min(nb_.top_level(), demand_seen_ + config_.demand_margin);
  demand_seen_ = -1;
  kept_levels_ += static_cast<std::uint64_t>(kept_top_) + 1;
  ++demand_frames_;
  // Every texel of every level takes the clear value (each square holds its in-image anchor), so
  // a clear writes all levels without reading any; a fast clear tags them instead (no work).
  UpdateWork w = new_work();
  if (config_.fast_clear) {
    ++fast_clears_;
    return w;
  }
  const auto plane = static_cast<std::uint64_t>(nb_.width()) * static_cast<std::uint64_t>(nb_.height());
  const std::size_t first = config_.level0 == "depth" ? 1 : 0;  // the depth buffer clears level 0 itself
  const std::size_t end = static_cast<std::size_t>(kept_top_) + 1;  // demand_levels: the kept levels only
  for (std::size_t i = first; i < end; ++i) {
    w.texels_recomputed[i] = w.texels_changed[i] = plane;
    recomputed_.add(i, plane);
    changed_.add(i, plane);
  }
  w.bytes_written = plane * (end - first) * static_cast<std::uint64_t>(texel_bytes(format_));
  bytes_written_ += w.bytes_written;
  return w;
}

UpdateWork NBufferUnitCore::end_of_pass() {
  if (policy_ != UpdatePolicy::Batched) return new_work();
  const std::uint64_t before = pending_count_;
  UpdateWork w = apply_pending({0, 0, nb_.width(), nb_.height()});
  applied_.add(kEndOfPass, before);
  return w;
}

UpdateWork NBufferUnitCore::end_of_frame() {
  ++frames_;
  return end_of_pass();
}

UpdateWork NBufferUnitCore::flush() {
  if (policy_ == UpdatePolicy::OnDemand) {  // every stale texel computed
    UpdateStats st = nb_.new_stats();
    nb_.ensure_all(st);
    UpdateWork w = new_work();
    account(st, w);
    return w;
  }
  const std::uint64_t before = pending_count_;
  UpdateWork w = apply_pending({0, 0, nb_.width(), nb_.height()});
  applied_.add(kFlush, before);
  return w;
}

void NBufferUnitCore::read_texel(QueryAnswer& a, int level, int x, int y) {
  a.value = farther(op_, a.value, nb_.texel(level, x, y));
  if (a.texel_count < 4) a.texels[static_cast<std::size_t>(a.texel_count++)] = {x, y};
  ++a.lookups;
  if (cache_.access(texel_address(level, x, y), false).hit) {
    ++a.cache_hits;
  } else {
    ++a.cache_misses;
    a.bytes_read += static_cast<std::uint64_t>(config_.cache.line_bytes);
  }
}

QueryAnswer NBufferUnitCore::query(const Rect& r, float nearest_depth) {
  QueryAnswer a;
  a.value = far_limit(op_);
  auto done = [&](QueryOutcome o) {
    a.outcome = o;
    a.hidden = o == QueryOutcome::Hidden;
    queries_.add(static_cast<std::size_t>(o));
    return a;
  };
  const Rect rr = to_reduced(r);  // empty when r is empty or off the image
  if (rr.empty()) return done(QueryOutcome::Offscreen);
  a.reduced = rr;
  const Covering cov = nb_.covering(rr, covering_);
  a.kase = cov.kase;
  a.level = cov.level;
  cases_.add(static_cast<std::size_t>(cov.kase));
  demand_seen_ = std::max(demand_seen_, cov.level);

  if (cov.level <= kept_top_) {
    if (policy_ == UpdatePolicy::Lazy) {
      int x0 = cov.squares[0].x, y0 = cov.squares[0].y, x1 = x0, y1 = y0;
      for (int i = 1; i < cov.count; ++i) {
        const Square& s = cov.squares[static_cast<std::size_t>(i)];
        x0 = std::min(x0, s.x), y0 = std::min(y0, s.y), x1 = std::max(x1, s.x), y1 = std::max(y1, s.y);
      }
      a.update = apply_pending({x0, y0, x1 - x0 + cov.width_px(), y1 - y0 + cov.height_px()});
    }
    if (policy_ == UpdatePolicy::OnDemand) {
      UpdateStats st = nb_.new_stats();
      for (int i = 0; i < cov.count; ++i)
        nb_.ensure(cov.level, cov.squares[static_cast<std::size_t>(i)].x, cov.squares[static_cast<std::size_t>(i)].y, st);
      a.update = new_work();
      account(st, a.update);
    }
    const QueryResult q = nb_.query(rr, covering_);
    NBSIM_CHECK(q.complete && q.level == cov.level, "N-buffer query read another level than its covering");
    a.value = neutral_depth(op_);
    for (const Texel& t : q.read()) read_texel(a, q.level, t.x, t.y);
    NBSIM_CHECK(a.value == q.value, "N-buffer unit's lookups disagree with the N-buffer's answer");
  } else {
    // The level needed is above level_cap or the kept levels (demand_levels): tile the rectangle
    // with top-level squares anchored at its left/bottom edge every S pixels and once more flush with its right/top edge (a rectangle
    // less tall than S: one row, flush with its top edge under the top alignment, as a covering).
    const int top = kept_top_, side = 1 << top;
    const long long nx = rr.w > side ? ceil_div(rr.w, side) : 1, ny = rr.h > side ? ceil_div(rr.h, side) : 1;
    if (nx * ny > config_.capped_max_lookups) {
      a.complete = false;
      return done(QueryOutcome::Incomplete);
    }
    // The first row's y: the rectangle's bottom, or (one row less tall than S, top alignment)
    // flush with its top edge, moved up to 0 where that would start below the image.
    const int row_y = rr.h < side && covering_.align == CoveringAlign::Top ? std::max(0, rr.y1() - side) : rr.y;
    a.tiled = true;
    a.level = top;
    ++tiled_queries_;
    if (policy_ == UpdatePolicy::Lazy)
      a.update = apply_pending({rr.x, row_y, std::max(rr.w, side), std::max(rr.h, side)});
    UpdateStats st = nb_.new_stats();
    if (policy_ == UpdatePolicy::OnDemand) a.update = new_work();
    a.value = neutral_depth(op_);
    for (long long j = 0; j < ny; ++j) {
      const int y = j + 1 < ny ? rr.y + static_cast<int>(j) * side : ny == 1 ? row_y : rr.y1() - side;
      for (long long i = 0; i < nx; ++i) {
        const int x = i + 1 < nx ? rr.x + static_cast<int>(i) * side : std::max(rr.x, rr.x1() - side);
        nb_.ensure(top, x, y, st);
        read_texel(a, top, x, y);
      }
    }
    if (policy_ == UpdatePolicy::OnDemand) account(st, a.update);
  }
  if (policy_ == UpdatePolicy::Lazy)
    applied_.add(kLazy, a.update.texels_recomputed.empty() ? 0 : a.update.texels_recomputed[0]);
  lookups_.add(static_cast<std::size_t>(a.level), static_cast<std::uint64_t>(a.lookups));
  hits_ += a.cache_hits;
  misses_ += a.cache_misses;
  bytes_read_ += a.bytes_read;
  return done(hidden_behind(op_, nearest_depth, a.value) ? QueryOutcome::Hidden : QueryOutcome::Visible);
}

}  // namespace nbsim::nbuffer
