// The heightfield of model/relief (heightfield.h states the conventions): its checks, the bilinear
// surface in double (the reference's and the safety radius's surface) and the procedural fields.
// The generators draw their randomness from their own splitmix64 hash, so a (kind, size, param,
// seed) gives the same heights with every standard library.
#include "model/relief/heightfield.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "model/common/error.h"

namespace nbsim::relief {

std::string heightfield_problem(const Heightfield& field) {
  const int n = field.size;
  if (n < kMinSize || n > kMaxSize) return fmt::format("size {} is not supported ({} to {})", n, kMinSize, kMaxSize);
  const std::size_t needed = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (field.heights.size() != needed)
    return fmt::format("has {} heights, but {} x {} needs {}", field.heights.size(), n, n, needed);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const float h = field.heights[static_cast<std::size_t>(j) * n + i];
      if (std::isnan(h)) return fmt::format("texel ({}, {}) is NaN", i, j);
      if (!(h >= 0.0f && h <= 1.0f)) return fmt::format("texel ({}, {}) is {}, outside [0, 1]", i, j, h);
    }
  }
  return {};
}

void check_heightfield(const Heightfield& field, std::string_view what) {
  if (std::string problem = heightfield_problem(field); !problem.empty())
    throw InputError(fmt::format("{}: {}", what, problem));
}

double surface_height(const Heightfield& field, double x, double y) noexcept {
  if (std::isnan(x) || std::isnan(y)) return std::numeric_limits<double>::quiet_NaN();
  // Cell coordinates: cell (ci, cj) is [ci, ci + 1] x [cj, cj + 1] here. Far outside the field
  // every texel is virtual (0), so clamping keeps the index in int range without changing a height.
  const double n = field.size;
  const double cx = std::clamp(x - 0.5, -2.0, n + 1.0);
  const double cy = std::clamp(y - 0.5, -2.0, n + 1.0);
  const double fx = std::floor(cx), fy = std::floor(cy);
  const int ci = static_cast<int>(fx), cj = static_cast<int>(fy);
  const double u = cx - fx, v = cy - fy;
  const double h00 = field.at(ci, cj), h10 = field.at(ci + 1, cj);
  const double h01 = field.at(ci, cj + 1), h11 = field.at(ci + 1, cj + 1);
  return (1.0 - v) * ((1.0 - u) * h00 + u * h10) + v * ((1.0 - u) * h01 + u * h11);
}

