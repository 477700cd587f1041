// The built-in perspective city depth scene; see demo_scene.h.
#include "pipeline/scenes/demo_scene.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace nbsim::scenes {

DepthImage city_depth(int width, int height, std::uint32_t seed) {
  // Perspective with near 1 m and far 1 km, GL window depth d(z) = f (z - n) / (z (f - n)).
  constexpr double near_m = 1.0, far_m = 1000.0, eye_height_m = 1.7;
  auto window_depth = [](double z) {
    return static_cast<float>(std::clamp(far_m * (z - near_m) / (z * (far_m - near_m)), 0.0, 1.0));
  };
  DepthImage img(width, height, 1.0f);  // cleared to the far plane (sky)
  const double focal_px = 0.8 * std::max(width, height);
  const double horizon = 0.62 * height;
  // Ground: the row y below the horizon sees the street at distance eye_height * focal / (horizon - y).
  auto ground_z = [&](double y) { return eye_height_m * focal_px / std::max(horizon - y, 1e-3); };
  for (int y = 0; y < height; ++y) {
    if (y + 0.5 >= horizon) break;
    const float d = window_depth(ground_z(y + 0.5));
    for (int x = 0; x < width; ++x) img.at(x, y) = d;
  }
  // Facades along both sides of the street, each a flat quad facing the camera at one distance,
  // drawn with a LESS depth test. Street half-width 6 m, buildings 5 to 400 m away.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int buildings = 80;
  for (int i = 0; i < buildings; ++i) {
    const double z = 5.0 + 395.0 * u(rng) * u(rng);
    const double side = i % 2 ? 1.0 : -1.0;
    const double x_near_m = side * (6.0 + 25.0 * u(rng) * u(rng)), w_m = 8.0 + 25.0 * u(rng);
    const double h_m = 6.0 + 50.0 * u(rng) * u(rng);
    const double base_y = horizon - eye_height_m * focal_px / z, top = base_y + h_m * focal_px / z;
    const double xa = 0.5 * width + x_near_m * focal_px / z, xb = xa + side * w_m * focal_px / z;
    const float d = window_depth(z);
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min(xa, xb))));
    const int x1 = std::min(width, static_cast<int>(std::ceil(std::max(xa, xb))));
    const int y0 = std::max(0, static_cast<int>(std::floor(base_y)));
    const int y1 = std::min(height, static_cast<int>(std::ceil(top)));
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) img.at(x, y) = std::min(img.at(x, y), d);
  }
  return img;
}

}  // namespace nbsim::scenes
