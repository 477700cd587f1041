// Procedural city and its BVH; see city.h.
#include "traces/capture/city.h"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

namespace nbsim::capture {

namespace {

using trace::Aabb;

constexpr float fl(int v) { return static_cast<float>(v); }

struct Builder {
  City& city;

  // An axis-aligned box [lo, hi] as 12 outward-facing CCW triangles, appended to the current object.
  void box(glm::vec3 lo, glm::vec3 hi) {
    const auto base = static_cast<std::uint32_t>(city.vertices.size());
    for (int i = 0; i < 8; ++i)
      city.vertices.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    // Faces as corner indices (bit 0 = x, bit 1 = y, bit 2 = z), CCW seen from outside.
    static constexpr std::uint32_t faces[6][4] = {
        {0, 4, 6, 2},  // -x
        {1, 3, 7, 5},  // +x
        {0, 1, 5, 4},  // -y
        {2, 6, 7, 3},  // +y
        {0, 2, 3, 1},  // -z
        {4, 5, 7, 6},  // +z
    };
    for (const auto& f : faces)
      for (std::uint32_t k : {f[0], f[1], f[2], f[0], f[2], f[3]}) city.indices.push_back(base + k);
  }

  void begin(ObjectKind kind) {
    Object o;
    o.kind = kind;
    o.first_index = static_cast<std::uint32_t>(city.indices.size());
    city.objects.push_back(o);
  }

