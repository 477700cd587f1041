// The N-buffer covering (model/nbuffer/covering.h) in GLSL: which texels of which level a query of
// a rectangle reads. The host inserts this file after its #defines (capture's with_covering()):
//   COVERING_KIND  0 paper (the paper's five cases, Fig. 3), 1 corners, 2 one;
//   COVERING_TOP   1: a square taller than the rectangle is flush with its top edge, 0: its bottom.
// nb_cover() fills the squares' lower-left corners (level-0 pixels) and returns how many (1 to 4);
// CoveringGlTest checks it against the C++ core box for box.

int nb_ceil_log2(int v) { return v <= 1 ? 0 : findMSB(v - 1) + 1; }

// The starts of the squares along one axis for the span [start, start + len): one every `side`
// from the start and the last flush with the end, or, when the span is not longer than a square,
// one flush with the start (or its end when at_end; moved to 0 when that would start below 0).
int nb_anchors(int start, int len, int side, bool at_end, out int a[4]) {
  if (len <= side) {
    int s = at_end ? start + len - side : start;
    if (s < 0 && start >= 0) s = 0;
    a[0] = s;
    a[1] = s;
    a[2] = s;
    a[3] = s;
    return 1;
  }
  const int n = (len + side - 1) / side;
  for (int k = 0; k < 4; ++k) a[k] = k + 1 < n ? start + k * side : start + len - side;
  return n;
}

// The squares of rectangle r = (x, y, w, h) at the returned `level`; top_level is the highest
// level the covering may use (the corner and one-square coverings clamp to it).
int nb_cover(ivec4 r, int top_level, out int level, out ivec2 squares[4]) {
  const int w = r.z, h = r.w, m = max(w, h);
#if COVERING_KIND == 0
  const int s_log = nb_ceil_log2(m);
  const int q = (1 << s_log) >> 1;
  const bool thin = (w > q && h <= q && 2 * h <= q) || (w <= q && 2 * w <= q);
  level = s_log == 0 ? 0 : (thin ? s_log - 2 : s_log - 1);
#elif COVERING_KIND == 1
  level = min(findMSB(m), top_level);
#else
  level = nb_ceil_log2(m);
  if (level > top_level) level = min(findMSB(m), top_level);
#endif
  const int side = 1 << level;
  int xs[4], ys[4];
  const int nx = nb_anchors(r.x, w, side, false, xs);
  const int ny = nb_anchors(r.y, h, side, COVERING_TOP != 0, ys);
  int count = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) squares[count++] = ivec2(xs[i], ys[j]);
  for (int k = count; k < 4; ++k) squares[k] = squares[0];
  return count;
}

// A point sprite's covering (the N-buffer paper, 3.2): a power-of-two square is one lookup of the
// level of its side (the direct covering, CoveringSpec::direct_squares) when that level is at most
// top_level; any other rectangle is nb_cover's.
int nb_cover_sprite(ivec4 r, int top_level, out int level, out ivec2 squares[4]) {
  if (r.z == r.w && (r.z & (r.z - 1)) == 0 && findMSB(r.z) <= top_level) {
    level = findMSB(r.z);
    squares[0] = r.xy;
    squares[1] = r.xy;
    squares[2] = r.xy;
    squares[3] = r.xy;
    return 1;
  }
  return nb_cover(r, top_level, level, squares);
}
