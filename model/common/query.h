// The answer of a depth-map query (N-buffer or Hi-Z): the value, the level read and the texels
// read, in that level's coordinates. Handed from the query units to culling and statistics.
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace nbsim {

struct Texel {
  int x = 0;
  int y = 0;
  friend bool operator==(const Texel&, const Texel&) = default;
};

struct QueryResult {
  float value = 0.0f;   // conservative farthest depth of the queried rectangle
  int level = 0;        // level whose texels were read (the level needed, when !complete)
  int texel_count = 0;  // number of lookups, at most 4
  std::array<Texel, 4> texels{};
  bool complete = true;  // false: the level needed was not built; value is the far limit

  std::span<const Texel> read() const noexcept { return {texels.data(), static_cast<std::size_t>(texel_count)}; }
};

}  // namespace nbsim
