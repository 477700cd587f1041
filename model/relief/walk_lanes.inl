// The relief walks in lanes (see walk.h, walk_each): included by walk.cpp once for each instruction
// set it compiles them for (NBSIM_LANES_TARGET, a gnu::target string), each time in a namespace of
// its own, inside walk.cpp's anonymous namespace (its readers, sinks, cell walks and CellLog).
// Every function here computes the same results, bit for bit, whatever the instruction set.

// One lane's ray and walk state, eight lanes side by side (structure of arrays, loaded as vectors).
struct alignas(32) Lanes {
  float o0[8], o1[8], o2[8], d0[8], d1[8], d2[8], t_out[8], t[8], tb[8];
  std::int32_t ci[8], cj[8], sx[8], sy[8], iter[8];
  std::int32_t ray[8];  // the ray's index in the run, -1: the lane is idle
};

// How a lane's walk ended.
enum class LaneEnd { HitEntry, HitInside, Miss, Capped };

[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256 select(__m256 mask, __m256 yes, __m256 no) { return _mm256_blendv_ps(no, yes, mask); }
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i select_i(__m256 mask, __m256i yes, __m256i no) {
  return _mm256_blendv_epi8(no, yes, _mm256_castps_si256(mask));
}

// std::min(a, b) and std::max(a, b) to the bit (the first argument on ties, +0 and -0 included).
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256 std_min(__m256 a, __m256 b) { return select(_mm256_cmp_ps(b, a, _CMP_LT_OQ), b, a); }
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256 std_max(__m256 a, __m256 b) { return select(_mm256_cmp_ps(a, b, _CMP_LT_OQ), b, a); }

// cell_exit(o, d, c) in eight lanes.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256 cell_exits(__m256 o, __m256 d, __m256i c) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 forward = _mm256_cmp_ps(d, zero, _CMP_GT_OQ), backward = _mm256_cmp_ps(d, zero, _CMP_LT_OQ);
  const __m256 edge = select(forward, _mm256_set1_ps(1.5f), _mm256_set1_ps(0.5f));
  const __m256 exit = _mm256_div_ps(_mm256_sub_ps(_mm256_add_ps(_mm256_cvtepi32_ps(c), edge), o), d);
  return select(_mm256_or_ps(forward, backward), exit, _mm256_set1_ps(kFar));
}

// The height at one corner of each lane's cell: 0 outside the field (the virtual border) or in an
// idle lane.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256 corner(const float* heights, __m256i i, __m256i j, __m256i n, __m256i live) {
  const __m256i minus1 = _mm256_set1_epi32(-1);
  const __m256i in = _mm256_and_si256(_mm256_and_si256(_mm256_cmpgt_epi32(i, minus1), _mm256_cmpgt_epi32(j, minus1)),
                                      _mm256_and_si256(_mm256_cmpgt_epi32(n, i), _mm256_cmpgt_epi32(n, j)));
  const __m256i index = _mm256_add_epi32(_mm256_mullo_epi32(j, n), i);
  return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), heights, index, _mm256_castsi256_ps(_mm256_and_si256(in, live)), 4);
}

// Cell::above in eight lanes.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256 cell_above(__m256 o0, __m256 o1, __m256 o2, __m256 d0, __m256 d1, __m256 d2, __m256 t, __m256 fci,
                                                 __m256 fcj, __m256 h00, __m256 h10, __m256 h01, __m256 h11) {
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 fx = _mm256_sub_ps(_mm256_sub_ps(_mm256_add_ps(o0, _mm256_mul_ps(t, d0)), half), fci);
  const __m256 fy = _mm256_sub_ps(_mm256_sub_ps(_mm256_add_ps(o1, _mm256_mul_ps(t, d1)), half), fcj);
  const __m256 a = _mm256_add_ps(h00, _mm256_mul_ps(fx, _mm256_sub_ps(h10, h00)));
  const __m256 b = _mm256_add_ps(h01, _mm256_mul_ps(fx, _mm256_sub_ps(h11, h01)));
  const __m256 bilinear = _mm256_add_ps(a, _mm256_mul_ps(fy, _mm256_sub_ps(b, a)));
  return _mm256_sub_ps(_mm256_add_ps(o2, _mm256_mul_ps(t, d2)), bilinear);
}

// A hit's refinement in its cell for out[out].
struct Refinement {
  const FragmentRay* ray;
  Cell cell;
  float a, b;
  std::size_t out;
};

// refine_in_cell for every job, eight at a time: the one-by-one bisection, each lane the same
// operations in the same order (refine_in_cell's two-at-a-time rounds take the same values). Sets
// each job's hit t (its bisections are counted).
[[gnu::target(NBSIM_LANES_TARGET)]] void refine_lanes(std::span<const Refinement> jobs, int steps, std::span<WalkResult> out) {
  for (std::size_t first = 0; first < jobs.size(); first += 8) {
    alignas(32) float v[15][8];  // o0, o1, o2, d0, d1, d2, ci, cj, h00, h10, h01, h11, a, b, spare
    for (std::size_t l = 0; l < 8; ++l) {
      const Refinement& j = jobs[std::min(first + l, jobs.size() - 1)];  // the last job again in spare lanes
      const float row[14] = {j.ray->o[0], j.ray->o[1], j.ray->o[2], j.ray->d[0], j.ray->d[1], j.ray->d[2], static_cast<float>(j.cell.ci),
                             static_cast<float>(j.cell.cj), j.cell.h00, j.cell.h10, j.cell.h01, j.cell.h11, j.a, j.b};
      for (std::size_t q = 0; q < 14; ++q) v[q][l] = row[q];
    }
    const __m256 o0 = _mm256_load_ps(v[0]), o1 = _mm256_load_ps(v[1]), o2 = _mm256_load_ps(v[2]);
    const __m256 d0 = _mm256_load_ps(v[3]), d1 = _mm256_load_ps(v[4]), d2 = _mm256_load_ps(v[5]);
    const __m256 fci = _mm256_load_ps(v[6]), fcj = _mm256_load_ps(v[7]);
    const __m256 h00 = _mm256_load_ps(v[8]), h10 = _mm256_load_ps(v[9]), h01 = _mm256_load_ps(v[10]), h11 = _mm256_load_ps(v[11]);
    __m256 a = _mm256_load_ps(v[12]), b = _mm256_load_ps(v[13]);
    const __m256 half = _mm256_set1_ps(0.5f), zero = _mm256_setzero_ps();
    for (int k = 0; k < steps; ++k) {
      const __m256 m = _mm256_mul_ps(_mm256_add_ps(a, b), half);
      const __m256 below = _mm256_cmp_ps(cell_above(o0, o1, o2, d0, d1, d2, m, fci, fcj, h00, h10, h01, h11), zero, _CMP_LE_OQ);
      b = select(below, m, b);
      a = select(below, a, m);
    }
    _mm256_store_ps(v[14], b);
    for (std::size_t l = 0; l < 8 && first + l < jobs.size(); ++l) out[jobs[first + l].out].t = v[14][l];
  }
}

// walk_with's first height (above() at t_in) for every ray of a lanes run, eight at a time: each
// ray's cell logged, and whether the height ends its walk (a hit at t_in) in `ends`.
[[gnu::target(NBSIM_LANES_TARGET)]] void first_heights(const FieldView& field, std::span<const FragmentRay* const> rays, CellLog& log,
                                           std::vector<std::uint8_t>& ends) {
  ends.resize(rays.size());
  const __m256i nv = _mm256_set1_epi32(field.size), live = _mm256_set1_epi32(-1), one = _mm256_set1_epi32(1);
  const __m256 half = _mm256_set1_ps(0.5f), zero = _mm256_setzero_ps();
  for (std::size_t first = 0; first < rays.size(); first += 8) {
    alignas(32) float v[7][8];  // o0, o1, o2, d0, d1, d2, t_in
    for (std::size_t l = 0; l < 8; ++l) {
      const FragmentRay& ray = *rays[std::min(first + l, rays.size() - 1)];  // the last ray again in spare lanes
      const float row[7] = {ray.o[0], ray.o[1], ray.o[2], ray.d[0], ray.d[1], ray.d[2], ray.t_in};
      for (std::size_t q = 0; q < 7; ++q) v[q][l] = row[q];
    }
    const __m256 o0 = _mm256_load_ps(v[0]), o1 = _mm256_load_ps(v[1]), o2 = _mm256_load_ps(v[2]);
    const __m256 d0 = _mm256_load_ps(v[3]), d1 = _mm256_load_ps(v[4]), d2 = _mm256_load_ps(v[5]), t = _mm256_load_ps(v[6]);
    const __m256i i = _mm256_cvttps_epi32(_mm256_floor_ps(_mm256_sub_ps(_mm256_add_ps(o0, _mm256_mul_ps(t, d0)), half)));
    const __m256i j = _mm256_cvttps_epi32(_mm256_floor_ps(_mm256_sub_ps(_mm256_add_ps(o1, _mm256_mul_ps(t, d1)), half)));
    const __m256i i1 = _mm256_add_epi32(i, one), j1 = _mm256_add_epi32(j, one);
    const float* h = field.heights.data();
    const __m256 f = cell_above(o0, o1, o2, d0, d1, d2, t, _mm256_cvtepi32_ps(i), _mm256_cvtepi32_ps(j), corner(h, i, j, nv, live),
                                corner(h, i1, j, nv, live), corner(h, i, j1, nv, live), corner(h, i1, j1, nv, live));
    const int below = _mm256_movemask_ps(_mm256_cmp_ps(f, zero, _CMP_LE_OQ));
    alignas(32) std::int32_t cells[2][8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(cells[0]), i);
    _mm256_store_si256(reinterpret_cast<__m256i*>(cells[1]), j);
    for (std::size_t l = 0; l < 8 && first + l < rays.size(); ++l) {
      log.rays[first + l].first_i = cells[0][l], log.rays[first + l].first_j = cells[1][l];
      ends[first + l] = static_cast<std::uint8_t>(below >> l & 1);
    }
  }
}

