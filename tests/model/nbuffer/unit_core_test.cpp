// NBufferUnitCoreTest: the N-buffer unit's core (model/nbuffer/unit_core.h) against brute force:
// conservative answers under every policy, divisor, format and level cap on random change and
// query sequences; policies agreeing once applied; statistics and work matching the answers.
#include "model/nbuffer/unit_core.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim::nbuffer {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};
constexpr const char* kPolicies[] = {"eager", "batched", "lazy", "on_demand"};
constexpr int kDivisors[] = {1, 2, 4, 8};

std::string where(FarOp op, const std::string& policy, int d, const std::string& format) {
  return "op " + std::string(to_string(op)) + ", policy " + policy + ", divisor " + std::to_string(d) + ", format " +
         format;
}

// The reduced image by definition: texel (x, y) is the farthest of the depth pixels of its block.
DepthImage reduce(const DepthImage& img, int d, FarOp op) {
  DepthImage r((img.width + d - 1) / d, (img.height + d - 1) / d, 0.0f);
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) r.at(x, y) = ref::farthest(img, op, {x * d, y * d, d, d});
  return r;
}

// A random depth value for a change: usually nearer than the old one (a LESS depth test passing),
// sometimes anything (GL_ALWAYS, depth-func switches), so changes also move depth farther.
float new_depth(std::mt19937& rng, FarOp op, float old, bool anything) {
  const float v = ref::unit_float(rng);
  if (anything) return v;
  return op == FarOp::Max ? std::min(old, v) : std::max(old, v);
}

// A depth buffer kept by the test (the truth) and a core fed the same changes.
struct Rig {
  FarOp op;
  NBufferUnitConfig cfg;
  stats::Registry reg;
  std::unique_ptr<NBufferUnitCore> core;
  DepthImage truth;
  UpdateWork work;  // sum of every UpdateWork returned

  Rig(FarOp o, NBufferUnitConfig c, int w, int h, const std::string& name = "gpu.nbuffer")
      : op(o), cfg(std::move(c)), truth(w, h, far_limit(o)) {
    core = std::make_unique<NBufferUnitCore>(cfg, w, h, op, reg.group(name));
  }

  // One random change: a rectangle, a batch of pixel writes or (rarely) a clear.
  void random_change(std::mt19937& rng) {
    const int kind = ref::uniform_int(rng, 0, 19);
    const bool anything = ref::uniform_int(rng, 0, 3) == 0;
    if (kind == 0) {
      const float v = ref::unit_float(rng);
      std::fill(truth.texels.begin(), truth.texels.end(), v);
      work += core->depth_cleared(v);
    } else if (kind < 11) {
      const Rect r = ref::random_rect(rng, truth.width, truth.height, true);
      const Rect c = clip(r, truth.width, truth.height);
      for (int y = c.y; y < c.y1(); ++y)
        for (int x = c.x; x < c.x1(); ++x) truth.at(x, y) = new_depth(rng, op, truth.at(x, y), anything);
      work += core->depth_changed(truth, r);
    } else {
      std::vector<PixelWrite> writes;
      const int n = ref::uniform_int(rng, 1, 40);
      for (int i = 0; i < n; ++i) {
        PixelWrite w{ref::uniform_int(rng, 0, truth.width - 1), ref::uniform_int(rng, 0, truth.height - 1), 0.0f};
        w.depth = new_depth(rng, op, truth.at(w.x, w.y), anything);
        truth.at(w.x, w.y) = w.depth;
        writes.push_back(w);
      }
      work += core->depth_changed(writes);
    }
  }

  // The N-buffer a fresh build over the truth gives (what every policy reaches once applied).
  NBuffer fresh() const {
    return NBuffer(reduce(truth, cfg.resolution_divisor, op),
                   NBufferConfig{op, cfg.storage_format(), cfg.level_cap, cfg.shape(), cfg.max_aspect_log2});
  }
};

// A nearest depth next to the truth: equal, a hair nearer or farther, random, or a limit.
float random_nearest(std::mt19937& rng, FarOp op, float truth) {
  switch (ref::uniform_int(rng, 0, 5)) {
    case 0:
      return truth;
    case 1:
      return std::nextafter(truth, op == FarOp::Max ? 2.0f : -1.0f);  // a hair farther
    case 2:
      return std::nextafter(truth, op == FarOp::Max ? -1.0f : 2.0f);  // a hair nearer
    case 3:
      return far_limit(op);
    case 4:
      return neutral_depth(op);
    default:
      return ref::unit_float(rng);
  }
}

