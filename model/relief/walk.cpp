// The relief ray walks in float; see walk.h. Every expression here has a twin in
// shaders/relief/relief.frag, written in the same order with the same roundings: change one, change
// the other (ReliefCaptureTest compares them fragment by fragment on llvmpipe).
#include "model/relief/walk.h"

#include <algorithm>
#include <cmath>

#include "model/nbuffer/covering.h"

namespace nbsim::relief {

namespace {

constexpr std::array<std::string_view, kMethods> kMethodNames = {"binary", "exact", "robust", "robust_clamp", "nbuffer"};
constexpr float kFar = 3.0e38f;  // the shader's "no boundary" (a finite constant: GLSL has no inf literal)

// A lookup source: the field's textures, every read reported to `sink` (sink(texture, index) for a
// texel in memory, sink.border() for a virtual border texel). The walks are templates on the sink
// so that a recording sink (LookupLines) costs no indirect call per lookup.
template <class Sink>
struct Reader {
  const FieldView f;  // a copy: its size and spans one load away, not two
  Sink& sink;
  std::uint32_t lookups = 0;

  float height(int i, int j) {
    ++lookups;
    if (i >= 0 && j >= 0 && i < f.size && j < f.size) {
      const std::int64_t index = static_cast<std::int64_t>(j) * f.size + i;
      sink(Texture::Height, index);
      return f.heights[static_cast<std::size_t>(index)];
    }
    sink.border(Texture::Height);
    return 0.0f;
  }
  // The four corners of cell (i, j) in the shader's order (h00, h10, h01, h11): one bounds check
  // and one index for a cell inside the field, the usual case.
  void corners(int i, int j, float& h00, float& h10, float& h01, float& h11) {
    const int n = f.size;
    if (i >= 0 && j >= 0 && i + 1 < n && j + 1 < n) {
      lookups += 4;
      const std::int64_t index = static_cast<std::int64_t>(j) * n + i;
      sink.pair(Texture::Height, index);
      sink.pair(Texture::Height, index + n);
      const float* p = f.heights.data() + index;
      h00 = p[0], h10 = p[1], h01 = p[n], h11 = p[n + 1];
      return;
    }
    h00 = height(i, j), h10 = height(i + 1, j), h01 = height(i, j + 1), h11 = height(i + 1, j + 1);
  }
  float radius(int i, int j) {
    ++lookups;
    const std::int64_t index = static_cast<std::int64_t>(j) * f.size + i;
    sink(Texture::Radius, index);
    return f.radius[static_cast<std::size_t>(index)];
  }
  float level(int l, int i, int j) {
    ++lookups;
    const std::int64_t index = (static_cast<std::int64_t>(l) * f.size + j) * f.size + i;
    sink(Texture::NBuffer, index);
    return f.nbuffer[static_cast<std::size_t>(index)];
  }
};

// The observer API's sink: the function pointer (may be null) sees every read, border ones as -1.
struct ObserverSink {
  LookupObserver observer;
  void* context;
  void operator()(Texture t, std::int64_t index) const {
    if (observer) observer(context, t, index);
  }
  void border(Texture t) const {
    if (observer) observer(context, t, -1);
  }
  void pair(Texture t, std::int64_t index) const {  // texels index and index + 1
    (*this)(t, index);
    (*this)(t, index + 1);
  }
};

// The recording sink: virtual border texels need no memory and are left out.
struct LinesSink {
  LookupLines& lines;
  void operator()(Texture t, std::int64_t index) const {
    lines.add(texel_address(t, index));
    if (t == Texture::NBuffer) lines.add_level_texel(index);
  }
  void pair(Texture t, std::int64_t index) const { lines.add_pair(texel_address(t, index), texel_address(t, index + 1)); }
  void border(Texture) const noexcept {}
};

int floor_int(float v) noexcept { return static_cast<int>(std::floor(v)); }

// The shader's point on the ray: o + t * d, one rounding for the product and one for the sum.
float along(float o, float t, float d) noexcept { return o + t * d; }

// Bilinear height from four corners at cell fractions (fx, fy), as the shader's bilerp().
float bilerp(float h00, float h10, float h01, float h11, float fx, float fy) noexcept {
  const float a = h00 + fx * (h10 - h00);
  const float b = h01 + fx * (h11 - h01);
  return a + fy * (b - a);
}

// The height above the surface at t (negative or zero: below), 4 lookups.
template <class Sink>
[[gnu::always_inline]] inline float above(Reader<Sink>& r, const FragmentRay& ray, float t) {
  const float u = along(ray.o[0], t, ray.d[0]) - 0.5f, v = along(ray.o[1], t, ray.d[1]) - 0.5f;
  const int i = floor_int(u), j = floor_int(v);
  const float fx = u - static_cast<float>(i), fy = v - static_cast<float>(j);
  float h00, h10, h01, h11;
  r.corners(i, j, h00, h10, h01, h11);
  return along(ray.o[2], t, ray.d[2]) - bilerp(h00, h10, h01, h11, fx, fy);
}

// The cell ahead of the ray at t along one axis: on a cell boundary, the cell the ray enters.
int cell_index(float o, float t, float d, int size) noexcept {
  const float u = along(o, t, d) - 0.5f;
  const int c = d < 0.0f ? static_cast<int>(std::ceil(u)) - 1 : floor_int(u);
  return std::clamp(c, -1, size - 1);
}

// The ray parameter where the ray leaves cell c along one axis (kFar when it never does).
float cell_exit(float o, float d, int c) noexcept {
  if (d > 0.0f) return ((static_cast<float>(c) + 1.5f) - o) / d;
  if (d < 0.0f) return ((static_cast<float>(c) + 0.5f) - o) / d;
  return kFar;
}

// One cell of the walk: its four corners read once.
struct Cell {
  int ci = 0, cj = 0;
  float h00 = 0, h10 = 0, h01 = 0, h11 = 0;