// A lanes run's rays handed to its lanes in order. walk_with's first height, and a walk that ends
// before its first iteration (`ends_at_once(ray, w)` true, w's capped flag set), are done here, so a
// lane takes only rays that walk.
struct LaneFeed {
  std::span<const FragmentRay* const> rays;
  std::span<WalkResult> out;
  CellLog& log;
  ObserverSink none{nullptr, nullptr};
  Reader<ObserverSink> reader;  // reads without recording (the log records)
  std::size_t next = 0;

  std::vector<std::uint8_t>& first_ends;  // per ray: its first height ends its walk

  LaneFeed(const FieldView& field, std::span<const FragmentRay* const> r, std::span<WalkResult> o, CellLog& l)
      : rays(r), out(o), log(l), reader{field, none}, first_ends(l.first_ends) {
    log.rays.assign(rays.size(), CellLog::Ray{});
    log.with_radii = log.with_texels = false;
    first_heights(field, rays, log, first_ends);
  }
  LaneFeed(const LaneFeed&) = delete;
  LaneFeed& operator=(const LaneFeed&) = delete;

  // The next ray for lane `l`, its steps logged from `row` on; -1 when none is left.
  template <class EndsAtOnce>
  std::ptrdiff_t take(int l, std::uint32_t row, EndsAtOnce&& ends_at_once) {
    while (next < rays.size()) {
      const std::size_t k = next++;
      const FragmentRay& ray = *rays[k];
      WalkResult& w = out[k];
      CellLog::Ray& logged = log.rays[k];
      w = WalkResult{};
      if (first_ends[k]) set_hit(w, ray.t_in);
      if (first_ends[k] || ends_at_once(ray, w)) {
        w.lookups = 4;
        end_walk(w, ray);
        continue;
      }
      logged.lane = l;
      logged.row0 = logged.row1 = row;
      return static_cast<std::ptrdiff_t>(k);
    }
    return -1;
  }

  // Ray k's hit inside cell (ci, cj), its bracket [a, b] refined later with the run's other hits
  // (refine_lanes; b stands for the hit's t until then): the cell's corners read again (no record),
  // the job listed, the bisections counted.
  void refine_later(std::size_t k, int ci, int cj, float a, float b, int root_steps, std::vector<Refinement>& jobs) {
    Refinement job{rays[k], Cell{}, a, b, k};
    job.cell.ci = ci, job.cell.cj = cj;
    job.cell.read(reader);
    jobs.push_back(job);
    out[k].bisections += static_cast<std::uint32_t>(root_steps);
    set_hit(out[k], b);
  }
};

// The exact walks of a run, eight at a time: walk_exact's steps, lane by lane the same operations in
// the same order (walk_with's first height in LaneFeed, its end per ray in scalar code).
[[gnu::target(NBSIM_LANES_TARGET)]] void exact_lanes(const FieldView& field, const WalkParams& params, std::span<const FragmentRay* const> rays,
                                         std::span<WalkResult> out, CellLog& log, std::vector<Refinement>& refinements) {
  const int n = field.size, cap = walk_iteration_cap(n);
  LaneFeed feed(field, rays, out, log);
  std::uint32_t row = 0;
  Lanes L;

  // Gives lane `l` the run's next ray that needs a walk, or leaves it idle.
  const auto load = [&](int l) {
    const std::ptrdiff_t next = feed.take(l, row, [&](const FragmentRay& ray, WalkResult& w) {
      CellWalk cw;
      cw.start(ray, ray.t_in, n);
      w.capped = cap <= 0;
      return cap <= 0 || !cw.inside(n) || cw.t >= ray.t_out;  // walk_exact's loop: capped before its first step, or done
    });
    if (next >= 0) {
      const auto k = static_cast<std::size_t>(next);
      const FragmentRay& ray = *rays[k];
      CellWalk cw;
      cw.start(ray, ray.t_in, n);
      L.o0[l] = ray.o[0], L.o1[l] = ray.o[1], L.o2[l] = ray.o[2];
      L.d0[l] = ray.d[0], L.d1[l] = ray.d[1], L.d2[l] = ray.d[2];
      L.t_out[l] = ray.t_out, L.t[l] = cw.t, L.tb[l] = 0.0f;
      L.ci[l] = cw.cell.ci, L.cj[l] = cw.cell.cj;
      L.sx[l] = ray.d[0] > 0.0f ? 1 : -1, L.sy[l] = ray.d[1] > 0.0f ? 1 : -1;
      L.iter[l] = 0;
      L.ray[l] = static_cast<std::int32_t>(k);
      return;
    }
    L.ray[l] = -1;
    L.o0[l] = L.o1[l] = L.o2[l] = L.d0[l] = L.d1[l] = L.d2[l] = L.t_out[l] = L.t[l] = L.tb[l] = 0.0f;
    L.ci[l] = L.cj[l] = L.sx[l] = L.sy[l] = L.iter[l] = 0;
  };
  // Ends lane l's walk and loads the next ray into it.
  const auto end_lane = [&](int l, LaneEnd how) {
    const auto k = static_cast<std::size_t>(L.ray[l]);
    const FragmentRay& ray = *rays[k];
    WalkResult& w = out[k];
    CellLog::Ray& logged = log.rays[k];
    w.steps = logged.row1 - logged.row0;
    w.lookups = 4 * (1 + w.steps);
    switch (how) {
      case LaneEnd::HitEntry: set_hit(w, L.t[l]); break;
      case LaneEnd::HitInside: feed.refine_later(k, L.ci[l], L.cj[l], L.t[l], L.tb[l], params.root_steps, refinements); break;
      case LaneEnd::Miss: break;
      case LaneEnd::Capped: w.capped = true; break;
    }
    end_walk(w, ray);
    load(l);
  };

  for (int l = 0; l < 8; ++l) load(l);
  const __m256i nv = _mm256_set1_epi32(n), one = _mm256_set1_epi32(1), minus1 = _mm256_set1_epi32(-1);
  const __m256 zero = _mm256_setzero_ps();
  for (;;) {
    const __m256i ray_index = _mm256_load_si256(reinterpret_cast<const __m256i*>(L.ray));
    const __m256i live = _mm256_cmpgt_epi32(ray_index, minus1);
    if (_mm256_testz_si256(live, live)) break;
    const __m256 o0 = _mm256_load_ps(L.o0), o1 = _mm256_load_ps(L.o1), o2 = _mm256_load_ps(L.o2);
    const __m256 d0 = _mm256_load_ps(L.d0), d1 = _mm256_load_ps(L.d1), d2 = _mm256_load_ps(L.d2);
    const __m256 t = _mm256_load_ps(L.t), t_out = _mm256_load_ps(L.t_out);
    const __m256i ci = _mm256_load_si256(reinterpret_cast<const __m256i*>(L.ci)), cj = _mm256_load_si256(reinterpret_cast<const __m256i*>(L.cj));
    // The step's cells, for the record.
    std::int32_t* logged = CellLog::slot(log.rows, row, 16);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged), ci);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged + 8), cj);
    // CellWalk::step: the cell's exits, its end tb, its corners, the cell test.
    const __m256 tx = cell_exits(o0, d0, ci), ty = cell_exits(o1, d1, cj);
    const __m256 tb = std_max(t, std_min(std_min(tx, ty), t_out));
    const __m256i ci1 = _mm256_add_epi32(ci, one), cj1 = _mm256_add_epi32(cj, one);
    const __m256 h00 = corner(field.heights.data(), ci, cj, nv, live), h10 = corner(field.heights.data(), ci1, cj, nv, live);
    const __m256 h01 = corner(field.heights.data(), ci, cj1, nv, live), h11 = corner(field.heights.data(), ci1, cj1, nv, live);
    const __m256 fci = _mm256_cvtepi32_ps(ci), fcj = _mm256_cvtepi32_ps(cj);
    const __m256 fa = cell_above(o0, o1, o2, d0, d1, d2, t, fci, fcj, h00, h10, h01, h11);
    const __m256 fb = cell_above(o0, o1, o2, d0, d1, d2, tb, fci, fcj, h00, h10, h01, h11);
    const __m256 livef = _mm256_castsi256_ps(live);
    const __m256 hit_entry = _mm256_and_ps(livef, _mm256_cmp_ps(fa, zero, _CMP_LE_OQ));
    const __m256 hit_inside = _mm256_andnot_ps(hit_entry, _mm256_and_ps(livef, _mm256_cmp_ps(fb, zero, _CMP_LE_OQ)));
    // The move to the next cell (lanes without a hit).
    const __m256i x_first = _mm256_castps_si256(_mm256_cmp_ps(tx, ty, _CMP_LT_OQ));
    const __m256i y_first = _mm256_castps_si256(_mm256_cmp_ps(ty, tx, _CMP_LT_OQ));
    const __m256i step_x = _mm256_andnot_si256(y_first, minus1);  // tx < ty, or neither first (a corner)
    const __m256i step_y = _mm256_andnot_si256(x_first, minus1);
    const __m256i next_ci = _mm256_add_epi32(ci, _mm256_and_si256(step_x, _mm256_load_si256(reinterpret_cast<const __m256i*>(L.sx))));
    const __m256i next_cj = _mm256_add_epi32(cj, _mm256_and_si256(step_y, _mm256_load_si256(reinterpret_cast<const __m256i*>(L.sy))));
    const __m256i iter = _mm256_add_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(L.iter)), one);
    // walk_exact's loop head for the next step: inside the field, t before t_out, under the cap.
    const __m256i inside = _mm256_and_si256(_mm256_and_si256(_mm256_cmpgt_epi32(next_ci, _mm256_set1_epi32(-2)), _mm256_cmpgt_epi32(next_cj, _mm256_set1_epi32(-2))),
                                            _mm256_and_si256(_mm256_cmpgt_epi32(nv, next_ci), _mm256_cmpgt_epi32(nv, next_cj)));
    const __m256 before_end = _mm256_cmp_ps(tb, t_out, _CMP_LT_OQ);
    const __m256 goes_on = _mm256_and_ps(before_end, _mm256_castsi256_ps(inside));
    const __m256i under_cap = _mm256_cmpgt_epi32(_mm256_set1_epi32(cap), iter);
    // Hit lanes keep their cell and t (the refinement and the record need them).
    const __m256 hit = _mm256_or_ps(hit_entry, hit_inside);
    const __m256i hiti = _mm256_castps_si256(hit);
    _mm256_store_si256(reinterpret_cast<__m256i*>(L.ci), _mm256_blendv_epi8(next_ci, ci, hiti));
    _mm256_store_si256(reinterpret_cast<__m256i*>(L.cj), _mm256_blendv_epi8(next_cj, cj, hiti));
    _mm256_store_ps(L.t, select(hit, t, tb));
    _mm256_store_ps(L.tb, tb);
    _mm256_store_si256(reinterpret_cast<__m256i*>(L.iter), iter);
    ++row;
    const int live_bits = _mm256_movemask_ps(livef);
    const int entry_bits = _mm256_movemask_ps(hit_entry), inside_bits = _mm256_movemask_ps(hit_inside);
    // walk_exact's loop ends after its cap-th step whatever the next step would find.
    const int walked = live_bits & ~(entry_bits | inside_bits);
    const int capped_bits = walked & ~_mm256_movemask_ps(_mm256_castsi256_ps(under_cap));
    const int on_bits = walked & ~capped_bits & _mm256_movemask_ps(goes_on);
    const int ended = live_bits & ~on_bits;
    if (ended == 0) continue;
    for (int l = 0; l < 8; ++l) {
      if (!(ended >> l & 1)) continue;
      log.rays[static_cast<std::size_t>(L.ray[l])].row1 = row;
      end_lane(l, entry_bits >> l & 1 ? LaneEnd::HitEntry : inside_bits >> l & 1 ? LaneEnd::HitInside : capped_bits >> l & 1 ? LaneEnd::Capped : LaneEnd::Miss);
    }
  }
}