// Checks one answer against the truth; "" when every rule holds.
std::string check(const Rig& rig, const Rect& r, float nearest, const QueryAnswer& a) {
  const Rect c = clip(r, rig.truth.width, rig.truth.height);
  const std::string at = ref::str(r) + " nearest " + std::to_string(nearest) + ": ";
  if (c.empty())
    return a.outcome == QueryOutcome::Offscreen && a.lookups == 0 && !a.hidden ? ""
                                                                               : at + "offscreen: answered on-screen";
  if (a.outcome == QueryOutcome::Offscreen) return at + "offscreen: an on-screen rectangle answered offscreen";
  const float truth = ref::farthest(rig.truth, rig.op, c);
  if (a.complete && !at_least_as_far(rig.op, a.value, truth))
    return at + "conservative: answered " + std::to_string(a.value) + ", nearer than the true farthest " +
           std::to_string(truth);
  if (a.hidden && !hidden_behind(rig.op, nearest, truth))
    return at + "false cull: hidden, but a pixel is at least as near as " + std::to_string(nearest);
  if (!a.complete && (a.hidden || a.outcome != QueryOutcome::Incomplete))
    return at + "incomplete: an incomplete answer must be Incomplete and never hidden";
  if (a.complete && a.hidden != hidden_behind(rig.op, nearest, a.value))
    return at + "hidden rule: hidden must be 'nearest strictly farther than the answer'";
  return "";
}

// Under every policy and divisor, random changes and queries never give a non-conservative
// answer, and eager and lazy answers equal a fresh build's at every query.
TEST(NBufferUnitCoreTest, ConservativeForEveryPolicyAndDivisor) {
  struct Size {
    int w, h;
    const char* format;
  };
  // Non-power-of-two, power-of-two wide, one pixel wide; u16 rounds toward far.
  const Size sizes[] = {{37, 29, "f32"}, {64, 16, "f32"}, {1, 23, "f32"}, {30, 19, "u16"}};
  for (const Size& size : sizes)
    for (const FarOp op : kOps)
      for (const char* policy : kPolicies)
        for (const int d : kDivisors) {
          NBufferUnitConfig cfg;
          cfg.update_policy = policy;
          cfg.resolution_divisor = d;
          cfg.format = size.format;
          // Each covering and alignment in turn over the configurations.
          const int variant = d + static_cast<int>(op) + static_cast<int>(std::string(policy).size());
          cfg.covering = std::string(kCoveringKindNames[static_cast<std::size_t>(variant % 3)]);
          cfg.align = std::string(kCoveringAlignNames[static_cast<std::size_t>(variant % 2)]);
          // And rectangle levels (all of them, or |i - j| <= 1) in a quarter of the configurations.
          // (on_demand computes square levels only.)
          if (variant % 4 == 3 && std::string(policy) != "on_demand") cfg.levels = "rect", cfg.max_aspect_log2 = variant % 8 == 3 ? -1 : 1;
          const int w = size.w, h = size.h;
          Rig rig(op, cfg, w, h);
          std::mt19937 rng(1000u + static_cast<unsigned>(d) * 7u + static_cast<unsigned>(op) * 3u +
                           static_cast<unsigned>(w));
          ref::Failures fails;
          int hidden = 0, visible = 0;
          for (int step = 0; step < 300; ++step) {
            rig.random_change(rng);
            if (ref::uniform_int(rng, 0, 9) == 0) rig.work += rig.core->end_of_pass();
            for (int q = 0; q < 3; ++q) {
              const Rect r = ref::random_rect(rng, w, h, true);
              const float nearest = random_nearest(rng, op, ref::farthest(rig.truth, op, r));
              const CoveringSpec kind = rig.core->covering();
              const QueryAnswer a = rig.core->query(r, nearest);
              hidden += a.hidden, visible += a.outcome == QueryOutcome::Visible;
              if (auto e = check(rig, r, nearest, a); !e.empty()) fails.add(e);
              if (std::string(policy) != "batched" && a.outcome != QueryOutcome::Offscreen) {
                const float want = rig.fresh().query(rig.core->to_reduced(r), kind).value;
                if (a.value != want)
                  fails.add(ref::str(r) + ": up to date: answered " + std::to_string(a.value) +
                            ", a fresh build gives " + std::to_string(want));
              }
            }
          }
          const std::string at = where(op, policy, d, size.format) + ", " + std::to_string(w) + "x" + std::to_string(h);
          EXPECT_EQ(fails.count(), 0) << at << ": " << fails.summary();
          EXPECT_GT(hidden, 0) << at << ": no query was hidden (test too weak)";
          EXPECT_GT(visible, 0) << at << ": no query was visible (test too weak)";
        }
}

