// A depth-query structure: what a frame program asks "is this screen rectangle hidden behind
// everything drawn so far?" (the N-buffer unit, a tile Hi-Z, a Hi-Z pyramid). Structures are named
// units that the top level builds from configuration (pipeline/sim/programs.h: one row per
// instance, each instance with its own config keys) and hands to the program that owns them; a
// program may own several (a min and a max N-buffer over a light-view image are two instances).
// The depth unit's changes reach a structure through its owner; every call below runs on the
// caller's SystemC thread and spends the structure's time there (model/sim/unit.h).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "model/common/rect.h"
#include "model/common/storage.h"

namespace nbsim::query {

// Kinds of structure. Fixed values (they may end up in run outputs).
enum class Kind : std::uint8_t { NBuffer = 0, TileHiZ = 1, HiZPyramid = 2 };
// Names of Kind, indexed by its value (model/common/names.h).
inline constexpr std::array<std::string_view, 3> kKindNames = {"nbuffer", "hiz_tile", "hiz_pyramid"};
std::string_view to_string(Kind k) noexcept;

// The answer to one query.
struct Answer {
  bool hidden = false;             // the rectangle's nearest depth is strictly farther than all it read
  std::uint64_t lookups = 0;       // texels compared against (the query's depth tests)
  std::uint64_t update_texels = 0; // texels brought up to date for this query (lazy N-buffer updates)
};

class Structure {
 public:
  virtual ~Structure() = default;
  virtual Kind structure_kind() const noexcept = 0;  // (sc_object has a kind() of its own)
  virtual FarOp op() const noexcept = 0;
  // Bytes its storage occupies in memory.
  virtual long long storage_bytes() const noexcept = 0;

  // The whole depth buffer was cleared to `depth`: returns texels filled by the (fast) clear.
  virtual std::uint64_t cleared(float depth) = 0;
  // The pixels of `depth` inside `dirty` changed: returns texels recomputed (or to recompute).
  virtual std::uint64_t changed(const DepthImage& depth, const Rect& dirty) = 0;
  // Queries come next (the end of a pass): brings the structure up to date with `depth` and
  // spends the time that takes; returns the texels recomputed now that changed() did not count.
  virtual std::uint64_t prepare(const DepthImage& depth) = 0;

  // One query: blocking, from an SC_THREAD. Off-screen and near-crossing rectangles are the
  // caller's to decide; r must be non-empty.
  virtual Answer query(const Rect& r, float nearest_depth) = 0;
  // A batch of queries (rects[i] with nearest[i]) as one pipelined stream: one latency for the
  // batch. Answers in order into `answers`.
  virtual void query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) = 0;
};

}  // namespace nbsim::query