// Eight lanes' ints from and to an aligned array.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i load_i(const std::int32_t* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p)); }
[[gnu::target(NBSIM_LANES_TARGET)]] inline void store_i(std::int32_t* p, __m256i v) { _mm256_store_si256(reinterpret_cast<__m256i*>(p), v); }
// std::clamp(v, lo, hi) of ints in eight lanes.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i clamp_lanes(__m256i v, __m256i lo, __m256i hi) { return _mm256_min_epi32(_mm256_max_epi32(v, lo), hi); }
// floor_int in eight lanes.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i floor_lanes(__m256 v) { return _mm256_cvttps_epi32(_mm256_floor_ps(v)); }

// cell_index() in eight lanes (the cell the ray enters at t along one axis).
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i cell_indices(__m256 o, __m256 t, __m256 d, __m256i last_texel) {
  const __m256 u = _mm256_sub_ps(_mm256_add_ps(o, _mm256_mul_ps(t, d)), _mm256_set1_ps(0.5f));
  const __m256i c = select_i(_mm256_cmp_ps(d, _mm256_setzero_ps(), _CMP_LT_OQ), _mm256_sub_epi32(_mm256_cvttps_epi32(_mm256_ceil_ps(u)), _mm256_set1_epi32(1)),
                             floor_lanes(u));
  return clamp_lanes(c, _mm256_set1_epi32(-1), last_texel);
}
// CellWalk::inside() in eight lanes.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i cells_inside(__m256i ci, __m256i cj, __m256i nv) {
  const __m256i minus2 = _mm256_set1_epi32(-2);
  return _mm256_and_si256(_mm256_and_si256(_mm256_cmpgt_epi32(ci, minus2), _mm256_cmpgt_epi32(cj, minus2)),
                          _mm256_and_si256(_mm256_cmpgt_epi32(nv, ci), _mm256_cmpgt_epi32(nv, cj)));
}

// CellWalk::step with the full cell test (cell_test(full): the entry, the exit, the middle and the
// dip of the quadratic through them) from t in cell (ci, cj), in the lanes of `stepped` (the others'
// values are meaningless): the cell's end tb, the hits (at the entry, or inside the cell, refined
// later from t to end_b), and the next cell and whether the walk goes on there (no hit, the cell
// inside the field, tb before t_out).
struct CellStepLanes {
  __m256 tb, entry, refined, end_b;
  __m256i next_ci, next_cj, goes_on;
};
[[gnu::target(NBSIM_LANES_TARGET)]] inline CellStepLanes full_cell_step(const float* heights, __m256i nv, __m256 o0, __m256 o1, __m256 o2, __m256 d0, __m256 d1,
                                                            __m256 d2, __m256 t, __m256 t_out, __m256i ci, __m256i cj, __m256i sx, __m256i sy,
                                                            __m256i stepped) {
  const __m256i one = _mm256_set1_epi32(1);
  const __m256 half = _mm256_set1_ps(0.5f), zero = _mm256_setzero_ps(), two = _mm256_set1_ps(2.0f), onef = _mm256_set1_ps(1.0f);
  CellStepLanes c;
  const __m256 tx = cell_exits(o0, d0, ci), ty = cell_exits(o1, d1, cj);
  c.tb = std_max(t, std_min(std_min(tx, ty), t_out));
  const __m256i ci1 = _mm256_add_epi32(ci, one), cj1 = _mm256_add_epi32(cj, one);
  const __m256 h00 = corner(heights, ci, cj, nv, stepped), h10 = corner(heights, ci1, cj, nv, stepped);
  const __m256 h01 = corner(heights, ci, cj1, nv, stepped), h11 = corner(heights, ci1, cj1, nv, stepped);
  const __m256 fci = _mm256_cvtepi32_ps(ci), fcj = _mm256_cvtepi32_ps(cj);
  const __m256 tm = _mm256_mul_ps(_mm256_add_ps(t, c.tb), half);
  const __m256 fa = cell_above(o0, o1, o2, d0, d1, d2, t, fci, fcj, h00, h10, h01, h11);
  const __m256 fb = cell_above(o0, o1, o2, d0, d1, d2, c.tb, fci, fcj, h00, h10, h01, h11);
  const __m256 fm = cell_above(o0, o1, o2, d0, d1, d2, tm, fci, fcj, h00, h10, h01, h11);
  const __m256 q2 = _mm256_mul_ps(two, _mm256_add_ps(_mm256_sub_ps(fa, _mm256_mul_ps(two, fm)), fb));
  const __m256 q1 = _mm256_sub_ps(_mm256_sub_ps(fb, fa), q2);
  const __m256 sv = _mm256_div_ps(_mm256_sub_ps(zero, q1), _mm256_mul_ps(two, q2));
  const __m256 tv = _mm256_add_ps(t, _mm256_mul_ps(sv, _mm256_sub_ps(c.tb, t)));
  const __m256 fv = cell_above(o0, o1, o2, d0, d1, d2, tv, fci, fcj, h00, h10, h01, h11);
  const __m256 steppedf = _mm256_castsi256_ps(stepped);
  c.entry = _mm256_and_ps(steppedf, _mm256_cmp_ps(fa, zero, _CMP_LE_OQ));
  const __m256 hit_exit = _mm256_andnot_ps(c.entry, _mm256_and_ps(steppedf, _mm256_cmp_ps(fb, zero, _CMP_LE_OQ)));
  const __m256 not_yet = _mm256_andnot_ps(_mm256_or_ps(c.entry, hit_exit), steppedf);
  const __m256 hit_middle = _mm256_and_ps(not_yet, _mm256_cmp_ps(fm, zero, _CMP_LE_OQ));
  const __m256 dip = _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(q2, zero, _CMP_GT_OQ), _mm256_cmp_ps(sv, zero, _CMP_GT_OQ)),
                                   _mm256_and_ps(_mm256_cmp_ps(sv, onef, _CMP_LT_OQ), _mm256_cmp_ps(fv, zero, _CMP_LE_OQ)));
  const __m256 hit_dip = _mm256_andnot_ps(hit_middle, _mm256_and_ps(not_yet, dip));
  c.refined = _mm256_or_ps(_mm256_or_ps(hit_exit, hit_middle), hit_dip);
  c.end_b = select(c.entry, t, select(hit_exit, c.tb, select(hit_middle, tm, tv)));
  const __m256i x_first = _mm256_castps_si256(_mm256_cmp_ps(tx, ty, _CMP_LT_OQ)), y_first = _mm256_castps_si256(_mm256_cmp_ps(ty, tx, _CMP_LT_OQ));
  c.next_ci = _mm256_add_epi32(ci, _mm256_andnot_si256(y_first, sx));
  c.next_cj = _mm256_add_epi32(cj, _mm256_andnot_si256(x_first, sy));
  const __m256i hit = _mm256_castps_si256(_mm256_or_ps(c.entry, c.refined));
  c.goes_on = _mm256_andnot_si256(hit, _mm256_and_si256(_mm256_and_si256(stepped, cells_inside(c.next_ci, c.next_cj, nv)),
                                                        _mm256_castps_si256(_mm256_cmp_ps(c.tb, t_out, _CMP_LT_OQ))));
  return c;
}