namespace {

// splitmix64 (Steele, Lea and Flood 2014): a full-period 64-bit generator whose output function
// also serves as a hash of (seed, coordinates).
std::uint64_t mix64(std::uint64_t z) noexcept {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() noexcept { return mix64(state += 0x9E3779B97F4A7C15ull); }
  // In [0, bound) (bound >= 1); the modulo's bias (below 2^-40 for any field size) does not matter here.
  std::uint64_t below(std::uint64_t bound) noexcept { return next() % bound; }
};

// A value in [0, 1) for the lattice point (x, y) of one octave.
double lattice_value(std::uint64_t seed, int octave, int x, int y) noexcept {
  std::uint64_t h = mix64(seed ^ 0x243F6A8885A308D3ull);
  h = mix64(h ^ static_cast<std::uint64_t>(octave));
  h = mix64(h ^ static_cast<std::uint32_t>(x));
  h = mix64(h ^ (static_cast<std::uint64_t>(static_cast<std::uint32_t>(y)) << 32));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

Heightfield blank(int size, float height) {
  Heightfield f;
  f.size = size;
  f.heights.assign(static_cast<std::size_t>(size) * static_cast<std::size_t>(size), height);
  return f;
}

float& texel(Heightfield& f, int i, int j) { return f.heights[static_cast<std::size_t>(j) * f.size + i]; }

// Fixed by the design: the largest fbm height (headroom under the box's top at z = 1).
constexpr double kFbmTop = 0.9;

Heightfield make_fbm(int size, int param, std::uint64_t seed) {
  const int octaves = param == 0 ? 6 : param;
  if (octaves < 1 || octaves > 12) throw InputError(fmt::format("fbm: octaves (param) must be 1 to 12 (0: 6), got {}", param));
  // Octave k: value noise on a lattice of period N / 2^(k+1) texels (at least 1), amplitude 2^-k,
  // interpolated with the smoothstep weights between lattice points.
  std::vector<double> sum(static_cast<std::size_t>(size) * static_cast<std::size_t>(size), 0.0);
  for (int k = 0; k < octaves; ++k) {
    const double period = std::max(1.0, static_cast<double>(size) / std::ldexp(1.0, k + 1));
    const double amplitude = std::ldexp(1.0, -k);
    for (int j = 0; j < size; ++j) {
      for (int i = 0; i < size; ++i) {
        const double x = (i + 0.5) / period, y = (j + 0.5) / period;
        const double fx = std::floor(x), fy = std::floor(y);
        const int xi = static_cast<int>(fx), yi = static_cast<int>(fy);
        double u = x - fx, v = y - fy;
        u = u * u * (3.0 - 2.0 * u);
        v = v * v * (3.0 - 2.0 * v);
        const double a = lattice_value(seed, k, xi, yi), b = lattice_value(seed, k, xi + 1, yi);
        const double c = lattice_value(seed, k, xi, yi + 1), d = lattice_value(seed, k, xi + 1, yi + 1);
        sum[static_cast<std::size_t>(j) * size + i] += amplitude * ((1.0 - v) * ((1.0 - u) * a + u * b) + v * ((1.0 - u) * c + u * d));
      }
    }
  }
  // Stretch the sum's range onto [0, kFbmTop] (a flat sum, impossible in practice, becomes kFbmTop / 2).
  const auto [lo, hi] = std::minmax_element(sum.begin(), sum.end());
  const double low = *lo, range = *hi - *lo;
  Heightfield f = blank(size, 0.0f);
  for (std::size_t t = 0; t < sum.size(); ++t) {
    const double h = range > 0.0 ? (sum[t] - low) / range * kFbmTop : kFbmTop / 2.0;
    f.heights[t] = std::clamp(static_cast<float>(h), 0.0f, static_cast<float>(kFbmTop));
  }
  return f;
}

Heightfield make_walls(int size, int param, std::uint64_t) {
  const int every = param == 0 ? 8 : param;
  if (every < 2 || every > kMaxSize)
    throw InputError(fmt::format("walls: the spacing (param) must be 2 to {} (0: 8), got {}", kMaxSize, param));
  // The walls sit on the columns and rows i with i % every == every / 2, so the field's edge is
  // floor unless the spacing is 2 or 3 (and a field smaller than every / 2 is all floor).
  Heightfield f = blank(size, 0.0f);
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i)
      if (i % every == every / 2 || j % every == every / 2) texel(f, i, j) = 1.0f;
  return f;
}

// Fixed by the design: the spikes' floor (above 0, so the border's drop to 0 is a feature too).
constexpr float kSpikeFloor = 0.1f;

Heightfield make_spikes(int size, int param, std::uint64_t seed) {
  const long long texels = static_cast<long long>(size) * size;
  const long long count = param == 0 ? std::max(1, size / 4) : param;
  if (count < 1 || count > texels)
    throw InputError(fmt::format("spikes: the count (param) must be 1 to {} (0: N / 4), got {}", texels, param));
  // Distinct texels: the first `count` entries of a partial Fisher-Yates shuffle.
  std::vector<std::uint32_t> order(static_cast<std::size_t>(texels));
  std::iota(order.begin(), order.end(), 0u);
  SplitMix64 rng{seed};
  Heightfield f = blank(size, kSpikeFloor);
  for (long long t = 0; t < count; ++t) {
    const auto pick = static_cast<std::size_t>(t) + rng.below(static_cast<std::uint64_t>(texels - t));
    std::swap(order[static_cast<std::size_t>(t)], order[pick]);
    f.heights[order[static_cast<std::size_t>(t)]] = 1.0f;
  }
  return f;
}

Heightfield make_saddle(int size, int, std::uint64_t) {
  // Texels (m - 1, m - 1) and (m, m) at 0, (m, m - 1) and (m - 1, m) at 1: cell (m - 1, m - 1) is
  // the saddle patch.
  Heightfield f = blank(size, 0.0f);
  const int m = size / 2;
  texel(f, m, m - 1) = 1.0f;
  texel(f, m - 1, m) = 1.0f;
  return f;
}

Heightfield make_step(int size, int, std::uint64_t) {
  Heightfield f = blank(size, 0.0f);
  for (int j = 0; j < size; ++j)
    for (int i = size / 2; i < size; ++i) texel(f, i, j) = 1.0f;
  return f;
}

struct Generator {
  std::string_view name;
  Heightfield (*make)(int size, int param, std::uint64_t seed);
};

// One row per kind (heightfield.h describes each).
constexpr std::array<Generator, 5> kGenerators = {{
    {"fbm", make_fbm},
    {"walls", make_walls},
    {"spikes", make_spikes},
    {"saddle", make_saddle},
    {"step", make_step},
}};

}  // namespace

Heightfield make_heightfield(std::string_view kind, int size, int param, std::uint64_t seed) {
  const auto row = std::find_if(kGenerators.begin(), kGenerators.end(), [&](const Generator& g) { return g.name == kind; });
  if (row == kGenerators.end())
    throw InputError(fmt::format("unknown heightfield kind '{}' (one of {})", kind, fmt::join(heightfield_kinds(), ", ")));
  if (size < kMinSize || size > kMaxSize)
    throw InputError(fmt::format("{}: size {} is not supported ({} to {})", kind, size, kMinSize, kMaxSize));
  Heightfield f = row->make(size, param, seed);
  NBSIM_CHECK(heightfield_problem(f).empty(), fmt::format("generator {} made an invalid field: {}", kind, heightfield_problem(f)));
  return f;
}

const std::vector<std::string_view>& heightfield_kinds() {
  static const std::vector<std::string_view> kinds = [] {
    std::vector<std::string_view> names;
    for (const Generator& g : kGenerators) names.push_back(g.name);
    return names;
  }();
  return kinds;
}

}  // namespace nbsim::relief