// Once applied (end_of_pass for batched, flush for lazy and on_demand), every policy's levels equal a fresh
// build over the reduced depth buffer, for every storage format.
TEST(NBufferUnitCoreTest, LevelsEqualFreshBuildOnceApplied) {
  for (const FarOp op : kOps)
    for (const char* policy : kPolicies)
      for (const char* format : {"f32", "u24", "u16"})
        for (const int d : {1, 4}) {
          NBufferUnitConfig cfg;
          cfg.update_policy = policy;
          cfg.format = format;
          cfg.resolution_divisor = d;
          Rig rig(op, cfg, 40, 23);
          std::mt19937 rng(77u + static_cast<unsigned>(d));
          for (int step = 0; step < 60; ++step) rig.random_change(rng);
          rig.work += rig.core->end_of_pass();
          rig.work += rig.core->flush();
          EXPECT_EQ(rig.core->pending_texels(), 0u) << where(op, policy, d, format);
          const NBuffer want = rig.fresh();
          const NBuffer& got = rig.core->levels();
          ASSERT_EQ(got.level_count(), want.level_count());
          long long differ = 0;
          for (int i = 0; i < got.level_count(); ++i)
            for (int y = 0; y < got.height(); ++y)
              for (int x = 0; x < got.width(); ++x) differ += got.texel(i, x, y) != want.texel(i, x, y);
          EXPECT_EQ(differ, 0) << where(op, policy, d, format) << ": texels differing from a fresh build";
        }
}

// The four policies fed the same changes: eager, lazy and on_demand answer alike at every query;
// batched answers at least as far before end_of_pass and alike after it.
TEST(NBufferUnitCoreTest, PoliciesAgreeOnceApplied) {
  for (const FarOp op : kOps)
    for (const int d : {1, 2, 8}) {
      std::vector<std::unique_ptr<Rig>> rigs;
      for (const char* policy : kPolicies) {
        NBufferUnitConfig cfg;
        cfg.update_policy = policy;
        cfg.resolution_divisor = d;
        rigs.push_back(std::make_unique<Rig>(op, cfg, 33, 41));
      }
      ref::Failures fails;
      std::mt19937 qrng(5u);
      for (int pass = 0; pass < 12; ++pass) {
        for (int step = 0; step < 8; ++step) {
          for (auto& rig : rigs) {
            std::mt19937 rng(static_cast<unsigned>(pass * 100 + step));  // same change for each policy
            rig->random_change(rng);
          }
          const Rect r = ref::random_rect(qrng, 33, 41, false);
          const float e = rigs[0]->core->query(r, 0.5f).value, b = rigs[1]->core->query(r, 0.5f).value,
                      l = rigs[2]->core->query(r, 0.5f).value, o = rigs[3]->core->query(r, 0.5f).value;
          if (e != l) fails.add(ref::str(r) + ": lazy answered " + std::to_string(l) + ", eager " + std::to_string(e));
          if (e != o) fails.add(ref::str(r) + ": on_demand answered " + std::to_string(o) + ", eager " + std::to_string(e));
          if (!at_least_as_far(op, b, e))
            fails.add(ref::str(r) + ": batched answered " + std::to_string(b) + ", nearer than eager's " +
                      std::to_string(e));
        }
        for (auto& rig : rigs) rig->core->end_of_pass();
        for (int q = 0; q < 10; ++q) {
          const Rect r = ref::random_rect(qrng, 33, 41, false);
          const float e = rigs[0]->core->query(r, 0.5f).value, b = rigs[1]->core->query(r, 0.5f).value,
                      l = rigs[2]->core->query(r, 0.5f).value, o = rigs[3]->core->query(r, 0.5f).value;
          if (e != b || e != l || e != o)
            fails.add(ref::str(r) + " after end_of_pass: eager " + std::to_string(e) + ", batched " +
                      std::to_string(b) + ", lazy " + std::to_string(l) + ", on_demand " + std::to_string(o));
        }
      }
      EXPECT_EQ(fails.count(), 0) << "op " << to_string(op) << ", divisor " << d << ": " << fails.summary();
    }
}

// Full-resolution rectangles map to every reduced texel their pixels fall in and no other,
// at image borders and non-multiple sizes too.
TEST(NBufferUnitCoreTest, ReducedRectangleCoversExactlyTheBlocksTouched) {
  struct Row {
    int d;
    Rect r, want;
    const char* why;
  };
  // Image 37x29: reduced 19x15 (d 2), 10x8 (d 4), 5x4 (d 8).
  const Row rows[] = {
      {1, {3, 4, 5, 6}, {3, 4, 5, 6}, "divisor 1 is the identity"},
      {2, {3, 4, 1, 1}, {1, 2, 1, 1}, "a 1-pixel rectangle is its block"},
      {2, {3, 4, 2, 2}, {1, 2, 2, 1}, "odd x start straddles two blocks"},
      {4, {0, 0, 37, 29}, {0, 0, 10, 8}, "the whole image is the whole reduced image"},
      {8, {36, 28, 5, 5}, {4, 3, 1, 1}, "the last partial block, clipped"},
      {8, {-10, -10, 11, 11}, {0, 0, 1, 1}, "sticking out left and below"},
      {4, {7, 7, 2, 2}, {1, 1, 2, 2}, "crossing a block corner"},
      {8, {40, 0, 5, 5}, {0, 0, 0, 0}, "off the image: empty"},
  };
  for (const Row& row : rows) {
    NBufferUnitConfig cfg;
    cfg.resolution_divisor = row.d;
    stats::Registry reg;
    NBufferUnitCore core(cfg, 37, 29, FarOp::Max, reg.group("u"));
    EXPECT_EQ(core.to_reduced(row.r), row.want) << row.why;
  }
}