// Lines a and b can be each their set's last at once (set: line & mask): the same line, or in
// different sets.
[[gnu::target(NBSIM_LANES_TARGET)]] inline __m256i apart_lines(__m256i mask, __m256i a, __m256i b) {
  const __m256i same_set = _mm256_cmpeq_epi32(_mm256_and_si256(a, mask), _mm256_and_si256(b, mask));
  return _mm256_or_si256(_mm256_cmpeq_epi32(a, b), _mm256_xor_si256(same_set, _mm256_set1_epi32(-1)));
}

// The lanes' rows gone through in order: each lane's cells but the repeats listed in its column of
// `kept`, in its rays' order, then each ray's recorded (its first height, its cells listed) and its
// repeats counted.
[[gnu::target(NBSIM_LANES_TARGET)]] void replay_repeats(CellLog& log, const FieldView& field, LookupLines& lines) {
  const std::vector<CellLog::Ray>& rays = log.rays;
  const std::vector<std::int32_t>& rows = log.rows;
  std::vector<std::int32_t>&kept = log.kept, &counts = log.counts;
  std::vector<std::uint8_t>& begins = log.begins;
  constexpr std::int32_t kNoCell = CellLog::kNoCell;
  std::uint32_t row_count = 0;
  for (const CellLog::Ray& ray : rays)
    if (ray.lane >= 0) row_count = std::max(row_count, ray.row1);
  const std::size_t rows_n = row_count;
  begins.assign(rows_n + 1, 0);
  for (const CellLog::Ray& ray : rays)
    if (ray.lane >= 0) begins[ray.row0] = static_cast<std::uint8_t>(begins[ray.row0] | 1u << ray.lane);
  if (kept.size() < 16 * rows_n) kept.resize(16 * rows_n);
  if (counts.size() < 16 * (rows_n + 1)) counts.resize(16 * (rows_n + 1));
  const int n = field.size;
  const __m256i nv = _mm256_set1_epi32(n), one = _mm256_set1_epi32(1), zero = _mm256_setzero_si256(), minus1 = _mm256_set1_epi32(-1);
  const __m256i four = _mm256_set1_epi32(4), row_bytes = _mm256_set1_epi32(4 * n);
  const __m256i mask = _mm256_set1_epi32(static_cast<std::int32_t>(lines.set_mask()));
  const __m128i shift = _mm_cvtsi32_si128(lines.line_shift());
  const __m256i no_cell = _mm256_set1_epi32(kNoCell), lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  // Per lane: the lines of the cell before (valid: in the field, its lines each their set's last),
  // and the counts so far (vectors: a row's are stored whole and read lane by lane, never the other way).
  __m256i pa = zero, pa2 = zero, pb = zero, pb2 = zero, valid = zero, kept_count = zero, cell_count = zero;
  alignas(32) std::int32_t pairs[16];
  std::int32_t* const out = kept.data();
  for (std::size_t row = 0; row < rows_n; ++row) {
    std::int32_t* const count_row = counts.data() + 16 * row;
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(count_row), kept_count);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(count_row + 8), cell_count);
    const std::int32_t* p = rows.data() + 16 * row;
    const __m256i ci = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)), cj = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 8));
    const __m256i begun = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(begins[row]), lane_bit), lane_bit);
    const __m256i cell = _mm256_xor_si256(_mm256_cmpeq_epi32(ci, no_cell), minus1);
    const __m256i inside = _mm256_and_si256(_mm256_and_si256(_mm256_cmpgt_epi32(ci, minus1), _mm256_cmpgt_epi32(cj, minus1)),
                                            _mm256_and_si256(_mm256_cmpgt_epi32(nv, _mm256_add_epi32(ci, one)), _mm256_cmpgt_epi32(nv, _mm256_add_epi32(cj, one))));
    // The lines of the corners (Reader::note's texels: (j n + i) 4, the next texel, the next row).
    const __m256i address = _mm256_slli_epi32(_mm256_add_epi32(_mm256_mullo_epi32(cj, nv), ci), 2);
    const __m256i a = _mm256_srl_epi32(address, shift), a2 = _mm256_srl_epi32(_mm256_add_epi32(address, four), shift);
    const __m256i below = _mm256_add_epi32(address, row_bytes);
    const __m256i b = _mm256_srl_epi32(below, shift), b2 = _mm256_srl_epi32(_mm256_add_epi32(below, four), shift);
    const __m256i same = _mm256_and_si256(_mm256_and_si256(_mm256_cmpeq_epi32(a, pa), _mm256_cmpeq_epi32(a2, pa2)),
                                          _mm256_and_si256(_mm256_cmpeq_epi32(b, pb), _mm256_cmpeq_epi32(b2, pb2)));
    const __m256i repeat = _mm256_andnot_si256(begun, _mm256_and_si256(_mm256_and_si256(cell, inside), _mm256_and_si256(same, valid)));
    // (a and a2, b and b2, are the same line or lines side by side, in different sets.)
    const __m256i apart = _mm256_and_si256(_mm256_and_si256(apart_lines(mask, a, b), apart_lines(mask, a, b2)),
                                           _mm256_and_si256(apart_lines(mask, a2, b), apart_lines(mask, a2, b2)));
    const __m256i lasts = _mm256_and_si256(inside, apart);
    // A lane without a cell this row keeps its cell before (it recorded nothing), unless its ray begins.
    valid = _mm256_andnot_si256(_mm256_andnot_si256(cell, begun), _mm256_blendv_epi8(valid, lasts, cell));
    pa = _mm256_blendv_epi8(pa, a, cell), pa2 = _mm256_blendv_epi8(pa2, a2, cell);
    pb = _mm256_blendv_epi8(pb, b, cell), pb2 = _mm256_blendv_epi8(pb2, b2, cell);
    // Each lane's cell written at its column's end, which moves on when the cell is kept: no branch.
    const __m256i lo = _mm256_unpacklo_epi32(ci, cj), hi = _mm256_unpackhi_epi32(ci, cj);  // lanes 0 1 4 5, 2 3 6 7
    _mm256_store_si256(reinterpret_cast<__m256i*>(pairs), _mm256_permute2x128_si256(lo, hi, 0x20));
    _mm256_store_si256(reinterpret_cast<__m256i*>(pairs + 8), _mm256_permute2x128_si256(lo, hi, 0x31));
    for (std::size_t l = 0; l < 8; ++l)
      std::memcpy(out + 2 * (l * rows_n + static_cast<std::size_t>(count_row[l])), pairs + 2 * l, 2 * sizeof(std::int32_t));
    kept_count = _mm256_sub_epi32(kept_count, _mm256_andnot_si256(repeat, cell));
    cell_count = _mm256_sub_epi32(cell_count, cell);
  }
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(counts.data() + 16 * rows_n), kept_count);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(counts.data() + 16 * rows_n + 8), cell_count);

  LinesSink sink{lines};
  Reader<LinesSink> r{field, sink};
  for (const CellLog::Ray& ray : rays) {
    r.note(ray.first_i, ray.first_j);
    if (ray.lane < 0) continue;
    const auto l = static_cast<std::size_t>(ray.lane);
    const std::int32_t* c0 = counts.data() + 16 * static_cast<std::size_t>(ray.row0);
    const std::int32_t* c1 = counts.data() + 16 * static_cast<std::size_t>(ray.row1);
    const std::int32_t* cells = out + 2 * l * rows_n;
    for (std::int32_t k = c0[l]; k < c1[l]; ++k) r.note(cells[2 * k], cells[2 * k + 1]);
    r.lookups += 4 * static_cast<std::uint32_t>((c1[8 + l] - c0[8 + l]) - (c1[l] - c0[l]));  // the repeats
  }
  sink.walked(r.lookups);
}

