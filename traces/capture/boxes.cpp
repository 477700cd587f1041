// The boxes scene; see boxes.h.
#include "traces/capture/boxes.h"

#include <random>

#include "traces/capture/mesh_builder.h"

namespace nbsim::capture {

CaptureScene make_boxes(const BoxesParams& p) {
  CaptureScene s;
  std::mt19937 rng(p.seed ^ 0xb0c5u);
  auto uni = [&](double a, double b) { return static_cast<float>(std::uniform_real_distribution<double>(a, b)(rng)); };
  const float ext = static_cast<float>(p.extent_m);
  MeshBuilder b(s);
  // The plane y = 0: one quad, open (a receiver only), counter-clockwise seen from above.
  b.begin("ground");
  const std::uint32_t v = b.vertex({0, 0, 0});
  b.vertex({0, 0, ext});
  b.vertex({ext, 0, ext});
  b.vertex({ext, 0, 0});
  b.triangle(v, v + 1, v + 2);
  b.triangle(v, v + 2, v + 3);
  b.end();
  // Boxes 2 to 10 m a side and 2 to 14 m tall, standing on the plane (their bottom face at y = 0).
  for (int k = 0; k < p.boxes; ++k) {
    const float w = uni(2.0, 10.0), d = uni(2.0, 10.0), x = uni(0.1 * ext, 0.9 * ext - w), z = uni(0.1 * ext, 0.9 * ext - d);
    b.begin("box");
    b.box({x, 0.0f, z}, {x + w, uni(2.0, 14.0), z + d});
    b.end();
  }
  b.finish();
  s.site.extent_m = p.extent_m;
  s.properties = {{"seed", std::to_string(p.seed)}, {"boxes", std::to_string(p.boxes)}, {"objects", std::to_string(s.objects.size())}};
  return s;
}

}  // namespace nbsim::capture
