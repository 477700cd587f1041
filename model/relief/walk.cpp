// The relief ray walks in float; see walk.h. Every expression here has a twin in
// shaders/relief/relief.frag, written in the same order with the same roundings: change one, change
// the other (ReliefCaptureTest compares them fragment by fragment on llvmpipe).
#include "model/relief/walk.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "model/nbuffer/covering.h"

namespace nbsim::relief {

namespace {

constexpr std::array<std::string_view, kMethods> kMethodNames = {"binary", "exact", "robust", "robust_clamp", "nbuffer"};
constexpr float kFar = 3.0e38f;  // the shader's "no boundary" (a finite constant: GLSL has no inf literal)

struct Deferred;

// A lookup source: the field's textures, every read reported to `sink` (sink(texture, index) for a
// texel in memory, sink.border() for a virtual border texel). The walks are templates on the sink
// so that a recording sink (LookupLines) costs no indirect call per lookup.
template <class Sink>
struct Reader {
  const FieldView f;  // a copy: its size and spans one load away, not two
  Sink& sink;
  std::uint32_t lookups = 0;
  Deferred* defer = nullptr;  // not null: a hit's refinement in its cell is left for later (see Deferred)

  // The four corners of cell (i, j) in the shader's order (h00, h10, h01, h11), their lookups
  // recorded: note() then peek().
  [[gnu::always_inline]] void corners(int i, int j, float& h00, float& h10, float& h01, float& h11) {
    note(i, j);
    peek(i, j, h00, h10, h01, h11);
  }
  // corners() in two halves, for a walk that reads a cell before it knows whether the shader does:
  // peek() the values (nothing recorded), then note() the four lookups (recorded and counted) once
  // the walk takes them. One bounds check and one index each for a cell inside the field, the usual
  // case; a texel outside the field is the virtual border (height 0, no memory).
  [[gnu::always_inline]] void peek(int i, int j, float& h00, float& h10, float& h01, float& h11) const {
    const int n = f.size;
    if (i >= 0 && j >= 0 && i + 1 < n && j + 1 < n) {
      const float* p = f.heights.data() + static_cast<std::int64_t>(j) * n + i;
      h00 = p[0], h10 = p[1], h01 = p[n], h11 = p[n + 1];
      return;
    }
    h00 = peek_height(i, j), h10 = peek_height(i + 1, j), h01 = peek_height(i, j + 1), h11 = peek_height(i + 1, j + 1);
  }
  [[gnu::always_inline]] void note(int i, int j) {
    const int n = f.size;
    lookups += 4;
    if (i >= 0 && j >= 0 && i + 1 < n && j + 1 < n) {
      const std::int64_t index = static_cast<std::int64_t>(j) * n + i;
      sink.pair(Texture::Height, index);
      sink.pair(Texture::Height, index + n);
      return;
    }
    note_height(i, j), note_height(i + 1, j), note_height(i, j + 1), note_height(i + 1, j + 1);
  }
  float peek_height(int i, int j) const {
    if (i >= 0 && j >= 0 && i < f.size && j < f.size) return f.heights[static_cast<std::size_t>(static_cast<std::int64_t>(j) * f.size + i)];
    return 0.0f;
  }
  void note_height(int i, int j) {
    if (i >= 0 && j >= 0 && i < f.size && j < f.size) sink(Texture::Height, static_cast<std::int64_t>(j) * f.size + i);
    else sink.border(Texture::Height);
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
  void walked(std::uint32_t) const noexcept {}
};

// The recording sink: virtual border texels need no memory and are left out.
// A sink is made for a walk (or a replay of logged walks) and holds a writer open on the record.
struct LinesSink {
  explicit LinesSink(LookupLines& l) : lines(l), writer(l) {}
  LookupLines& lines;
  LookupLines::Writer writer;
  [[gnu::always_inline]] void operator()(Texture t, std::int64_t index) {
    writer.add(texel_address(t, index));
    if (t == Texture::NBuffer) lines.add_level_texel(index);
  }
  [[gnu::always_inline]] void pair(Texture t, std::int64_t index) { writer.add_pair(texel_address(t, index), texel_address(t, index + 1)); }
  void border(Texture) noexcept { writer.add_border(); }
  void walked(std::uint32_t lookups) noexcept { writer.add_lookups(lookups); }
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

// The height above the surface at t (negative or zero: below), its cell's four lookups not yet
// recorded (Reader::note(i, j) records them).
struct Probe {
  float f;
  int i, j;
};
template <class Sink>
[[gnu::always_inline]] inline Probe probe(const Reader<Sink>& r, const FragmentRay& ray, float t) {
  const float u = along(ray.o[0], t, ray.d[0]) - 0.5f, v = along(ray.o[1], t, ray.d[1]) - 0.5f;
  const int i = floor_int(u), j = floor_int(v);
  const float fx = u - static_cast<float>(i), fy = v - static_cast<float>(j);
  float h00, h10, h01, h11;
  r.peek(i, j, h00, h10, h01, h11);
  return Probe{along(ray.o[2], t, ray.d[2]) - bilerp(h00, h10, h01, h11, fx, fy), i, j};
}

// The height above the surface at t, 4 lookups.
template <class Sink>
[[gnu::always_inline]] inline float above(Reader<Sink>& r, const FragmentRay& ray, float t) {
  const Probe p = probe(r, ray, t);
  r.note(p.i, p.j);
  return p.f;
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

// A hit's refinement in its cell, left for later: it reads no texel and is the walk's last work, so
// walk_each runs the refinements of a run's walks together, eight at a time (refine_lanes).
struct Deferred {
  bool pending = false;
  Cell cell;
  float a = 0.0f, b = 0.0f;
};

// refine_in_cell, or its deferral: then b stands for the hit's t until the refinement is run (b >= 0,
// a hit for every caller), and the bisections are counted now.
float refine(const Cell& cell, const FragmentRay& ray, float a, float b, int steps, WalkResult& w, Deferred* defer) {
  if (!defer) return refine_in_cell(cell, ray, a, b, steps, w);
  *defer = Deferred{true, cell, a, b};
  w.bisections += static_cast<std::uint32_t>(steps);
  return b;
}

// The cell test on [ta, tb]: the hit's t, or a negative value when none. `full` adds the dip.
float cell_test(const Cell& cell, const FragmentRay& ray, float ta, float tb, bool full, int root_steps, WalkResult& w, Deferred* defer) {
  const float fa = cell.above(ray, ta);
  if (fa <= 0.0f) return ta;
  const float fb = cell.above(ray, tb);
  if (fb <= 0.0f) return refine(cell, ray, ta, tb, root_steps, w, defer);
  if (!full) return -1.0f;
  // f along the ray in this cell is a quadratic; through s = 0, 1/2, 1 of [ta, tb]:
  // f(s) = fa + q1 s + q2 s^2 with q2 = 2 (fa - 2 fm + fb), q1 = (fb - fa) - q2.
  const float tm = (ta + tb) * 0.5f;
  const float fm = cell.above(ray, tm);
  if (fm <= 0.0f) return refine(cell, ray, ta, tm, root_steps, w, defer);
  const float q2 = 2.0f * ((fa - 2.0f * fm) + fb);
  if (!(q2 > 0.0f)) return -1.0f;  // not convex: no dip below both ends
  const float q1 = (fb - fa) - q2;
  const float s = -q1 / (2.0f * q2);
  if (!(s > 0.0f && s < 1.0f)) return -1.0f;
  const float tv = ta + s * (tb - ta);
  if (cell.above(ray, tv) > 0.0f) return -1.0f;
  return refine(cell, ray, ta, tv, root_steps, w, defer);
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
    const float hit = cell_test(cell, ray, t, tb, full, root_steps, w, r.defer);
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

// Every walk's end: a ray that leaves through the box's floor with no hit before hits there, and a
// capped walk is a miss.
void end_walk(WalkResult& w, const FragmentRay& ray) {
  if (!w.hit && !w.capped && ray.floor_exit) set_hit(w, ray.t_out);
  if (w.capped) w.hit = false, w.t = 0.0f;
}

// Bisection of [a, b] (above at a, below at b) anywhere: 4 lookups a step. Two bisections a round,
// as refine_in_cell's: the midpoint and both midpoints the second bisection may take are evaluated
// at once (three independent chains of a cell's reads and its bilinear height instead of two in a
// row), and the lookups recorded are the shader's: the midpoint's cell, then the cell of the one
// taken.
template <class Sink>
float bisect(Reader<Sink>& r, const FragmentRay& ray, float a, float b, int steps, WalkResult& w) {
  int k = 0;
  for (; k + 1 < steps; k += 2) {
    const float m = (a + b) * 0.5f;
    const float left = (a + m) * 0.5f, right = (m + b) * 0.5f;
    const Probe pm = probe(r, ray, m), pl = probe(r, ray, left), pr = probe(r, ray, right);
    const bool below = pm.f <= 0.0f;
    const Probe& second = below ? pl : pr;
    r.note(pm.i, pm.j);
    r.note(second.i, second.j);
    const bool second_below = second.f <= 0.0f;
    // [a, m] then [a, left] or [left, m]; [m, b] then [m, right] or [right, b].
    const float lo = below ? a : m, mid = below ? left : right, hi = below ? m : b;
    a = second_below ? lo : mid;
    b = second_below ? mid : hi;
  }
  for (; k < steps; ++k) {
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
WalkResult walk_with(Method method, const FieldView& field, const WalkParams& params, const FragmentRay& ray, Sink& sink,
                     Deferred* defer = nullptr) {
  Reader<Sink> r{field, sink};
  r.defer = defer;
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
  end_walk(w, ray);
  w.lookups = r.lookups;
  sink.walked(r.lookups);
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

// ---- Runs of walks: every method in lanes (walk_lanes.inl) ----

namespace {

// The texel reads of a run's walks kept for the record: the cells whose corners each walk read
// (its first height at t_in, then one cell a step), replayed into the record after the run in the
// walks' order through the same Reader::corners the one-by-one walks use.
struct CellLog {
  // Per ray: the cell of its first height, the lane that walked it (-1: none, its first height
  // ended it) and its steps' rows in `rows` (the lane's column).
  struct Ray {
    int first_i = 0, first_j = 0, lane = -1;
    std::uint32_t row0 = 0, row1 = 0;
  };
  std::vector<Ray> rays;
  // Per step of the lanes (row), from 0 to the run's last:
  // - rows: the eight lanes' ci, then their cj (kNoCell: the lane read no cell);
  // - radii, when with_radii: the radius texel each lane read before its cell (-1: none);
  // - texels, when with_texels: the N-buffer level texels each lane's query read before its cell,
  //   four a lane (the k-th of lane l at 8 k + l; -1: none).
  std::vector<std::int32_t> rows, radii, texels;
  bool with_radii = false, with_texels = false;
  static constexpr std::int32_t kNoCell = CellWalk::kNoCell;
  // The `stride` entries of row `row` in `v`. The vectors only grow (kept from run to run, and not
  // cleared: a run writes every row it reads), so a row costs no zeroing.
  static std::int32_t* slot(std::vector<std::int32_t>& v, std::uint32_t row, std::size_t stride) {
    const std::size_t need = stride * (static_cast<std::size_t>(row) + 1);
    if (v.size() < need) v.resize(std::max(need, 2 * v.size()));
    return v.data() + stride * row;
  }
  std::vector<std::uint8_t> first_ends;  // scratch of the lanes' runs (LaneFeed)
  // Scratch of replay_repeats: per lane, its cells but the repeats (see there); per row and one past
  // the last, the lanes' counts of those before the row, then of all their cells; per row, the lanes
  // whose ray begins there.
  std::vector<std::int32_t> kept, counts;
  std::vector<std::uint8_t> begins;

  void replay(const FieldView& field, LookupLines& lines) const {
    LinesSink sink{lines};
    Reader<LinesSink> r{field, sink};
    for (const Ray& ray : rays) {
      r.note(ray.first_i, ray.first_j);
      if (ray.lane < 0) continue;
      for (std::uint32_t row = ray.row0; row < ray.row1; ++row) {
        if (with_radii) {
          const std::int32_t index = radii[8 * static_cast<std::size_t>(row) + static_cast<std::size_t>(ray.lane)];
          if (index >= 0) ++r.lookups, sink(Texture::Radius, index);
        }
        if (with_texels)
          for (std::size_t q = 0; q < 4; ++q) {
            const std::int32_t index = texels[32 * static_cast<std::size_t>(row) + 8 * q + static_cast<std::size_t>(ray.lane)];
            if (index >= 0) ++r.lookups, sink(Texture::NBuffer, index);
          }
        const std::int32_t* p = rows.data() + 16 * static_cast<std::size_t>(row);
        if (p[ray.lane] != kNoCell) r.note(p[ray.lane], p[8 + ray.lane]);
      }
    }
    sink.walked(r.lookups);
  }

  // A cell whose four texels lie in the lines its ray's cell before had (right before it in the
  // record) is a repeat when each of those lines is still its set's last: they fall in different sets
  // of the cache (or are the same line). Then the cell's four lookups are all merged (counted, not
  // recorded). The binary searches and the exact walks read nothing but cells, and nearly half their
  // cells are repeats (a step along x within the 16 texels of a line): replay_repeats finds them
  // eight lanes at a time and records only the others, the same record in less time. It needs a
  // table of sets, lines of a texel or more and cells whose texel addresses fit 31 bits. (The robust
  // walks' radius texels between their cells would need a check of their sets and a branch between
  // two kinds of entry: measured, no faster.)
  static bool repeats_known(const FieldView& field, const LookupLines& lines) noexcept {
    return lines.merges() && lines.set_mask() != 0 && lines.line_shift() >= 2 && lines.line_shift() < 31 && field.size >= 2 && field.size <= 16384;
  }
};

void walk_one_by_one(Method method, const FieldView& field, const WalkParams& params, std::span<const FragmentRay* const> rays,
                     std::span<WalkResult> out, LookupLines* lines) {
  for (std::size_t k = 0; k < rays.size(); ++k) out[k] = lines ? walk(method, field, params, *rays[k], *lines) : walk(method, field, params, *rays[k]);
}

#if defined(__x86_64__)
// The lanes twice: for AVX2, and for AVX-512 (the same operations in 256-bit vectors, which the
// compiler then encodes with twice the registers and masked gathers: about 2% faster on Zen 5).
namespace lanes_avx2 {
#define NBSIM_LANES_TARGET "avx2"
#include "model/relief/walk_lanes.inl"  // IWYU pragma: keep
#undef NBSIM_LANES_TARGET
}  // namespace lanes_avx2
namespace lanes_avx512 {
#define NBSIM_LANES_TARGET "avx2,avx512f,avx512vl,avx512bw,avx512dq"
#include "model/relief/walk_lanes.inl"  // IWYU pragma: keep
#undef NBSIM_LANES_TARGET
}  // namespace lanes_avx512
#endif

}  // namespace

bool lane_set_available(LaneSet set) noexcept {
#if defined(__x86_64__)
  switch (set) {
    case LaneSet::None: return true;
    case LaneSet::Avx2: return __builtin_cpu_supports("avx2");
    case LaneSet::Avx512:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  }
  return false;
#else
  return set == LaneSet::None;
#endif
}

LaneSet best_lane_set() noexcept {
  static const LaneSet best = lane_set_available(LaneSet::Avx512) ? LaneSet::Avx512 : lane_set_available(LaneSet::Avx2) ? LaneSet::Avx2 : LaneSet::None;
  return best;
}


void walk_each(Method method, const FieldView& field, const WalkParams& params, std::span<const FragmentRay* const> rays,
               std::span<WalkResult> out, LookupLines* lines, LaneSet lanes) {
#if defined(__x86_64__)
  if (lanes == LaneSet::Avx512 && lane_set_available(LaneSet::Avx512) && lanes_avx512::walk_lanes(method, field, params, rays, out, lines)) return;
  if (lanes != LaneSet::None && lane_set_available(LaneSet::Avx2) && lanes_avx2::walk_lanes(method, field, params, rays, out, lines)) return;
#endif
  walk_one_by_one(method, field, params, rays, out, lines);
}

}  // namespace nbsim::relief