// The binary searches (walk_binary) or the robust searches (walk_robust) of a run, eight at a time,
// each ending in bisect()'s bisections: lane by lane the same operations in the same order as the
// one-by-one walks (walk_with's first height in LaneFeed, its end per ray in scalar code). Each
// iteration a lane tests its step's end (binary: t_in + dt * k; robust: its texel's radius ahead of
// t) or its bracket's midpoint, or, for the robust walk where the radius is 0 (robust_clamp takes
// 1), walks one of its up to two cells with the full cell test (full_cell_step; a hit inside a cell
// refined with the run's others). The cells the heights read, and the radius texels, are logged for
// the record as exact_lanes' cells are.
template <Method M>
[[gnu::target(NBSIM_LANES_TARGET)]] void search_lanes(const FieldView& field, const WalkParams& params, std::span<const FragmentRay* const> rays,
                                          std::span<WalkResult> out, CellLog& log, std::vector<Refinement>& refinements) {
  constexpr bool kRobust = M != Method::Binary, kCells = M == Method::Robust;
  const int n = field.size, linear = params.linear_steps, bisections = params.binary_steps, cap = walk_iteration_cap(n);
  LaneFeed feed(field, rays, out, log);
  std::uint32_t row = 0;
  struct alignas(32) SearchLanes {
    float o0[8], o1[8], o2[8], d0[8], d1[8], d2[8];
    float start[8];  // binary: t_in; robust: t_out
    float delta[8];  // binary: dt; robust: the inverse horizontal length (inverse_horizontal)
    float lo[8];     // the last point tested above the surface (t_in at first), or the cell walk's t
    float a[8], b[8];  // the bracket, or (in b) a cell hit's t or its refinement's below end
    std::int32_t k[8];       // steps (binary) or iterations (robust) begun, or bisections done
    std::int32_t bisect[8];  // -1: bisecting the bracket [a, b]
    std::int32_t cell2[8];   // -1: the cell walk's second cell next (robust)
    std::int32_t ci[8], cj[8], sx[8], sy[8];  // the cell walk (robust)
    std::int32_t steps[8], lookups[8];
    std::int32_t ray[8];  // the ray's index in the run, -1: the lane is idle
  } L;

  // Gives lane `l` the run's next ray that needs a walk, or leaves it idle.
  const auto load = [&](int l) {
    const std::ptrdiff_t next = feed.take(l, row, [&](const FragmentRay&, WalkResult& w) {
      w.capped = kRobust && cap <= 0;  // walk_robust capped before its first step
      return w.capped;
    });
    L.o0[l] = L.o1[l] = L.o2[l] = L.d0[l] = L.d1[l] = L.d2[l] = L.start[l] = L.delta[l] = L.lo[l] = L.a[l] = L.b[l] = 0.0f;
    L.k[l] = L.bisect[l] = L.cell2[l] = L.ci[l] = L.cj[l] = L.sx[l] = L.sy[l] = L.steps[l] = L.lookups[l] = 0;
    L.ray[l] = static_cast<std::int32_t>(next);
    if (next < 0) return;
    const FragmentRay& ray = *rays[static_cast<std::size_t>(next)];
    L.o0[l] = ray.o[0], L.o1[l] = ray.o[1], L.o2[l] = ray.o[2];
    L.d0[l] = ray.d[0], L.d1[l] = ray.d[1], L.d2[l] = ray.d[2];
    L.start[l] = kRobust ? ray.t_out : ray.t_in;
    L.delta[l] = kRobust ? inverse_horizontal(ray) : (ray.t_out - ray.t_in) / static_cast<float>(linear);
    L.lo[l] = ray.t_in;
    L.sx[l] = ray.d[0] > 0.0f ? 1 : -1, L.sy[l] = ray.d[1] > 0.0f ? 1 : -1;
    L.lookups[l] = 4;  // the first height
  };

  for (int l = 0; l < 8; ++l) load(l);
  const __m256i nv = _mm256_set1_epi32(n), one = _mm256_set1_epi32(1), four = _mm256_set1_epi32(4), minus1 = _mm256_set1_epi32(-1);
  const __m256i zeroi = _mm256_setzero_si256(), no_cell = _mm256_set1_epi32(CellLog::kNoCell);
  const __m256i last_texel = _mm256_set1_epi32(n - 1), last_bisection = _mm256_set1_epi32(bisections);
  const __m256i last_step = _mm256_set1_epi32(kRobust ? cap : linear);
  const __m256 half = _mm256_set1_ps(0.5f), zero = _mm256_setzero_ps(), onef = _mm256_set1_ps(1.0f);
  const float* heights = field.heights.data();
  for (;;) {
    const __m256i live = _mm256_cmpgt_epi32(load_i(L.ray), minus1);
    if (_mm256_testz_si256(live, live)) break;
    const __m256 o0 = _mm256_load_ps(L.o0), o1 = _mm256_load_ps(L.o1), o2 = _mm256_load_ps(L.o2);
    const __m256 d0 = _mm256_load_ps(L.d0), d1 = _mm256_load_ps(L.d1), d2 = _mm256_load_ps(L.d2);
    const __m256 start = _mm256_load_ps(L.start), delta = _mm256_load_ps(L.delta);
    const __m256 lo = _mm256_load_ps(L.lo), a = _mm256_load_ps(L.a), b = _mm256_load_ps(L.b);
    const __m256i k = load_i(L.k), bisecting = load_i(L.bisect), cell2 = load_i(L.cell2);
    const __m256 bisectingf = _mm256_castsi256_ps(bisecting);
    // Stepping lanes begin an iteration (robust: with their texel's radius).
    const __m256i stepping = _mm256_andnot_si256(_mm256_or_si256(bisecting, cell2), live);
    __m256 step_end;
    __m256i rindex = minus1, zero_radius = zeroi;
    if constexpr (kRobust) {
      // The radius of the texel under lo (clamped into the field) and the step's end: t_out for a
      // vertical ray, else min(lo + radius * inv, t_out).
      const __m256i ri = clamp_lanes(floor_lanes(_mm256_add_ps(o0, _mm256_mul_ps(lo, d0))), zeroi, last_texel);
      const __m256i rj = clamp_lanes(floor_lanes(_mm256_add_ps(o1, _mm256_mul_ps(lo, d1))), zeroi, last_texel);
      rindex = _mm256_blendv_epi8(minus1, _mm256_add_epi32(_mm256_mullo_epi32(rj, nv), ri), stepping);
      __m256 rad = _mm256_mask_i32gather_ps(zero, field.radius.data(), rindex, _mm256_castsi256_ps(stepping), 4);
      const __m256 radius_zero = _mm256_cmp_ps(rad, zero, _CMP_EQ_OQ);
      if constexpr (kCells) zero_radius = _mm256_and_si256(stepping, _mm256_castps_si256(radius_zero));
      else rad = select(radius_zero, onef, rad);
      step_end = select(_mm256_cmp_ps(delta, zero, _CMP_EQ_OQ), start, std_min(_mm256_add_ps(lo, _mm256_mul_ps(rad, delta)), start));
    } else {
      step_end = _mm256_add_ps(start, _mm256_mul_ps(delta, _mm256_cvtepi32_ps(_mm256_add_epi32(k, one))));
    }
    // The lanes that test a point (a step's end or the bracket's midpoint) and those that walk a cell.
    const __m256i cells = _mm256_or_si256(zero_radius, cell2);
    const __m256i pointing = _mm256_andnot_si256(cells, live);
    const __m256 m = _mm256_mul_ps(_mm256_add_ps(a, b), half);
    const __m256 p = select(bisectingf, m, step_end);
    const __m256i i = floor_lanes(_mm256_sub_ps(_mm256_add_ps(o0, _mm256_mul_ps(p, d0)), half));
    const __m256i j = floor_lanes(_mm256_sub_ps(_mm256_add_ps(o1, _mm256_mul_ps(p, d1)), half));
    const __m256i i1 = _mm256_add_epi32(i, one), j1 = _mm256_add_epi32(j, one);
    const __m256 h00 = corner(heights, i, j, nv, pointing), h10 = corner(heights, i1, j, nv, pointing);
    const __m256 h01 = corner(heights, i, j1, nv, pointing), h11 = corner(heights, i1, j1, nv, pointing);
    const __m256 f = cell_above(o0, o1, o2, d0, d1, d2, p, _mm256_cvtepi32_ps(i), _mm256_cvtepi32_ps(j), h00, h10, h01, h11);
    const __m256 below = _mm256_and_ps(_mm256_castsi256_ps(pointing), _mm256_cmp_ps(f, zero, _CMP_LE_OQ));
    // The cell walks (robust, rare): from lo, in a new walk's first cell or its stored second one.
    __m256i walked = zeroi, cell_miss = zeroi, ci = zeroi, cj = zeroi;
    CellStepLanes cs{};
    if (kCells && !_mm256_testz_si256(cells, cells)) {
      ci = _mm256_blendv_epi8(cell_indices(o0, lo, d0, last_texel), load_i(L.ci), cell2);
      cj = _mm256_blendv_epi8(cell_indices(o1, lo, d1, last_texel), load_i(L.cj), cell2);
      walked = _mm256_and_si256(_mm256_and_si256(cells, cells_inside(ci, cj, nv)), _mm256_castps_si256(_mm256_cmp_ps(lo, start, _CMP_LT_OQ)));
      cell_miss = _mm256_andnot_si256(walked, cells);
      cs = full_cell_step(heights, nv, o0, o1, o2, d0, d1, d2, lo, start, ci, cj, load_i(L.sx), load_i(L.sy), walked);
    }
    std::int32_t* logged = CellLog::slot(log.rows, row, 16);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged), _mm256_blendv_epi8(_mm256_blendv_epi8(no_cell, ci, walked), i, pointing));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged + 8), _mm256_blendv_epi8(cj, j, pointing));
    if constexpr (kRobust) {
      log.with_radii = true;
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(CellLog::slot(log.radii, row, 8)), rindex);
    }
    // Point lanes: a stepping one below starts the bracket [lo, step_end] (bisections from 0), else
    // lo moves to the step's end; a bisecting one takes [a, m] below, else [m, b].
    const __m256 stepped_pointf = _mm256_castsi256_ps(_mm256_and_si256(pointing, stepping));
    const __m256 bracket = _mm256_and_ps(stepped_pointf, below);
    const __m256 cell_hit = _mm256_or_ps(cs.entry, cs.refined);
    const __m256i moved = _mm256_andnot_si256(_mm256_castps_si256(cell_hit), walked);
    _mm256_store_ps(L.a, select(bisectingf, select(below, a, m), select(bracket, lo, a)));
    _mm256_store_ps(L.b, select(bisectingf, select(below, m, b), select(bracket, step_end, select(cell_hit, cs.end_b, b))));
    _mm256_store_ps(L.lo, select(stepped_pointf, step_end, select(_mm256_castsi256_ps(moved), cs.tb, lo)));
    const __m256i bracketi = _mm256_castps_si256(bracket);
    const __m256i next_k = _mm256_blendv_epi8(_mm256_add_epi32(k, _mm256_and_si256(one, _mm256_or_si256(stepping, bisecting))), zeroi, bracketi);
    store_i(L.k, next_k);
    const __m256i now_bisecting = _mm256_or_si256(bisecting, bracketi);
    store_i(L.bisect, now_bisecting);
    // A cell walk goes on from its first cell to its second; from its second, to the next iteration.
    const __m256i to_cell2 = _mm256_andnot_si256(cell2, cs.goes_on);
    store_i(L.cell2, to_cell2);
    store_i(L.ci, _mm256_blendv_epi8(load_i(L.ci), _mm256_blendv_epi8(ci, cs.next_ci, moved), walked));
    store_i(L.cj, _mm256_blendv_epi8(load_i(L.cj), _mm256_blendv_epi8(cj, cs.next_cj, moved), walked));
    // Counts: a step a point stepped to and a cell walked; a radius an iteration begun, four heights a
    // point or a cell.
    const __m256i stepped_point = _mm256_castps_si256(stepped_pointf);
    store_i(L.steps, _mm256_sub_epi32(_mm256_sub_epi32(load_i(L.steps), stepped_point), walked));
    __m256i looked = _mm256_and_si256(four, _mm256_or_si256(pointing, walked));
    if constexpr (kRobust) looked = _mm256_sub_epi32(looked, stepping);
    store_i(L.lookups, _mm256_add_epi32(load_i(L.lookups), looked));
    ++row;
    // Ends: a bracket with no bisection to run or after its last bisection; a stepping point with
    // neither (binary: the last linear step, a miss; robust: one that reached t_out, a miss, or else
    // the cap-th iteration, capped); a cell hit; a cell walk that ran out of the field or to t_out; a
    // cell walk's second cell after the cap-th iteration (capped).
    const __m256i bisected = _mm256_and_si256(now_bisecting, _mm256_cmpeq_epi32(next_k, last_bisection));
    const __m256i still_stepping = _mm256_andnot_si256(bracketi, stepped_point);
    const __m256i missed = kRobust ? _mm256_castps_si256(_mm256_cmp_ps(step_end, start, _CMP_GE_OQ)) : _mm256_cmpeq_epi32(next_k, last_step);
    const __m256i at_cap = _mm256_cmpeq_epi32(next_k, last_step);
    const __m256i step_capped = kRobust ? _mm256_and_si256(still_stepping, _mm256_andnot_si256(missed, at_cap)) : zeroi;
    const __m256i cells_out = _mm256_or_si256(cell_miss, _mm256_andnot_si256(cs.goes_on, moved));
    const __m256i cell_capped = _mm256_and_si256(_mm256_and_si256(cell2, cs.goes_on), at_cap);
    const __m256i capped = _mm256_or_si256(step_capped, cell_capped);
    const __m256i ends = _mm256_or_si256(_mm256_or_si256(bisected, _mm256_and_si256(still_stepping, missed)),
                                         _mm256_or_si256(_mm256_or_si256(_mm256_castps_si256(cell_hit), cells_out), capped));
    const int ended = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_and_si256(live, ends)));
    if (ended == 0) continue;
    const int capped_bits = _mm256_movemask_ps(_mm256_castsi256_ps(capped)), refined_bits = _mm256_movemask_ps(cs.refined);
    const int entry_bits = _mm256_movemask_ps(cs.entry);
    for (int l = 0; l < 8; ++l) {
      if (!(ended >> l & 1)) continue;
      const auto r = static_cast<std::size_t>(L.ray[l]);
      log.rays[r].row1 = row;
      WalkResult& w = out[r];
      const FragmentRay& ray = *rays[r];
      w.steps = static_cast<std::uint32_t>(L.steps[l]);
      w.lookups = static_cast<std::uint32_t>(L.lookups[l]);
      if (L.bisect[l]) {  // the bracket's bisections done: a hit at its below end
        w.bisections = static_cast<std::uint32_t>(bisections);
        set_hit(w, L.b[l]);
      } else if (entry_bits >> l & 1) {
        set_hit(w, L.b[l]);
      } else if (refined_bits >> l & 1) {  // refined from lo
        feed.refine_later(r, L.ci[l], L.cj[l], L.lo[l], L.b[l], params.root_steps, refinements);
      } else {
        w.capped = capped_bits >> l & 1;
      }
      end_walk(w, ray);
      load(l);
    }
  }
}

