// Seeded random LDIs for the ldi tests: depths on a 1/16 grid so that layers tie with each other
// and with test points, odd and even layer counts, empty texels around and inside the crop,
// trailing unused layers, and the edge depths 0, -0.0 and 1.0.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "model/ldi/ldi.h"

namespace nbsim::ldi::test_support {

inline constexpr int kGrid = 16;  // depths are multiples of 1/kGrid

class RandomLdi {
 public:
  explicit RandomLdi(std::uint32_t seed) : rng_(seed) {}
  // Below: a uniform integer in [0, n) from the raw engine (std distributions differ across
  // standard libraries; mt19937's output does not).
  int below(int n) { return static_cast<int>(rng_() % static_cast<std::uint32_t>(n)); }

  Ldi next(int max_side = 10, int max_layers = 9) {
    const int w = 1 + below(max_side), h = 1 + below(max_side);
    const int layers = below(max_layers + 1);
    std::vector<std::vector<float>> texels(static_cast<std::size_t>(w) * h);
    for (auto& t : texels) {
      if (below(4) == 0) continue;  // empty texel
      const int n = layers == 0 ? 0 : below(layers + 1);
      for (int k = 0; k < n; ++k) t.push_back(static_cast<float>(below(kGrid + 1)) / kGrid);
      std::sort(t.begin(), t.end());
      if (!t.empty() && t[0] == 0.0f && below(2) == 0) t[0] = -0.0f;  // bit-exactness of the sign
    }
    // Keep `layers` stored layers even when no texel reaches it (trailing unused layers).
    const std::size_t texel_count = texels.size();
    std::vector<float> depths(texel_count * layers, kInvalidDepth);
    for (std::size_t i = 0; i < texel_count; ++i)
      for (std::size_t k = 0; k < texels[i].size(); ++k) depths[k * texel_count + i] = texels[i][k];
    return Ldi(w, h, layers, std::move(depths));
  }

 private:
  std::mt19937 rng_;
};

}  // namespace nbsim::ldi::test_support