  void end() {
    Object& o = city.objects.back();
    o.index_count = static_cast<std::uint32_t>(city.indices.size()) - o.first_index;
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (std::uint32_t i = o.first_index; i < o.first_index + o.index_count; ++i) {
      lo = glm::min(lo, city.vertices[city.indices[i]]);
      hi = glm::max(hi, city.vertices[city.indices[i]]);
    }
    o.bounds = {{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}};
  }
};

}  // namespace

City make_city(const CityParams& p) {
  if (p.objects < 2) throw std::invalid_argument("a city needs at least 2 objects");
  City city;
  city.block_m = p.block_m;
  city.street_m = p.street_m;
  // About 14 buildings and 30 props per block; enough blocks that buildings are ~1/3 of objects.
  city.blocks_per_side = std::max(1, static_cast<int>(std::ceil(std::sqrt(p.objects / 44.0))));
  const int n = city.blocks_per_side;
  const float pitch = static_cast<float>(city.pitch_m()), half_street = static_cast<float>(p.street_m / 2);
  std::mt19937 rng(p.seed);
  auto uni = [&](double a, double b) { return static_cast<float>(std::uniform_real_distribution<double>(a, b)(rng)); };
  Builder b{city};

  // Ground: one thin slab under the whole city (its top face is y = 0).
  const float ext = static_cast<float>(city.extent_m());
  b.begin(ObjectKind::Ground);
  b.box({-half_street, -1.0f, -half_street}, {ext + half_street, 0.0f, ext + half_street});
  b.end();

  // Buildings: lots along the four sides of every block, inset from the street.
  const int budget_buildings = std::max(0, std::min(p.objects - 1, static_cast<int>(p.objects * 0.35)));
  int buildings = 0;
  for (int by = 0; by < n && buildings < budget_buildings; ++by) {
    for (int bx = 0; bx < n && buildings < budget_buildings; ++bx) {
      const float x0 = fl(bx) * pitch + half_street, z0 = fl(by) * pitch + half_street;
      const float side = static_cast<float>(p.block_m);
      // Downtown (centre of the grid) is taller.
      const float cx = (fl(bx) + 0.5f) / fl(n) - 0.5f, cz = (fl(by) + 0.5f) / fl(n) - 0.5f;
      const float tall = 1.0f + 3.0f * std::exp(-8.0f * (cx * cx + cz * cz));
      // Lots never overlap (overlapping boxes would share planes and z-fight, which makes the
      // ground truth depend on draw order): edges 0 and 2 (along x) own the bands of depth
      // `band` at the block's front and back, edges 1 and 3 the middle; lots on an edge are
      // separated by at least half a metre.
      const float band = 0.3f * side;
      for (int edge = 0; edge < 4 && buildings < budget_buildings; ++edge) {
        const bool along_x = edge % 2 == 0;
        const float start = along_x ? 0.0f : band + 0.5f, stop = along_x ? side : side - band - 0.5f;
        float t = start;
        while (t < stop - 8.0f && buildings < budget_buildings) {
          const float w = std::min(uni(9.0, 24.0), stop - t), d = uni(10.0, band);
          const float h = std::min(220.0f, tall * std::exp(uni(std::log(8.0), std::log(45.0))));
          glm::vec3 lo, hi;
          switch (edge) {
            case 0: lo = {x0 + t, 0, z0}; hi = {x0 + t + w, h, z0 + d}; break;
            case 1: lo = {x0 + side - d, 0, z0 + t}; hi = {x0 + side, h, z0 + t + w}; break;
            case 2: lo = {x0 + side - t - w, 0, z0 + side - d}; hi = {x0 + side - t, h, z0 + side}; break;
            default: lo = {x0, 0, z0 + side - t - w}; hi = {x0 + d, h, z0 + side - t}; break;
          }
          b.begin(ObjectKind::Building);
          b.box(lo, hi);
          if (h > 30.0f && uni(0, 1) < 0.5f) {  // a setback tower on top
            const glm::vec3 c = (lo + hi) * 0.5f, e = (hi - lo) * glm::vec3(0.3f, 0, 0.3f);
            b.box({c.x - e.x, h, c.z - e.z}, {c.x + e.x, h + uni(0.2, 0.6) * h, c.z + e.z});
          }
          b.end();
          ++buildings;
          t += w + uni(0.5, 3.0);
        }
      }
    }
  }

  // Props along the streets, until the object count is reached. Their sizes are drawn at random
  // so that two props that happen to overlap do not share a plane.
  while (static_cast<int>(city.objects.size()) < p.objects) {
    const bool along_x = uni(0, 1) < 0.5f;
    const int line = static_cast<int>(uni(0, n + 1 - 1e-6));
    const float along = uni(0, fl(n) * pitch), across = fl(line) * pitch + uni(-half_street + 1.0, half_street - 1.0);
    const float x = along_x ? along : across, z = along_x ? across : along;
    const float r = uni(0, 1);
    if (r < 0.45f) {  // car, parked or driving along the street
      b.begin(ObjectKind::Car);
      const float l = uni(3.8, 5.2) / 2, w = 0.9f;
      const glm::vec3 half = along_x ? glm::vec3(l, 0, w) : glm::vec3(w, 0, l);
      b.box({x - half.x, uni(0.12, 0.2), z - half.z}, {x + half.x, uni(1.35, 1.65), z + half.z});
      b.end();
    } else if (r < 0.7f) {  // lamp post
      b.begin(ObjectKind::Lamp);
      b.box({x - 0.12f, 0, z - 0.12f}, {x + 0.12f, uni(5.0, 7.0), z + 0.12f});
      b.end();
    } else if (r < 0.9f) {  // tree: trunk and crown
      b.begin(ObjectKind::Tree);
      const float h = uni(2.0, 3.5), c = uni(1.2, 2.5);
      b.box({x - 0.2f, 0, z - 0.2f}, {x + 0.2f, h, z + 0.2f});
      b.box({x - c, h, z - c}, {x + c, h + 2 * c, z + c});
      b.end();
    } else {  // kiosk
      b.begin(ObjectKind::Kiosk);
      b.box({x - 1.5f, 0, z - 1.2f}, {x + 1.5f, uni(2.4, 2.9), z + 1.2f});
      b.end();
    }
  }

  std::vector<Aabb> bounds;
  for (const Object& o : city.objects) {
    bounds.push_back(o.bounds);
    city.scene.triangles.push_back(o.index_count / 3);
  }
  city.scene.objects = bounds;
  build_bvh(bounds, city.scene);
  return city;
}

void build_bvh(const std::vector<Aabb>& objects, trace::SceneObjects& out) {
  out.node_bounds.clear();
  out.node_left.clear();
  out.node_right.clear();
  out.node_first.clear();
  out.node_count.clear();
  out.leaf_objects.resize(objects.size());
  std::iota(out.leaf_objects.begin(), out.leaf_objects.end(), 0u);
  if (objects.empty()) return;
  auto centre = [&](std::uint32_t i, int axis) { return 0.5f * (objects[i].lo[axis] + objects[i].hi[axis]); };
  auto merge = [](Aabb a, const Aabb& o) {
    for (int k = 0; k < 3; ++k) a.lo[k] = std::min(a.lo[k], o.lo[k]), a.hi[k] = std::max(a.hi[k], o.hi[k]);
    return a;
  };
  auto area = [](const Aabb& a) {
    const float dx = a.hi[0] - a.lo[0], dy = a.hi[1] - a.lo[1], dz = a.hi[2] - a.lo[2];
    return dx * dy + dy * dz + dz * dx;
  };
  constexpr std::uint32_t leaf_size = 4;
  constexpr int bins = 16;
  struct Task { std::uint32_t node, first, count; };
  std::vector<Task> stack;
  auto new_node = [&](std::uint32_t first, std::uint32_t count) {
    Aabb box = objects[out.leaf_objects[first]];
    for (std::uint32_t i = first + 1; i < first + count; ++i) box = merge(box, objects[out.leaf_objects[i]]);
    out.node_bounds.push_back(box);
    out.node_left.push_back(-1);
    out.node_right.push_back(-1);
    out.node_first.push_back(first);
    out.node_count.push_back(count);
    return static_cast<std::uint32_t>(out.node_bounds.size() - 1);
  };
  stack.push_back({new_node(0, static_cast<std::uint32_t>(objects.size())), 0, static_cast<std::uint32_t>(objects.size())});
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    if (t.count <= leaf_size) continue;
    // Binned SAH over the centroid bounds, on every axis.
    float best_cost = INFINITY;
    int best_axis = -1;
    float best_split = 0;
    for (int axis = 0; axis < 3; ++axis) {
      float lo = INFINITY, hi = -INFINITY;
      for (std::uint32_t i = t.first; i < t.first + t.count; ++i) {
        lo = std::min(lo, centre(out.leaf_objects[i], axis));
        hi = std::max(hi, centre(out.leaf_objects[i], axis));
      }
      if (hi - lo <= 1e-6f) continue;
      std::array<Aabb, bins> box{};
      std::array<std::uint32_t, bins> cnt{};
      auto bin_of = [&](float c) { return std::min(bins - 1, static_cast<int>((c - lo) / (hi - lo) * bins)); };
      for (std::uint32_t i = t.first; i < t.first + t.count; ++i) {
        const std::uint32_t o = out.leaf_objects[i];
        const int k = bin_of(centre(o, axis));
        box[static_cast<std::size_t>(k)] = cnt[static_cast<std::size_t>(k)] ? merge(box[static_cast<std::size_t>(k)], objects[o]) : objects[o];
        ++cnt[static_cast<std::size_t>(k)];
      }
      for (int s = 1; s < bins; ++s) {
        Aabb l{}, r{};
        std::uint32_t nl = 0, nr = 0;
        for (int k = 0; k < s; ++k)
          if (cnt[static_cast<std::size_t>(k)]) l = nl ? merge(l, box[static_cast<std::size_t>(k)]) : box[static_cast<std::size_t>(k)], nl += cnt[static_cast<std::size_t>(k)];
        for (int k = s; k < bins; ++k)
          if (cnt[static_cast<std::size_t>(k)]) r = nr ? merge(r, box[static_cast<std::size_t>(k)]) : box[static_cast<std::size_t>(k)], nr += cnt[static_cast<std::size_t>(k)];
        if (!nl || !nr) continue;
        const float cost = area(l) * static_cast<float>(nl) + area(r) * static_cast<float>(nr);
        if (cost < best_cost) best_cost = cost, best_axis = axis, best_split = lo + (hi - lo) * static_cast<float>(s) / bins;
      }
    }
    auto* first = out.leaf_objects.data() + t.first;
    std::uint32_t mid;
    if (best_axis < 0) {  // all centres coincide: split the list in half
      mid = t.count / 2;
    } else {
      mid = static_cast<std::uint32_t>(std::partition(first, first + t.count, [&](std::uint32_t o) { return centre(o, best_axis) < best_split; }) - first);
      if (mid == 0 || mid == t.count) mid = t.count / 2;
    }
    const std::uint32_t left = new_node(t.first, mid), right = new_node(t.first + mid, t.count - mid);
    out.node_left[t.node] = static_cast<std::int32_t>(left);
    out.node_right[t.node] = static_cast<std::int32_t>(right);
    stack.push_back({left, t.first, mid});
    stack.push_back({right, t.first + mid, t.count - mid});
  }
}

}  // namespace nbsim::capture