// A level cap never hides a visible rectangle: queries above the cap are tiled with top-level
// squares within the lookup budget (exactly covering the rectangle) or answered incomplete.
TEST(NBufferUnitCoreTest, LevelCapNeverHidesVisible) {
  for (const FarOp op : kOps)
    for (const int cap : {0, 1, 3})
      for (const int budget : {0, 3, 16})
        for (const int d : {1, 2}) {
          NBufferUnitConfig cfg;
          cfg.level_cap = cap;
          cfg.capped_max_lookups = budget;
          cfg.resolution_divisor = d;
          cfg.update_policy = "lazy";
          Rig rig(op, cfg, 45, 30);
          std::mt19937 rng(300u + static_cast<unsigned>(cap * 10 + budget));
          ref::Failures fails;
          int tiled = 0, incomplete = 0;
          for (int step = 0; step < 80; ++step) {
            rig.random_change(rng);
            for (int q = 0; q < 3; ++q) {
              const Rect r = ref::random_rect(rng, 45, 30, true);
              const float nearest = random_nearest(rng, op, ref::farthest(rig.truth, op, r));
              const QueryAnswer a = rig.core->query(r, nearest);
              if (auto e = check(rig, r, nearest, a); !e.empty()) fails.add(e);
              if (a.tiled) {
                ++tiled;
                if (a.lookups > budget || a.level != cap)
                  fails.add(ref::str(r) + ": tiled beyond the budget or off the top level");
                // The tiling covers the reduced rectangle: its answer is at least the reduced truth.
                const float want = ref::farthest(reduce(rig.truth, d, op), op, a.reduced);
                if (!at_least_as_far(op, a.value, want))
                  fails.add(ref::str(r) + ": tiling misses part of the rectangle");
              }
              if (!a.complete) {
                ++incomplete;
                if (a.value != far_limit(op) || a.lookups != 0)
                  fails.add(ref::str(r) + ": incomplete must read nothing and answer far");
              }
            }
          }
          EXPECT_EQ(fails.count(), 0) << "cap " << cap << ", budget " << budget << ", divisor " << d << ": "
                                      << fails.summary();
          if (budget == 0) {
            EXPECT_EQ(tiled, 0) << "a zero budget never tiles";
            EXPECT_GT(incomplete, 0) << "some queries must exceed the cap (test too weak)";
          }
          if (budget == 16 && cap == 3) {
            EXPECT_GT(tiled, 0) << "some queries must need tiling (test too weak)";
          }
        }
}