  template <class Sink>
  void read(Reader<Sink>& r) {
    r.corners(ci, cj, h00, h10, h01, h11);
  }
  // Height above the cell's patch at t (no lookups).
  float above(const FragmentRay& ray, float t) const noexcept {
    const float fx = (along(ray.o[0], t, ray.d[0]) - 0.5f) - static_cast<float>(ci);
    const float fy = (along(ray.o[1], t, ray.d[1]) - 0.5f) - static_cast<float>(cj);
    return along(ray.o[2], t, ray.d[2]) - bilerp(h00, h10, h01, h11, fx, fy);
  }
};

// Bisection of [a, b] (above at a, below at b) inside one cell: the below end after `steps`.
// Two bisections a round: the midpoint m and both midpoints the second one may take, (a + m) / 2
// and (m + b) / 2, are tested at once (three independent chains instead of two in a row: the same
// values, so the same result, in about half the time: each test is a long chain of dependent float
// operations), and m's side picks which of the other two counts.
float refine_in_cell(const Cell& cell, const FragmentRay& ray, float a, float b, int steps, WalkResult& w) {
  int k = 0;
  for (; k + 1 < steps; k += 2) {
    const float m = (a + b) * 0.5f;
    const float left = (a + m) * 0.5f, right = (m + b) * 0.5f;
    const float fm = cell.above(ray, m), fl = cell.above(ray, left), fr = cell.above(ray, right);
    if (fm <= 0.0f) {  // b = m, then the midpoint of [a, m]
      if (fl <= 0.0f) b = left;
      else a = left, b = m;
    } else {  // a = m, then the midpoint of [m, b]
      if (fr <= 0.0f) a = m, b = right;
      else a = right;
    }
  }
  for (; k < steps; ++k) {
    const float m = (a + b) * 0.5f;
    if (cell.above(ray, m) <= 0.0f) b = m;
    else a = m;
  }
  w.bisections += static_cast<std::uint32_t>(steps);
  return b;
}

// The cell test on [ta, tb]: the hit's t, or a negative value when none. `full` adds the dip.
float cell_test(const Cell& cell, const FragmentRay& ray, float ta, float tb, bool full, int root_steps, WalkResult& w) {
  const float fa = cell.above(ray, ta);
  if (fa <= 0.0f) return ta;
  const float fb = cell.above(ray, tb);
  if (fb <= 0.0f) return refine_in_cell(cell, ray, ta, tb, root_steps, w);
  if (!full) return -1.0f;
  // f along the ray in this cell is a quadratic; through s = 0, 1/2, 1 of [ta, tb]:
  // f(s) = fa + q1 s + q2 s^2 with q2 = 2 (fa - 2 fm + fb), q1 = (fb - fa) - q2.
  const float tm = (ta + tb) * 0.5f;
  const float fm = cell.above(ray, tm);
  if (fm <= 0.0f) return refine_in_cell(cell, ray, ta, tm, root_steps, w);
  const float q2 = 2.0f * ((fa - 2.0f * fm) + fb);
  if (!(q2 > 0.0f)) return -1.0f;  // not convex: no dip below both ends
  const float q1 = (fb - fa) - q2;
  const float s = -q1 / (2.0f * q2);
  if (!(s > 0.0f && s < 1.0f)) return -1.0f;
  const float tv = ta + s * (tb - ta);
  if (cell.above(ray, tv) > 0.0f) return -1.0f;
  return refine_in_cell(cell, ray, ta, tv, root_steps, w);
}

// A cell walker (Amanatides-Woo over cells) from t.
struct CellWalk {
  Cell cell;
  float t = 0.0f;
  // The exits of the last cell column and row computed: a step moves along one axis (or both at a
  // corner), so the other axis's exit is the one the step before computed (the same value).
  int exit_i = kNoCell, exit_j = kNoCell;
  float tx = 0.0f, ty = 0.0f;
  static constexpr int kNoCell = -2;  // no cell index is below -1