// The paper's covering with top alignment (cover(): paper(), grid(), anchors()) of the rectangles
// [i0, i0 + w) x [j0, j0 + h) (w, h >= 1, i0, j0 >= 0) in eight lanes: the level, and square q's
// lower-left corner (x[q], y[q]) for q below `count` (the squares row by row, as grid() lists them).
struct CoverLanes {
  __m256i level, count, x[4], y[4];
};
[[gnu::target(NBSIM_LANES_TARGET)]] inline CoverLanes cover_paper_top(__m256i i0, __m256i j0, __m256i w, __m256i h) {
  const __m256i one = _mm256_set1_epi32(1), zero = _mm256_setzero_si256();
  // ceil_log2(max(w, h)): bit_width(m - 1), from the exponent of m - 1 as a float (exact below 2^24).
  const __m256i m1 = _mm256_sub_epi32(_mm256_max_epi32(w, h), one);
  const __m256i exponent = _mm256_sub_epi32(_mm256_srli_epi32(_mm256_castps_si256(_mm256_cvtepi32_ps(m1)), 23), _mm256_set1_epi32(126));
  const __m256i s_log = _mm256_and_si256(_mm256_cmpgt_epi32(m1, zero), exponent);
  const __m256i q = _mm256_srli_epi32(_mm256_sllv_epi32(one, s_log), 1);
  const __m256i wide = _mm256_cmpgt_epi32(w, q), tall = _mm256_cmpgt_epi32(h, q);
  const __m256i quadrants = _mm256_and_si256(wide, tall);
  // Four in a row (wide, 2 h <= q) or a column (not wide, 2 w <= q): squares of q / 2.
  const __m256i row4 = _mm256_andnot_si256(quadrants, _mm256_and_si256(wide, _mm256_cmpgt_epi32(_mm256_add_epi32(q, one), _mm256_add_epi32(h, h))));
  const __m256i col4 = _mm256_andnot_si256(wide, _mm256_cmpgt_epi32(_mm256_add_epi32(q, one), _mm256_add_epi32(w, w)));
  const __m256i fourth = _mm256_or_si256(row4, col4);
  const __m256i level = _mm256_andnot_si256(_mm256_cmpeq_epi32(s_log, zero),
                                            _mm256_sub_epi32(s_log, _mm256_blendv_epi8(one, _mm256_set1_epi32(2), fourth)));
  const __m256i side = _mm256_sllv_epi32(one, level), side1 = _mm256_sub_epi32(side, one);
  // anchors(): one square when the span fits in one (x flush with the start; y flush with the end,
  // moved up to 0), else ceil(len / side), one every side from the start and the last flush with the end.
  const __m256i x_one = _mm256_cmpgt_epi32(_mm256_add_epi32(side, one), w), y_one = _mm256_cmpgt_epi32(_mm256_add_epi32(side, one), h);
  const __m256i nx = _mm256_blendv_epi8(_mm256_srlv_epi32(_mm256_add_epi32(w, side1), level), one, x_one);
  const __m256i ny = _mm256_blendv_epi8(_mm256_srlv_epi32(_mm256_add_epi32(h, side1), level), one, y_one);
  const __m256i x_last = _mm256_sub_epi32(_mm256_add_epi32(i0, w), side), y_last = _mm256_sub_epi32(_mm256_add_epi32(j0, h), side);
  const __m256i y_single = _mm256_max_epi32(y_last, zero);
  CoverLanes c;
  c.level = level;
  c.count = _mm256_mullo_epi32(nx, ny);
  const __m256i nx_is1 = _mm256_cmpeq_epi32(nx, one), nx_is2 = _mm256_cmpeq_epi32(nx, _mm256_set1_epi32(2));
  for (int k = 0; k < 4; ++k) {
    const __m256i qk = _mm256_set1_epi32(k);
    // Square k's column and row: nx 1: (0, k); nx 2: (k & 1, k >> 1); nx 3 or 4: (k, 0).
    const __m256i jy = _mm256_blendv_epi8(_mm256_blendv_epi8(zero, _mm256_set1_epi32(k >> 1), nx_is2), qk, nx_is1);
    const __m256i ix = _mm256_sub_epi32(qk, _mm256_mullo_epi32(jy, nx));
    const __m256i x_inner = _mm256_cmpgt_epi32(_mm256_sub_epi32(nx, one), ix), y_inner = _mm256_cmpgt_epi32(_mm256_sub_epi32(ny, one), jy);
    const __m256i xs = _mm256_blendv_epi8(x_last, _mm256_add_epi32(i0, _mm256_mullo_epi32(ix, side)), x_inner);
    const __m256i ys = _mm256_blendv_epi8(y_last, _mm256_add_epi32(j0, _mm256_mullo_epi32(jy, side)), y_inner);
    c.x[k] = _mm256_blendv_epi8(xs, i0, x_one);
    c.y[k] = _mm256_blendv_epi8(ys, y_single, y_one);
  }
  return c;
}