// The hidden rule on edge cases: strictly farther only; equal depth, NaN and the far plane never cull.
TEST(NBufferUnitCoreTest, HiddenRuleEdgeCases) {
  struct Row {
    FarOp op;
    float stored, nearest;
    bool hidden;
    const char* why;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Row rows[] = {
      {FarOp::Max, 0.5f, 0.5f, false, "equal depth may pass LEQUAL: not hidden"},
      {FarOp::Max, 0.5f, std::nextafter(0.5f, 1.0f), true, "a hair farther is hidden"},
      {FarOp::Max, 0.5f, std::nextafter(0.5f, 0.0f), false, "a hair nearer is visible"},
      {FarOp::Max, 1.0f, 1.0f, false, "far plane behind a cleared buffer is not hidden"},
      {FarOp::Max, 0.5f, nan, false, "NaN nearest depth is never hidden"},
      {FarOp::Max, 0.5f, 0.0f, false, "bounds crossing the near plane (clamped to 0) are visible"},
      {FarOp::Min, 0.5f, 0.5f, false, "reversed Z: equal depth is not hidden"},
      {FarOp::Min, 0.5f, 0.25f, true, "reversed Z: smaller is farther"},
      {FarOp::Min, 0.5f, 0.75f, false, "reversed Z: larger is nearer"},
  };
  for (const Row& row : rows) {
    stats::Registry reg;
    NBufferUnitCore core({}, 8, 8, row.op, reg.group("u"));
    core.depth_cleared(row.stored);
    const QueryAnswer a = core.query({1, 1, 5, 3}, row.nearest);
    EXPECT_EQ(a.hidden, row.hidden) << row.why;
    EXPECT_EQ(a.outcome, row.hidden ? QueryOutcome::Hidden : QueryOutcome::Visible) << row.why;
  }
}

// Empty and off-screen rectangles read nothing and are never hidden.
TEST(NBufferUnitCoreTest, OffscreenReadsNothing) {
  stats::Registry reg;
  NBufferUnitCore core({}, 16, 8, FarOp::Max, reg.group("u"));
  core.depth_cleared(0.0f);
  for (const Rect r : {Rect{0, 0, 0, 4}, Rect{16, 0, 4, 4}, Rect{-5, 0, 5, 4}, Rect{3, 8, 2, 2}, Rect{2, 2, -1, 3}}) {
    const QueryAnswer a = core.query(r, 1.0f);
    EXPECT_EQ(a.outcome, QueryOutcome::Offscreen) << ref::str(r);
    EXPECT_EQ(a.lookups, 0) << ref::str(r);
    EXPECT_FALSE(a.hidden) << ref::str(r);
  }
  EXPECT_EQ(reg.values()["u"]["queries"]["offscreen"], 5);
  EXPECT_EQ(reg.values()["u"]["lookups"]["0"], 0);
}

// Batched: a change that moves depth farther is applied at once (stale levels would be nearer
// than the truth); changes that move depth nearer wait for end_of_pass.
TEST(NBufferUnitCoreTest, BatchedAppliesFartherChangesAtOnce) {
  NBufferUnitConfig cfg;
  cfg.update_policy = "batched";
  stats::Registry reg;
  NBufferUnitCore core(cfg, 16, 16, FarOp::Max, reg.group("u"));
  DepthImage depth(16, 16, 0.5f);
  core.depth_changed(depth, {0, 0, 16, 16});  // 0.5 is nearer than the clear 1.0: pending
  EXPECT_EQ(core.pending_texels(), 256u);
  EXPECT_EQ(core.query({0, 0, 4, 4}, 0.75f).value, 1.0f) << "nearer changes wait: the stale answer is the clear";
  core.end_of_pass();
  EXPECT_EQ(core.pending_texels(), 0u);
  EXPECT_TRUE(core.query({0, 0, 4, 4}, 0.75f).hidden) << "after end_of_pass the levels hold 0.5";
  const PixelWrite far[] = {{2, 2, 0.9f}};
  core.depth_changed(far);
  EXPECT_EQ(core.pending_texels(), 0u) << "a farther write is not left pending";
  EXPECT_FALSE(core.query({0, 0, 4, 4}, 0.75f).hidden) << "the farther pixel must be seen before end_of_pass";
  EXPECT_EQ(reg.values()["u"]["texels_applied"]["forced"], 1);
}

// Lazy: a query applies only the pending changes its squares cover.
TEST(NBufferUnitCoreTest, LazyAppliesOnlyWhatAQueryReads) {
  NBufferUnitConfig cfg;
  cfg.update_policy = "lazy";
  stats::Registry reg;
  NBufferUnitCore core(cfg, 64, 64, FarOp::Max, reg.group("u"));
  const PixelWrite corner[] = {{60, 60, 0.25f}, {61, 60, 0.25f}, {60, 61, 0.25f}, {61, 61, 0.25f}};
  core.depth_changed(corner);
  EXPECT_EQ(core.pending_texels(), 4u);
  QueryAnswer a = core.query({0, 0, 8, 8}, 0.5f);
  EXPECT_EQ(a.update.recomputed(), 0u) << "a query far from the change applies nothing";
  EXPECT_EQ(core.pending_texels(), 4u);
  a = core.query({60, 60, 2, 2}, 0.5f);
  EXPECT_GT(a.update.recomputed(), 0u) << "a query over the change applies it";
  EXPECT_EQ(core.pending_texels(), 0u);
  EXPECT_TRUE(a.hidden);
  EXPECT_EQ(a.value, 0.25f);
}

// Statistics match the answers and the work returned: lookups per level, outcomes, cases,
// texels per level, cache hits and misses, bytes.
TEST(NBufferUnitCoreTest, StatisticsMatchAnswersAndWork) {
  NBufferUnitConfig cfg;
  cfg.resolution_divisor = 2;
  Rig rig(FarOp::Max, cfg, 50, 34, "gpu.nbuffer");
  std::mt19937 rng(9);
  std::vector<std::uint64_t> lookups(static_cast<std::size_t>(rig.core->levels().level_count()), 0);
  std::uint64_t outcomes[4] = {}, cases[5] = {}, hits = 0, misses = 0, query_bytes = 0;
  for (int step = 0; step < 100; ++step) {
    rig.random_change(rng);
    const Rect r = ref::random_rect(rng, 50, 34, true);
    const QueryAnswer a = rig.core->query(r, ref::unit_float(rng));
    ++outcomes[static_cast<int>(a.outcome)];
    if (a.outcome != QueryOutcome::Offscreen) ++cases[static_cast<int>(a.kase)];
    lookups[static_cast<std::size_t>(a.level)] += static_cast<std::uint64_t>(a.lookups);
    EXPECT_EQ(a.cache_hits + a.cache_misses, static_cast<std::uint64_t>(a.lookups));
    EXPECT_EQ(a.bytes_read, a.cache_misses * 256u) << "a miss fills one 256-byte line";
    hits += a.cache_hits, misses += a.cache_misses, query_bytes += a.bytes_read;
  }
  const auto v = rig.reg.values()["gpu.nbuffer"];
  for (std::size_t i = 0; i < lookups.size(); ++i)
    EXPECT_EQ(v["lookups"][std::to_string(i)], lookups[i]) << "level " << i;
  const char* outcome_names[] = {"hidden", "visible", "incomplete", "offscreen"};
  for (int i = 0; i < 4; ++i) EXPECT_EQ(v["queries"][outcome_names[i]], outcomes[i]) << outcome_names[i];
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(v["query_cases"][std::string(nbsim::to_string(static_cast<CoveringCase>(i)))], cases[i]) << i;
  for (std::size_t i = 0; i < rig.work.texels_recomputed.size(); ++i) {
    EXPECT_EQ(v["texels_recomputed"][std::to_string(i)], rig.work.texels_recomputed[i]) << "level " << i;
    EXPECT_EQ(v["texels_changed"][std::to_string(i)], rig.work.texels_changed[i]) << "level " << i;
  }
  EXPECT_EQ(v["cache_hits"], hits);
  EXPECT_EQ(v["cache_misses"], misses);
  EXPECT_GT(hits, 0u) << "a 16 KiB cache over a 25x17 N-buffer must hit sometimes";
  EXPECT_EQ(v["bytes_read"], query_bytes + rig.work.bytes_read);
  EXPECT_EQ(v["bytes_written"], rig.work.bytes_written);
  EXPECT_EQ(v["depth_pixels_reduced"], rig.work.depth_pixels_reduced);
  EXPECT_GT(rig.work.depth_pixels_reduced, 0u);
}

// The same query twice: the second one hits the cache on every lookup.
TEST(NBufferUnitCoreTest, RepeatedQueryHitsTheCache) {
  stats::Registry reg;
  NBufferUnitCore core({}, 64, 64, FarOp::Max, reg.group("u"));
  // Level 4: anchors x 3 and 17, y 5 and 19, in four different 8x8 tiles.
  const QueryAnswer cold = core.query({3, 5, 30, 30}, 0.5f), warm = core.query({3, 5, 30, 30}, 0.5f);
  EXPECT_EQ(cold.lookups, 4);
  EXPECT_EQ(cold.cache_misses, 4u) << "cold cache, four texels in four tiles are four lines";
  EXPECT_EQ(warm.cache_hits, 4u);
  EXPECT_EQ(warm.bytes_read, 0u);
}

// Texels of one cache line share a tile: addresses of an 8x8 f32 tile (256 B lines) are one line.
TEST(NBufferUnitCoreTest, TexelAddressesTileByCacheLine) {
  stats::Registry reg;
  NBufferUnitCore core({}, 40, 40, FarOp::Max, reg.group("u"));
  const std::uint64_t base = core.texel_address(2, 8, 16) / 256;
  for (int y = 16; y < 24; ++y)
    for (int x = 8; x < 16; ++x) EXPECT_EQ(core.texel_address(2, x, y) / 256, base) << x << "," << y;
  EXPECT_NE(core.texel_address(2, 16, 16) / 256, base) << "the next tile is another line";
  EXPECT_NE(core.texel_address(3, 8, 16) / 256, base) << "another level is another plane";
}

// Pixel writes outside the depth buffer are refused before anything changes.
TEST(NBufferUnitCoreTest, RefusesWritesOutsideTheImage) {
  stats::Registry reg;
  NBufferUnitCore core({}, 8, 8, FarOp::Max, reg.group("u"));
  const PixelWrite writes[] = {{1, 1, 0.1f}, {8, 0, 0.1f}};
  try {
    core.depth_changed(writes);
    ADD_FAILURE() << "a write at x = 8 of an 8-wide buffer must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("(8, 0) outside the 8x8"), std::string::npos) << e.what();
  }
  EXPECT_EQ(core.depth().at(1, 1), 1.0f) << "the valid write of a refused batch must not land";
}

// A depth buffer size outside 1 .. 16384 is the user's error, with a message.
TEST(NBufferUnitCoreTest, RefusesBadSizes) {
  stats::Registry reg;
  EXPECT_THROW(NBufferUnitCore({}, 0, 8, FarOp::Max, reg.group("a")), InputError);
  EXPECT_THROW(NBufferUnitCore({}, 8, 20000, FarOp::Max, reg.group("b")), InputError);
}

// The upkeep variants: a fast clear writes no level texel; level0=depth writes no copy of level 0
// (its changes reach level 1 as before); the answers are the same either way.
TEST(NBufferUnitCoreTest, FastClearAndSharedLevel0CostLess) {
  std::uint64_t recomputed[2][2] = {}, written[2][2] = {};
  float answer[2][2] = {};
  for (int fast = 0; fast < 2; ++fast)
    for (int shared = 0; shared < 2; ++shared) {
      NBufferUnitConfig cfg;
      cfg.fast_clear = fast == 1;
      cfg.level0 = shared ? "depth" : "copy";
      stats::Registry reg;
      NBufferUnitCore core(cfg, 32, 32, FarOp::Max, reg.group("u"));
      UpdateWork w = core.depth_cleared(1.0f);
      DepthImage d(32, 32, 1.0f);
      for (int y = 4; y < 12; ++y)
        for (int x = 4; x < 12; ++x) d.at(x, y) = 0.25f;
      w += core.depth_changed(d, {4, 4, 8, 8});
      recomputed[fast][shared] = w.recomputed();
      written[fast][shared] = w.bytes_written;
      answer[fast][shared] = core.query({4, 4, 8, 8}, 0.5f).value;
    }
  const auto plane = 32u * 32u;
  const std::uint64_t levels = 5;  // 32x32: levels 0 .. 4 (squares up to 16x16)
  EXPECT_EQ(recomputed[0][0] - recomputed[1][0], levels * plane) << "a clear writes every level, a fast clear none";
  EXPECT_EQ(recomputed[1][0] - recomputed[1][1], 64u) << "the 8x8 change copied into level 0, or not";
  EXPECT_LT(written[1][1], written[1][0]);
  for (int fast = 0; fast < 2; ++fast)
    for (int shared = 0; shared < 2; ++shared) EXPECT_EQ(answer[fast][shared], 0.25f);
}


// Dirty tiles (dirty_tile > 1) track pending changes per tile: lazy answers still equal a fresh
// build at every query, batched ones once the pass ends, and the levels equal a fresh build once
// flushed; a tile's texels all reach level 0 (at least the per-texel work there), for a fraction
// of the per-texel flags.
TEST(NBufferUnitCoreTest, DirtyTilesAnswerAsPerTexelTracking) {
  for (const FarOp op : kOps)
    for (const char* policy : {"batched", "lazy"})
      for (const int tile : {2, 8, 64})
        for (const int d : {1, 2}) {
          const std::string at = where(op, policy, d, "f32") + ", dirty_tile " + std::to_string(tile);
          NBufferUnitConfig per_texel, per_tile;
          per_texel.update_policy = per_tile.update_policy = policy;
          per_texel.resolution_divisor = per_tile.resolution_divisor = d;
          per_tile.dirty_tile = tile;
          Rig a(op, per_texel, 43, 37), b(op, per_tile, 43, 37);
          ref::Failures fails;
          std::mt19937 qrng(9u + static_cast<unsigned>(tile));
          for (int pass = 0; pass < 10; ++pass) {
            for (int step = 0; step < 10; ++step) {
              std::mt19937 rng_a(static_cast<unsigned>(pass * 1000 + step * 7 + tile)), rng_b = rng_a;
              a.random_change(rng_a);
              b.random_change(rng_b);
              const Rect r = ref::random_rect(qrng, 43, 37, true);
              const float nearest = random_nearest(qrng, op, ref::farthest(b.truth, op, r));
              const QueryAnswer qa = a.core->query(r, nearest), qb = b.core->query(r, nearest);
              if (auto e = check(b, r, nearest, qb); !e.empty()) fails.add(e);
              if (std::string(policy) == "lazy" && qb.outcome != QueryOutcome::Offscreen &&
                  qb.value != b.fresh().query(b.core->to_reduced(r), b.core->covering()).value)
                fails.add(ref::str(r) + ": a lazy per-tile answer differs from a fresh build");
              if (qa.outcome != qb.outcome && std::string(policy) == "lazy")
                fails.add(ref::str(r) + ": per-tile and per-texel lazy answers differ");
            }
            a.work += a.core->end_of_pass();
            b.work += b.core->end_of_pass();
            for (int q = 0; q < 5; ++q) {
              const Rect r = ref::random_rect(qrng, 43, 37, false);
              if (a.core->query(r, 0.5f).value != b.core->query(r, 0.5f).value)
                fails.add(ref::str(r) + " after end_of_pass: per-tile and per-texel answers differ");
            }
          }
          b.work += b.core->flush();
          a.work += a.core->flush();
          EXPECT_EQ(b.core->pending_texels(), 0u) << at;
          const NBuffer want = b.fresh();
          long long differ = 0;
          for (int i = 0; i < want.level_count(); ++i)
            for (int y = 0; y < want.height(); ++y)
              for (int x = 0; x < want.width(); ++x) differ += b.core->levels().texel(i, x, y) != want.texel(i, x, y);
          EXPECT_EQ(differ, 0) << at << ": texels differing from a fresh build";
          EXPECT_EQ(fails.count(), 0) << at << ": " << fails.summary();
          EXPECT_GE(b.work.texels_recomputed[0], a.work.texels_recomputed[0]) << at << ": a dirty tile reaches level 0 whole";
          EXPECT_LT(b.core->tracking_bits(), a.core->tracking_bits()) << at;
          EXPECT_EQ(a.core->tracking_bits(), static_cast<std::uint64_t>(a.core->levels().width() * a.core->levels().height()));
        }
}

// Demand-capped levels: the levels kept after a clear are those the queries since the clear
// before needed (plus the margin); no work is counted above them; a query needing more tiles the
// highest kept level or answers Incomplete, and no answer is ever non-conservative.
TEST(NBufferUnitCoreTest, DemandLevelsFollowThePreviousFrame) {
  for (const FarOp op : kOps)
    for (const char* policy : {"eager", "batched", "lazy"})
      for (const int margin : {0, 1}) {
        const std::string at = where(op, policy, 1, "f32") + ", margin " + std::to_string(margin);
        NBufferUnitConfig cfg;
        cfg.update_policy = policy;
        cfg.demand_levels = true;
        cfg.demand_margin = margin;
        Rig rig(op, cfg, 64, 48);
        const int full = rig.core->levels().top_level();
        EXPECT_EQ(rig.core->kept_top_level(), full) << at << ": the first frame keeps every level";
        ref::Failures fails;
        std::mt19937 rng(41u + static_cast<unsigned>(margin));
        int tiled_or_incomplete = 0;
        for (int frame = 0; frame < 12; ++frame) {
          // Each frame's queries stay below a side that changes from frame to frame.
          const int side = 1 << ref::uniform_int(rng, 0, 5);
          int needed = -1;
          for (int step = 0; step < 12; ++step) {
            const int kind = ref::uniform_int(rng, 0, 1);
            const Rect c = {ref::uniform_int(rng, 0, 60), ref::uniform_int(rng, 0, 44), ref::uniform_int(rng, 1, 8),
                            ref::uniform_int(rng, 1, 8)};
            const Rect cc = clip(c, 64, 48);
            for (int y = cc.y; y < cc.y1(); ++y)
              for (int x = cc.x; x < cc.x1(); ++x) rig.truth.at(x, y) = new_depth(rng, op, rig.truth.at(x, y), kind == 1);
            const UpdateWork w = rig.core->depth_changed(rig.truth, c);
            rig.work += w;
            for (std::size_t i = static_cast<std::size_t>(rig.core->kept_top_level()) + 1; i < w.texels_recomputed.size(); ++i)
              if (w.texels_recomputed[i] != 0) fails.add("work counted above the kept levels");
            const Rect r = {ref::uniform_int(rng, 0, 63), ref::uniform_int(rng, 0, 47), ref::uniform_int(rng, 1, side),
                            ref::uniform_int(rng, 1, side)};
            const float nearest = random_nearest(rng, op, ref::farthest(rig.truth, op, r));
            const QueryAnswer a = rig.core->query(r, nearest);
            if (auto e = check(rig, r, nearest, a); !e.empty()) fails.add(e);
            if (a.outcome != QueryOutcome::Offscreen) {
              const Covering cov = rig.core->levels().covering(a.reduced, rig.core->covering());
              needed = std::max(needed, cov.level);
              const bool above = cov.level > rig.core->kept_top_level();
              tiled_or_incomplete += above;
              if (above != (a.tiled || !a.complete)) fails.add(ref::str(r) + ": tiled or incomplete exactly when above the kept levels");
            }
          }
          const float v = ref::unit_float(rng);
          std::fill(rig.truth.texels.begin(), rig.truth.texels.end(), v);
          const UpdateWork clear = rig.core->depth_cleared(v);
          const int want = needed < 0 ? rig.core->kept_top_level() : std::min(full, needed + margin);
          if (rig.core->kept_top_level() != want)
            fails.add("frame " + std::to_string(frame) + ": kept " + std::to_string(rig.core->kept_top_level()) + ", want " +
                      std::to_string(want));
          // The clear writes exactly the kept levels.
          for (std::size_t i = 0; i < clear.texels_recomputed.size(); ++i)
            if ((clear.texels_recomputed[i] != 0) != (static_cast<int>(i) <= rig.core->kept_top_level()))
              fails.add("frame " + std::to_string(frame) + ": the clear wrote level " + std::to_string(i) + " wrongly");
        }
        EXPECT_EQ(fails.count(), 0) << at << ": " << fails.summary();
        EXPECT_GT(tiled_or_incomplete, 0) << at << ": no query needed more than the kept levels (test too weak)";
      }
}
}  // namespace
}  // namespace nbsim::nbuffer