  void start(const FragmentRay& ray, float from, int size) {
    t = from;
    cell.ci = cell_index(ray.o[0], from, ray.d[0], size);
    cell.cj = cell_index(ray.o[1], from, ray.d[1], size);
    exit_i = exit_j = kNoCell;
  }
  bool inside(int size) const noexcept { return cell.ci >= -1 && cell.cj >= -1 && cell.ci < size && cell.cj < size; }
  // Tests the current cell, then moves to the next: the hit's t, or negative.
  template <class Sink>
  float step(Reader<Sink>& r, const FragmentRay& ray, bool full, int root_steps, WalkResult& w) {
    if (exit_i != cell.ci) tx = cell_exit(ray.o[0], ray.d[0], cell.ci), exit_i = cell.ci;
    if (exit_j != cell.cj) ty = cell_exit(ray.o[1], ray.d[1], cell.cj), exit_j = cell.cj;
    const float tb = std::max(t, std::min(std::min(tx, ty), ray.t_out));
    cell.read(r);
    ++w.steps;
    const float hit = cell_test(cell, ray, t, tb, full, root_steps, w);
    if (hit >= 0.0f) return hit;
    if (tx < ty) cell.ci += ray.d[0] > 0.0f ? 1 : -1;
    else if (ty < tx) cell.cj += ray.d[1] > 0.0f ? 1 : -1;
    else {
      cell.ci += ray.d[0] > 0.0f ? 1 : -1;
      cell.cj += ray.d[1] > 0.0f ? 1 : -1;
    }
    t = tb;
    return -1.0f;
  }
};

void set_hit(WalkResult& w, float t) {
  w.hit = true;
  w.t = t;
}

// Bisection of [a, b] (above at a, below at b) anywhere: 4 lookups a step.
template <class Sink>
float bisect(Reader<Sink>& r, const FragmentRay& ray, float a, float b, int steps, WalkResult& w) {
  for (int k = 0; k < steps; ++k) {
    const float m = (a + b) * 0.5f;
    if (above(r, ray, m) <= 0.0f) b = m;
    else a = m;
  }
  w.bisections += static_cast<std::uint32_t>(steps);
  return b;
}

template <class Sink>
void walk_binary(Reader<Sink>& r, const WalkParams& p, const FragmentRay& ray, WalkResult& w) {
  const float dt = (ray.t_out - ray.t_in) / static_cast<float>(p.linear_steps);
  float prev = ray.t_in;
  for (int k = 1; k <= p.linear_steps; ++k) {
    const float t = ray.t_in + dt * static_cast<float>(k);
    ++w.steps;
    if (above(r, ray, t) <= 0.0f) {
      set_hit(w, bisect(r, ray, prev, t, p.binary_steps, w));
      return;
    }
    prev = t;
  }
}

template <class Sink>
void walk_exact(Reader<Sink>& r, const WalkParams& p, const FragmentRay& ray, WalkResult& w, int cap) {
  CellWalk cw;
  cw.start(ray, ray.t_in, r.f.size);
  for (int n = 0; n < cap; ++n) {
    if (!cw.inside(r.f.size) || cw.t >= ray.t_out) return;
    const float hit = cw.step(r, ray, false, p.root_steps, w);
    if (hit >= 0.0f) {
      set_hit(w, hit);
      return;
    }
  }
  w.capped = true;
}

// The inverse horizontal length of d (0 for a vertical ray: its steps reach t_out at once).
float inverse_horizontal(const FragmentRay& ray) noexcept {
  if (ray.d[0] == 0.0f && ray.d[1] == 0.0f) return 0.0f;
  return 1.0f / std::sqrt(ray.d[0] * ray.d[0] + ray.d[1] * ray.d[1]);
}

// t advanced by `texels` of horizontal travel, clamped to t_out.
float advance(const FragmentRay& ray, float t, float texels, float inv) noexcept {
  if (inv == 0.0f) return ray.t_out;
  return std::min(t + texels * inv, ray.t_out);
}

template <class Sink>
void walk_robust(Reader<Sink>& r, const WalkParams& p, const FragmentRay& ray, WalkResult& w, bool clamp, int cap) {
  const int n = r.f.size;
  const float inv = inverse_horizontal(ray);
  float t = ray.t_in;
  for (int it = 0; it < cap; ++it) {
    const int i = std::clamp(floor_int(along(ray.o[0], t, ray.d[0])), 0, n - 1);
    const int j = std::clamp(floor_int(along(ray.o[1], t, ray.d[1])), 0, n - 1);
    float rad = r.radius(i, j);
    if (rad == 0.0f) {
      if (clamp) {
        rad = 1.0f;
      } else {
        CellWalk cw;
        cw.start(ray, t, n);
        for (int k = 0; k < 2 && cw.inside(n) && cw.t < ray.t_out; ++k) {
          const float hit = cw.step(r, ray, true, p.root_steps, w);
          if (hit >= 0.0f) {
            set_hit(w, hit);
            return;
          }
        }
        if (!cw.inside(n) || cw.t >= ray.t_out) return;
        t = cw.t;
        continue;
      }
    }
    const float next = advance(ray, t, rad, inv);
    ++w.steps;
    if (above(r, ray, next) <= 0.0f) {
      set_hit(w, bisect(r, ray, t, next, p.binary_steps, w));
      return;
    }
    if (next >= ray.t_out) return;
    t = next;
  }
  w.capped = true;
}

// The N-buffer's maximum over the texels the surface depends on for x in [x0, x1], y in [y0, y1].
template <class Sink>
float nbuffer_max(Reader<Sink>& r, const CoveringSpec& covering, float x0, float x1, float y0, float y1) {
  const int n = r.f.size, top = r.f.levels - 1;
  const int i0 = std::clamp(floor_int(x0 - 0.5f), 0, n - 1), i1 = std::clamp(floor_int(x1 - 0.5f) + 1, 0, n - 1);
  const int j0 = std::clamp(floor_int(y0 - 0.5f), 0, n - 1), j1 = std::clamp(floor_int(y1 - 0.5f) + 1, 0, n - 1);
  const Covering c = cover(Rect{i0, j0, i1 - i0 + 1, j1 - j0 + 1}, covering, top);
  float m = r.level(c.level, c.squares[0].x, c.squares[0].y);
  for (int k = 1; k < c.count; ++k) m = std::max(m, r.level(c.level, c.squares[static_cast<std::size_t>(k)].x, c.squares[static_cast<std::size_t>(k)].y));
  return m;
}

template <class Sink>
void walk_nbuffer(Reader<Sink>& r, const WalkParams& p, const FragmentRay& ray, WalkResult& w, int cap) {
  const int n = r.f.size, top = r.f.levels - 1;
  const float inv = inverse_horizontal(ray);
  float t = ray.t_in;
  int s = 0;
  CellWalk cw;
  bool walking = false;  // cw holds the cell at t (after a cell step); else it is found from t
  for (int it = 0; it < cap; ++it) {
    ++w.steps;
    const float te = advance(ray, t, static_cast<float>(1 << s), inv);
    const float xa = along(ray.o[0], t, ray.d[0]), xb = along(ray.o[0], te, ray.d[0]);
    const float ya = along(ray.o[1], t, ray.d[1]), yb = along(ray.o[1], te, ray.d[1]);
    const float top_height = nbuffer_max(r, p.covering, std::min(xa, xb), std::max(xa, xb), std::min(ya, yb), std::max(ya, yb));
    const float lowest = std::min(along(ray.o[2], t, ray.d[2]), along(ray.o[2], te, ray.d[2]));
    if (lowest > top_height) {
      if (te >= ray.t_out) return;
      t = te;
      walking = false;
      s = std::min(s + 1, top);
    } else if (s > 0) {
      --s;
    } else {
      if (!walking) cw.start(ray, t, n);
      if (!cw.inside(n) || cw.t >= ray.t_out) return;
      const float hit = cw.step(r, ray, true, p.root_steps, w);
      if (hit >= 0.0f) {
        set_hit(w, hit);
        return;
      }
      t = cw.t;
      walking = true;
      if (!cw.inside(n) || t >= ray.t_out) return;
    }
  }
  w.capped = true;
}

}  // namespace

std::uint64_t storage_bytes(Method m, int size, int levels) noexcept {
  const std::uint64_t plane = 4 * static_cast<std::uint64_t>(std::max(size, 0)) * static_cast<std::uint64_t>(std::max(size, 0));
  switch (m) {
    case Method::Robust:
    case Method::RobustClamp: return 2 * plane;
    case Method::NBuffer: return plane * (1 + static_cast<std::uint64_t>(std::max(levels, 0)));
    default: return plane;
  }
}

std::string_view to_string(Method m) noexcept {
  const auto i = static_cast<std::size_t>(m);
  return i < kMethodNames.size() ? kMethodNames[i] : "?";
}

std::optional<Method> parse_method(std::string_view s) noexcept {
  for (std::size_t i = 0; i < kMethodNames.size(); ++i)
    if (kMethodNames[i] == s) return static_cast<Method>(i);
  return std::nullopt;
}

int walk_iteration_cap(int size) noexcept { return 16 * (size + 2) + 64; }

std::optional<FragmentRay> fragment_ray(const RayFrame& frame, int size, float px, float py) {
  FragmentRay ray;
  if (frame.frustum) {
    std::array<float, 4> q{};
    for (std::size_t k = 0; k < 4; ++k) q[k] = (frame.qa[k] * px + frame.qb[k] * py) + frame.qc[k];
    if (!(q[3] > 0.0f)) return std::nullopt;  // the near-plane point outside the frustum's w > 0 side
    for (std::size_t k = 0; k < 3; ++k) {
      ray.o[k] = q[k] / q[3];
      ray.d[k] = frame.eye_h[3] * q[k] - q[3] * frame.eye_h[k];
    }
  } else {
    ray.o = frame.origin;
    for (int k = 0; k < 3; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      ray.d[kk] = (frame.a[kk] * px + frame.b[kk] * py) + frame.c[kk];
    }
  }
  float tmin = 0.0f, tmax = kFar, t_floor = kFar;
  const float hi[3] = {static_cast<float>(size), static_cast<float>(size), 1.0f};
  for (int k = 0; k < 3; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const float o = ray.o[kk], d = ray.d[kk];
    if (d == 0.0f) {
      if (o < 0.0f || o > hi[k]) return std::nullopt;
      continue;
    }
    const float t1 = (0.0f - o) / d, t2 = (hi[k] - o) / d;
    tmin = std::max(tmin, std::min(t1, t2));
    tmax = std::min(tmax, std::max(t1, t2));
    if (k == 2 && d < 0.0f) t_floor = t1;
  }
  if (!(tmin <= tmax)) return std::nullopt;
  ray.t_in = tmin;
  ray.t_out = tmax;
  ray.floor_exit = t_floor == tmax;
  return ray;
}

namespace {

template <class Sink>
WalkResult walk_with(Method method, const FieldView& field, const WalkParams& params, const FragmentRay& ray, Sink& sink) {
  Reader<Sink> r{field, sink};
  WalkResult w;
  const int cap = walk_iteration_cap(field.size);
  if (above(r, ray, ray.t_in) <= 0.0f) {
    set_hit(w, ray.t_in);
  } else {
    switch (method) {
      case Method::Binary: walk_binary(r, params, ray, w); break;
      case Method::Exact: walk_exact(r, params, ray, w, cap); break;
      case Method::Robust: walk_robust(r, params, ray, w, false, cap); break;
      case Method::RobustClamp: walk_robust(r, params, ray, w, true, cap); break;
      case Method::NBuffer: walk_nbuffer(r, params, ray, w, cap); break;
    }
  }
  if (!w.hit && !w.capped && ray.floor_exit) set_hit(w, ray.t_out);
  if (w.capped) w.hit = false, w.t = 0.0f;
  w.lookups = r.lookups;
  return w;
}

}  // namespace

WalkResult walk(Method method, const FieldView& field, const WalkParams& params, const FragmentRay& ray, LookupObserver observer,
                void* context) {
  ObserverSink sink{observer, context};
  return walk_with(method, field, params, ray, sink);
}

WalkResult walk(Method method, const FieldView& field, const WalkParams& params, const FragmentRay& ray, LookupLines& lines) {
  LinesSink sink{lines};
  return walk_with(method, field, params, ray, sink);
}

}  // namespace nbsim::relief