// The N-buffer walks of a run with the paper's covering (top alignment, no direct squares), eight at
// a time: walk_nbuffer's queries and cell steps, lane by lane the same operations in the same order
// (walk_with's first height in LaneFeed, its end per ray in scalar code). Each iteration is one
// query a lane and, where it fails at a span of one texel, one cell step with the full cell test;
// the hits found inside a cell are refined with the run's others (refine_lanes). The level texels
// and cells read are logged for the record.
[[gnu::target(NBSIM_LANES_TARGET)]] void nbuffer_lanes(const FieldView& field, const WalkParams& params, std::span<const FragmentRay* const> rays,
                                           std::span<WalkResult> out, CellLog& log, std::vector<Refinement>& refinements) {
  const int n = field.size, top = field.levels - 1, cap = walk_iteration_cap(n);
  LaneFeed feed(field, rays, out, log);
  std::uint32_t row = 0;
  struct alignas(32) NBufferLanes {
    float o0[8], o1[8], o2[8], d0[8], d1[8], d2[8], t_out[8], inv[8], t[8];
    float end_a[8], end_b[8];  // a hit's refinement bracket (or its t in end_b), at the iteration that ends it
    std::int32_t s[8];         // the span's exponent
    std::int32_t walking[8];   // -1: ci, cj hold the cell at t (after a cell step)
    std::int32_t ci[8], cj[8], sx[8], sy[8];
    std::int32_t iter[8], steps[8], lookups[8];
    std::int32_t ray[8];  // the ray's index in the run, -1: the lane is idle
  } L;

  // Gives lane `l` the run's next ray that needs a walk, or leaves it idle.
  const auto load = [&](int l) {
    const std::ptrdiff_t next = feed.take(l, row, [&](const FragmentRay&, WalkResult& w) {
      w.capped = cap <= 0;  // walk_nbuffer capped before its first query
      return w.capped;
    });
    if (next >= 0) {
      const auto k = static_cast<std::size_t>(next);
      const FragmentRay& ray = *rays[k];
      L.o0[l] = ray.o[0], L.o1[l] = ray.o[1], L.o2[l] = ray.o[2];
      L.d0[l] = ray.d[0], L.d1[l] = ray.d[1], L.d2[l] = ray.d[2];
      L.t_out[l] = ray.t_out, L.inv[l] = inverse_horizontal(ray), L.t[l] = ray.t_in;
      L.end_a[l] = L.end_b[l] = 0.0f;
      L.s[l] = 0, L.walking[l] = 0, L.ci[l] = L.cj[l] = 0;
      L.sx[l] = ray.d[0] > 0.0f ? 1 : -1, L.sy[l] = ray.d[1] > 0.0f ? 1 : -1;
      L.iter[l] = 0, L.steps[l] = 0, L.lookups[l] = 4;
      L.ray[l] = static_cast<std::int32_t>(k);
      return;
    }
    L.ray[l] = -1;
    L.o0[l] = L.o1[l] = L.o2[l] = L.d0[l] = L.d1[l] = L.d2[l] = L.t_out[l] = L.inv[l] = L.t[l] = L.end_a[l] = L.end_b[l] = 0.0f;
    L.s[l] = L.walking[l] = L.ci[l] = L.cj[l] = L.sx[l] = L.sy[l] = L.iter[l] = L.steps[l] = L.lookups[l] = 0;
  };

  for (int l = 0; l < 8; ++l) load(l);
  const __m256i nv = _mm256_set1_epi32(n), one = _mm256_set1_epi32(1), minus1 = _mm256_set1_epi32(-1), zeroi = _mm256_setzero_si256();
  const __m256i last_texel = _mm256_set1_epi32(n - 1), topv = _mm256_set1_epi32(top), capv = _mm256_set1_epi32(cap);
  const __m256i no_cell = _mm256_set1_epi32(CellLog::kNoCell);
  const __m256 half = _mm256_set1_ps(0.5f), zero = _mm256_setzero_ps();
  const float* heights = field.heights.data();
  const float* levels = field.nbuffer.data();
  for (;;) {
    const __m256i live = _mm256_cmpgt_epi32(load_i(L.ray), minus1);
    if (_mm256_testz_si256(live, live)) break;
    const __m256 o0 = _mm256_load_ps(L.o0), o1 = _mm256_load_ps(L.o1), o2 = _mm256_load_ps(L.o2);
    const __m256 d0 = _mm256_load_ps(L.d0), d1 = _mm256_load_ps(L.d1), d2 = _mm256_load_ps(L.d2);
    const __m256 t_out = _mm256_load_ps(L.t_out), inv = _mm256_load_ps(L.inv), t = _mm256_load_ps(L.t);
    const __m256i s = load_i(L.s);
    // The query: the span of 2^s texels of horizontal travel from t, and the N-buffer's maximum
    // over the texels its surface depends on (nbuffer_max).
    const __m256 texels = _mm256_cvtepi32_ps(_mm256_sllv_epi32(one, s));
    const __m256 te = select(_mm256_cmp_ps(inv, zero, _CMP_EQ_OQ), t_out, std_min(_mm256_add_ps(t, _mm256_mul_ps(texels, inv)), t_out));
    const __m256 xa = _mm256_add_ps(o0, _mm256_mul_ps(t, d0)), xb = _mm256_add_ps(o0, _mm256_mul_ps(te, d0));
    const __m256 ya = _mm256_add_ps(o1, _mm256_mul_ps(t, d1)), yb = _mm256_add_ps(o1, _mm256_mul_ps(te, d1));
    const __m256 x0 = std_min(xa, xb), x1 = std_max(xa, xb), y0 = std_min(ya, yb), y1 = std_max(ya, yb);
    const __m256i i0 = clamp_lanes(floor_lanes(_mm256_sub_ps(x0, half)), zeroi, last_texel);
    const __m256i i1 = clamp_lanes(_mm256_add_epi32(floor_lanes(_mm256_sub_ps(x1, half)), one), zeroi, last_texel);
    const __m256i j0 = clamp_lanes(floor_lanes(_mm256_sub_ps(y0, half)), zeroi, last_texel);
    const __m256i j1 = clamp_lanes(_mm256_add_epi32(floor_lanes(_mm256_sub_ps(y1, half)), one), zeroi, last_texel);
    const CoverLanes c = cover_paper_top(i0, j0, _mm256_add_epi32(_mm256_sub_epi32(i1, i0), one), _mm256_add_epi32(_mm256_sub_epi32(j1, j0), one));
    if (!_mm256_testz_si256(live, _mm256_cmpgt_epi32(c.level, topv))) {  // cover()'s check, with its message
      for (int l = 0; l < 8; ++l)
        if (L.ray[l] >= 0) {
          alignas(32) std::int32_t a[4][8];
          store_i(a[0], i0), store_i(a[1], j0), store_i(a[2], i1), store_i(a[3], j1);
          (void)cover(Rect{a[0][l], a[1][l], a[2][l] - a[0][l] + 1, a[3][l] - a[1][l] + 1}, params.covering, top);
        }
    }
    const __m256i plane = _mm256_mullo_epi32(c.level, nv);
    log.with_texels = true;
    std::int32_t* logged_texels = CellLog::slot(log.texels, row, 32);
    __m256 top_height = zero;
    for (int k = 0; k < 4; ++k) {
      const __m256i read = _mm256_and_si256(live, _mm256_cmpgt_epi32(c.count, _mm256_set1_epi32(k)));
      const __m256i index = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(plane, c.y[k]), nv), c.x[k]);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged_texels + 8 * k), _mm256_blendv_epi8(minus1, index, read));
      const __m256 v = _mm256_mask_i32gather_ps(zero, levels, index, _mm256_castsi256_ps(read), 4);
      top_height = k == 0 ? v : select(_mm256_castsi256_ps(read), std_max(top_height, v), top_height);
    }
    const __m256 lowest = std_min(_mm256_add_ps(o2, _mm256_mul_ps(t, d2)), _mm256_add_ps(o2, _mm256_mul_ps(te, d2)));
    const __m256i pass = _mm256_castps_si256(_mm256_cmp_ps(lowest, top_height, _CMP_GT_OQ));
    const __m256i s0 = _mm256_cmpeq_epi32(s, zeroi);
    // A failed query at s = 0: a cell step (the cell walk started at t when not walking).
    const __m256i walking = load_i(L.walking);
    const __m256i cell_try = _mm256_and_si256(live, _mm256_andnot_si256(pass, s0));
    const __m256i ci = _mm256_blendv_epi8(cell_indices(o0, t, d0, last_texel), load_i(L.ci), walking);
    const __m256i cj = _mm256_blendv_epi8(cell_indices(o1, t, d1, last_texel), load_i(L.cj), walking);
    const __m256i before_end = _mm256_castps_si256(_mm256_cmp_ps(t, t_out, _CMP_LT_OQ));
    const __m256i stepped = _mm256_and_si256(cell_try, _mm256_and_si256(cells_inside(ci, cj, nv), before_end));  // the lanes that read a cell
    const __m256i cell_miss = _mm256_andnot_si256(stepped, cell_try);                                              // ended before it
    CellStepLanes cs{};  // no hit and no walk on where no lane steps
    if (!_mm256_testz_si256(stepped, stepped))
      cs = full_cell_step(heights, nv, o0, o1, o2, d0, d1, d2, t, t_out, ci, cj, load_i(L.sx), load_i(L.sy), stepped);
    std::int32_t* logged = CellLog::slot(log.rows, row, 16);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged), _mm256_blendv_epi8(no_cell, ci, stepped));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(logged + 8), cj);
    _mm256_store_ps(L.end_a, t);
    _mm256_store_ps(L.end_b, cs.end_b);
    const __m256 hit_entry = cs.entry, refined = cs.refined;
    const __m256 tb = cs.tb;
    const __m256i next_ci = cs.next_ci, next_cj = cs.next_cj;
    // The walk goes on: a passed query moves t to the span's end (not walking, s up to the top);
    // a failed one at s > 0 halves the span; a cell step without a hit moves to the next cell.
    const __m256i hit = _mm256_castps_si256(_mm256_or_ps(hit_entry, refined));
    const __m256i moved = _mm256_andnot_si256(hit, stepped);
    const __m256i moved_out = _mm256_andnot_si256(cs.goes_on, moved);
    const __m256i passed = _mm256_and_si256(live, pass);
    const __m256i passed_out = _mm256_and_si256(passed, _mm256_castps_si256(_mm256_cmp_ps(te, t_out, _CMP_GE_OQ)));
    const __m256i halved = _mm256_andnot_si256(_mm256_or_si256(pass, s0), live);
    _mm256_store_ps(L.t, select(_mm256_castsi256_ps(passed), te, select(_mm256_castsi256_ps(moved), tb, t)));
    store_i(L.s, _mm256_blendv_epi8(_mm256_blendv_epi8(s, _mm256_sub_epi32(s, one), halved), _mm256_min_epi32(_mm256_add_epi32(s, one), topv), passed));
    store_i(L.walking, _mm256_blendv_epi8(_mm256_andnot_si256(passed, walking), minus1, moved));
    store_i(L.ci, _mm256_blendv_epi8(load_i(L.ci), next_ci, moved));
    store_i(L.cj, _mm256_blendv_epi8(load_i(L.cj), next_cj, moved));
    const __m256i hit_cells = _mm256_and_si256(hit, stepped);  // a hit keeps its cell (for the refinement)
    store_i(L.ci, _mm256_blendv_epi8(load_i(L.ci), ci, hit_cells));
    store_i(L.cj, _mm256_blendv_epi8(load_i(L.cj), cj, hit_cells));
    // Counts: a step a query and a cell step; the query's texels and a cell's four corners.
    store_i(L.steps, _mm256_add_epi32(load_i(L.steps), _mm256_sub_epi32(one, stepped)));
    store_i(L.lookups, _mm256_add_epi32(load_i(L.lookups), _mm256_add_epi32(_mm256_and_si256(live, c.count), _mm256_and_si256(stepped, _mm256_set1_epi32(4)))));
    const __m256i iter = _mm256_add_epi32(load_i(L.iter), one);
    store_i(L.iter, iter);
    ++row;
    const __m256i missed = _mm256_or_si256(_mm256_or_si256(passed_out, cell_miss), moved_out);
    const __m256i going = _mm256_andnot_si256(_mm256_or_si256(missed, hit), live);
    const __m256i capped = _mm256_and_si256(going, _mm256_cmpeq_epi32(iter, capv));
    const int ended = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_and_si256(live, _mm256_or_si256(_mm256_or_si256(missed, hit), capped))));
    if (ended == 0) continue;
    const int entry_bits = _mm256_movemask_ps(hit_entry), refined_bits = _mm256_movemask_ps(refined);
    const int capped_bits = _mm256_movemask_ps(_mm256_castsi256_ps(capped));
    for (int l = 0; l < 8; ++l) {
      if (!(ended >> l & 1)) continue;
      const auto r = static_cast<std::size_t>(L.ray[l]);
      log.rays[r].row1 = row;
      WalkResult& w = out[r];
      const FragmentRay& ray = *rays[r];
      w.steps = static_cast<std::uint32_t>(L.steps[l]);
      w.lookups = static_cast<std::uint32_t>(L.lookups[l]);
      if (entry_bits >> l & 1) {
        set_hit(w, L.end_b[l]);
      } else if (refined_bits >> l & 1) {
        feed.refine_later(r, L.ci[l], L.cj[l], L.end_a[l], L.end_b[l], params.root_steps, refinements);
      } else if (capped_bits >> l & 1) {
        w.capped = true;
      }
      end_walk(w, ray);
      load(l);
    }
  }
}

// The log's texels recorded: the repeats left out where they can be found (CellLog::repeats_known).
[[gnu::target(NBSIM_LANES_TARGET)]] inline void replay_log(CellLog& log, const FieldView& field, LookupLines& lines) {
  if (!log.with_radii && !log.with_texels && CellLog::repeats_known(field, lines)) replay_repeats(log, field, lines);
  else log.replay(field, lines);
}

// walk_each's walks in lanes (false: this method walks one by one).
[[gnu::target(NBSIM_LANES_TARGET)]] bool walk_lanes(Method method, const FieldView& field, const WalkParams& params,
                                                    std::span<const FragmentRay* const> rays, std::span<WalkResult> out, LookupLines* lines) {
  if (method == Method::Exact || method == Method::NBuffer) {
    thread_local std::vector<Refinement> refinements;
    refinements.clear();
    if (method == Method::Exact) {
      thread_local CellLog log;
      exact_lanes(field, params, rays, out, log, refinements);
      if (lines) replay_log(log, field, *lines);
    } else if (params.covering == CoveringSpec{}) {  // the paper's covering: in lanes
      thread_local CellLog log;
      nbuffer_lanes(field, params, rays, out, log, refinements);
      if (lines) replay_log(log, field, *lines);
    } else {  // one by one, the hits' refinements left for refine_lanes
      for (std::size_t k = 0; k < rays.size(); ++k) {
        Deferred deferred;
        if (lines) {
          LinesSink sink{*lines};
          out[k] = walk_with(method, field, params, *rays[k], sink, &deferred);
        } else {
          ObserverSink sink{nullptr, nullptr};
          out[k] = walk_with(method, field, params, *rays[k], sink, &deferred);
        }
        if (deferred.pending) refinements.push_back(Refinement{rays[k], deferred.cell, deferred.a, deferred.b, k});
      }
    }
    refine_lanes(refinements, params.root_steps, out);
    return true;
  }
  if (method == Method::Binary || method == Method::Robust || method == Method::RobustClamp) {
    thread_local CellLog log;
    thread_local std::vector<Refinement> refinements;
    refinements.clear();
    if (method == Method::Binary) search_lanes<Method::Binary>(field, params, rays, out, log, refinements);
    else if (method == Method::Robust) search_lanes<Method::Robust>(field, params, rays, out, log, refinements);
    else search_lanes<Method::RobustClamp>(field, params, rays, out, log, refinements);
    if (lines) replay_log(log, field, *lines);
    refine_lanes(refinements, params.root_steps, out);
    return true;
  }
  return false;
}
