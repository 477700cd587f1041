// UpdateTest: incremental updates of model/nbuffer/nbuffer.h (dirty rectangles and pixel writes)
// against full rebuilds, and the work they report per level.
#include "model/nbuffer/nbuffer.h"

#include <gtest/gtest.h>

#include <bit>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};

using Snapshot = std::vector<std::vector<float>>;  // every level's texels

Snapshot snapshot(const NBuffer& nb) {
  Snapshot s;
  for (int i = 0; i < nb.level_count(); ++i) s.emplace_back(nb.level(i).begin(), nb.level(i).end());
  return s;
}

// Texels of level i whose bits differ between two snapshots.
long long differing(const Snapshot& a, const Snapshot& b, int i) {
  long long n = 0;
  const auto& la = a[static_cast<std::size_t>(i)];
  const auto& lb = b[static_cast<std::size_t>(i)];
  for (std::size_t k = 0; k < la.size(); ++k) n += std::bit_cast<std::uint32_t>(la[k]) != std::bit_cast<std::uint32_t>(lb[k]);
  return n;
}

// The texels of level i an update of the pixels in `box` may touch: box grown by 2^i - 1 to the
// left and below (level i at (x, y) reads level 0 up to x + 2^i - 1), clipped to the image.
long long reach_area(const Rect& box, int i, int w, int h) {
  const int g = (1 << i) - 1;
  return clip({box.x - g, box.y - g, box.w + g, box.h + g}, w, h).area();
}

// Texels of level i (i >= 1) that read a texel of level i - 1 that differs between a and b:
// the least an incremental update must recompute.
long long readers_of_changes(const Snapshot& a, const Snapshot& b, int i, int w, int h) {
  const int s = 1 << (i - 1);
  const auto& la = a[static_cast<std::size_t>(i - 1)];
  const auto& lb = b[static_cast<std::size_t>(i - 1)];
  auto differs = [&](int x, int y) {
    if (x >= w || y >= h) return false;
    const std::size_t k = static_cast<std::size_t>(y) * w + x;
    return std::bit_cast<std::uint32_t>(la[k]) != std::bit_cast<std::uint32_t>(lb[k]);
  };
  long long n = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) n += differs(x, y) || differs(x + s, y) || differs(x, y + s) || differs(x + s, y + s);
  return n;
}

// Checks an update's result against a full rebuild of `depth` and its stats against the texels
// that really changed and the reach of `box` (the dirty pixels' bounding box). With exact_work
// (pixel writes) each level must recompute exactly the texels that read a changed texel, once.
void check_update(const NBuffer& nb, const DepthImage& depth, const Snapshot& before, const UpdateStats& st,
                  const Rect& box, long long level0_work, const std::string& what, ref::Failures& f,
                  bool exact_work) {
  const NBuffer rebuilt(depth, nb.config());
  const Snapshot after = snapshot(nb);
  const Snapshot want = snapshot(rebuilt);
  const auto levels = static_cast<std::size_t>(nb.level_count());
  if (st.texels_recomputed.size() != levels || st.texels_changed.size() != levels) {
    f.add(what + ": stats: not one entry per level");
    return;
  }
  for (int i = 0; i < nb.level_count(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const std::string lv = what + ": level " + std::to_string(i) + ": ";
    if (const long long d = differing(after, want, i)) f.add(lv + "rebuild: " + std::to_string(d) + " texels differ from a full rebuild");
    const long long changed = differing(before, after, i);
    if (st.texels_changed[k] != changed)
      f.add(lv + "changed: reported " + std::to_string(st.texels_changed[k]) + " changed texels, " + std::to_string(changed) + " did");
    if (i == 0 && st.texels_recomputed[0] != level0_work)
      f.add(lv + "level-0 work: reported " + std::to_string(st.texels_recomputed[0]) + ", expected " + std::to_string(level0_work));
    if (i > 0 && st.texels_recomputed[k] > reach_area(box, i, nb.width(), nb.height()))
      f.add(lv + "reach: recomputed " + std::to_string(st.texels_recomputed[k]) + " texels, more than the " +
            std::to_string(reach_area(box, i, nb.width(), nb.height())) + " the dirty pixels can reach");
    if (st.texels_changed[k] > st.texels_recomputed[k]) f.add(lv + "stats: more texels changed than recomputed");
    if (i > 0) {
      const long long readers = readers_of_changes(before, after, i, nb.width(), nb.height());
      if (st.texels_recomputed[k] < readers)
        f.add(lv + "work: recomputed " + std::to_string(st.texels_recomputed[k]) + " texels, fewer than the " +
              std::to_string(readers) + " that read a changed texel");
      if (exact_work && st.texels_recomputed[k] != readers)
        f.add(lv + "work: recomputed " + std::to_string(st.texels_recomputed[k]) + " texels, not exactly the " +
              std::to_string(readers) + " that read a changed texel");
    }
    if (i > 0 && st.texels_changed[k - 1] == 0 && st.texels_recomputed[k] != 0)
      f.add(lv + "stop: recomputed " + std::to_string(st.texels_recomputed[k]) + " texels although level " +
            std::to_string(i - 1) + " did not change");
  }
}

// New depth for a pixel: random, a tie from three values, the far plane, or unchanged.
float next_depth(std::mt19937& rng, float current, FarOp op) {
  switch (ref::uniform_int(rng, 0, 5)) {
    case 0: return current;
    case 1: return 0.25f * static_cast<float>(ref::uniform_int(rng, 1, 3));
    case 2: return far_limit(op);
    case 3: return neutral_depth(op);
    default: return ref::unit_float(rng);
  }
}

struct Case {
  int w, h;
  FarOp op;
  StorageFormat format;
};

std::vector<Case> setups() {
  std::vector<Case> s;
  const std::pair<int, int> sizes[] = {{37, 23}, {1, 45}, {45, 1}, {1, 1}, {64, 64}, {70, 33}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) s.push_back({w, h, op, StorageFormat::F32});
  s.push_back({41, 29, FarOp::Max, StorageFormat::U16});
  s.push_back({41, 29, FarOp::Min, StorageFormat::U24});
  return s;
}

std::string name_of(const Case& s) {
  return std::to_string(s.w) + "x" + std::to_string(s.h) + " " + std::string(to_string(s.op)) + " " +
         std::string(to_string(s.format));
}

// Random dirty rectangles, many rounds on one buffer, equal a full rebuild and report their work.
TEST(UpdateTest, DirtyRectsMatchRebuild) {
  for (const Case& s : setups()) {
    std::mt19937 rng(static_cast<std::uint32_t>(s.w * 131 + s.h));
    DepthImage depth = ref::uniform(s.w, s.h, 3);
    NBuffer nb(depth, {.op = s.op, .format = s.format});
    ref::Failures f;
    for (int round = 0; round < 150; ++round) {
      const Rect dirty = ref::random_rect(rng, s.w, s.h, true);
      const Rect c = clip(dirty, s.w, s.h);
      // Outside the dirty rectangle the image given to update holds garbage it must ignore.
      DepthImage next = ref::uniform(s.w, s.h, static_cast<std::uint32_t>(1000 + round));
      for (int y = c.y; y < c.y1(); ++y)
        for (int x = c.x; x < c.x1(); ++x) depth.at(x, y) = next.at(x, y) = next_depth(rng, depth.at(x, y), s.op);
      const Snapshot before = snapshot(nb);
      const UpdateStats st = nb.update(next, dirty);
      check_update(nb, depth, before, st, c, c.area(), name_of(s) + " round " + std::to_string(round) + " dirty " + ref::str(dirty), f,
                   false);
    }
    EXPECT_EQ(f.count(), 0) << name_of(s) << ": " << f.summary();
  }
}

// Random pixel sets (scattered, clustered, duplicated, unchanged), many rounds on one buffer,
// equal a full rebuild and report their work; the last write to a pixel wins.
TEST(UpdateTest, PixelWritesMatchRebuild) {
  for (const Case& s : setups()) {
    std::mt19937 rng(static_cast<std::uint32_t>(s.w * 71 + s.h));
    DepthImage depth = ref::uniform(s.w, s.h, 4);
    NBuffer nb(depth, {.op = s.op, .format = s.format});
    ref::Failures f;
    for (int round = 0; round < 150; ++round) {
      std::vector<PixelWrite> writes;
      Rect area{0, 0, s.w, s.h};
      if (round % 3 == 1) {  // clustered in a small box
        const int bw = std::min(s.w, ref::uniform_int(rng, 1, 6)), bh = std::min(s.h, ref::uniform_int(rng, 1, 6));
        area = {ref::uniform_int(rng, 0, s.w - bw), ref::uniform_int(rng, 0, s.h - bh), bw, bh};
      }
      const int n = ref::uniform_int(rng, 1, 40);
      Rect box;
      for (int j = 0; j < n; ++j) {
        PixelWrite wr;
        if (j > 0 && ref::uniform_int(rng, 0, 3) == 0) {  // the same pixel again
          wr = writes[static_cast<std::size_t>(ref::uniform_int(rng, 0, j - 1))];
        } else {
          wr.x = ref::uniform_int(rng, area.x, area.x1() - 1);
          wr.y = ref::uniform_int(rng, area.y, area.y1() - 1);
        }
        wr.depth = next_depth(rng, depth.at(wr.x, wr.y), s.op);
        depth.at(wr.x, wr.y) = wr.depth;
        writes.push_back(wr);
        box = box.empty() ? Rect{wr.x, wr.y, 1, 1}
                          : Rect{std::min(box.x, wr.x), std::min(box.y, wr.y), std::max(box.x1(), wr.x + 1) - std::min(box.x, wr.x),
                                 std::max(box.y1(), wr.y + 1) - std::min(box.y, wr.y)};
      }
      const Snapshot before = snapshot(nb);
      const UpdateStats st = nb.update(writes);
      check_update(nb, depth, before, st, box, n, name_of(s) + " round " + std::to_string(round) + " (" + std::to_string(n) + " writes)", f,
                   true);
    }
    EXPECT_EQ(f.count(), 0) << name_of(s) << ": " << f.summary();
  }
}

// Dirty rectangles and pixel writes interleaved for many rounds keep the buffer equal to a rebuild.
TEST(UpdateTest, InterleavedUpdatesMatchRebuild) {
  for (const FarOp op : kOps) {
    std::mt19937 rng(op == FarOp::Max ? 17u : 18u);
    DepthImage depth = ref::three_values(53, 39, 5);
    NBuffer nb(depth, {.op = op});
    ref::Failures f;
    for (int round = 0; round < 300; ++round) {
      const Snapshot before = snapshot(nb);
      if (round % 2) {
        const Rect dirty = ref::random_rect(rng, 53, 39, true);
        const Rect c = clip(dirty, 53, 39);
        DepthImage next = depth;
        for (int y = c.y; y < c.y1(); ++y)
          for (int x = c.x; x < c.x1(); ++x) depth.at(x, y) = next.at(x, y) = next_depth(rng, depth.at(x, y), op);
        check_update(nb, depth, before, nb.update(next, dirty), c, c.area(), "round " + std::to_string(round), f, false);
      } else {
        const PixelWrite wr{ref::uniform_int(rng, 0, 52), ref::uniform_int(rng, 0, 38), ref::unit_float(rng)};
        depth.at(wr.x, wr.y) = wr.depth;
        check_update(nb, depth, before, nb.update(std::span(&wr, 1)), {wr.x, wr.y, 1, 1}, 1, "round " + std::to_string(round), f,
                     true);
      }
    }
    EXPECT_EQ(f.count(), 0) << to_string(op) << ": " << f.summary();
  }
}

// A pixel that becomes the new farthest changes exactly the texels whose square contains it.
TEST(UpdateTest, NewFarthestPixelChangesItsReach) {
  struct Row { int x, y; const char* why; };
  const Row rows[] = {
      {0, 0, "origin: only texel (0, 0) of each level contains it"},
      {36, 22, "top-right corner pixel: full 2^i squares to the left and below"},
      {16, 8, "on level borders 2^4 and 2^3"},
      {15, 7, "just before level borders"},
      {36, 0, "right edge, bottom row"},
  };
  for (const FarOp op : kOps)
    for (const Row& row : rows) {
      // Background strictly nearer than the far limit, so the new pixel raises every square it is in.
      const DepthImage img = ref::uniform(37, 23, 9, 0.1f, 0.9f);
      for (const bool as_rect : {false, true}) {
        NBuffer nb(img, {.op = op});
        DepthImage next = img;
        next.at(row.x, row.y) = far_limit(op);
        const PixelWrite wr{row.x, row.y, far_limit(op)};
        const UpdateStats st = as_rect ? nb.update(next, {row.x, row.y, 1, 1}) : nb.update(std::span(&wr, 1));
        for (int i = 0; i < nb.level_count(); ++i) {
          const long long want = reach_area({row.x, row.y, 1, 1}, i, 37, 23);
          EXPECT_EQ(st.texels_changed[static_cast<std::size_t>(i)], want)
              << to_string(op) << (as_rect ? " rect" : " write") << " level " << i << ": " << row.why;
          EXPECT_EQ(st.texels_recomputed[static_cast<std::size_t>(i)], i == 0 ? 1 : want)
              << "recomputing exactly the reach is enough here: " << row.why;
        }
      }
    }
}

// Updates that change nothing recompute nothing above level 0 and report no changes.
TEST(UpdateTest, NoChangeRecomputesNothingAboveLevel0) {
  for (const FarOp op : kOps) {
    const DepthImage img = ref::uniform(29, 31, 10);
    NBuffer nb(img, {.op = op});
    const Snapshot before = snapshot(nb);
    const float v = img.at(5, 7), other = v < 0.5f ? v + 0.25f : v - 0.25f;
    struct Row { std::vector<PixelWrite> writes; const char* why; };
    const Row rows[] = {
        {{{5, 7, v}}, "rewriting a pixel's own value"},
        {{{5, 7, other}, {5, 7, v}}, "writing a new value then the old one back in the same batch"},
        {{{5, 7, other}, {5, 7, far_limit(op)}, {5, 7, v}, {5, 7, v}}, "several writes ending on the old value"},
        {{{0, 0, img.at(0, 0)}, {28, 30, img.at(28, 30)}, {28, 0, img.at(28, 0)}}, "own values at image corners"},
        {{}, "no writes at all"},
    };
    for (const Row& row : rows) {
      const UpdateStats st = nb.update(row.writes);
      EXPECT_EQ(st.texels_recomputed[0], static_cast<long long>(row.writes.size())) << row.why << ": each write is level-0 work";
      EXPECT_EQ(st.total_changed(), 0) << row.why << ": nothing changed";
      EXPECT_EQ(st.total_recomputed(), st.texels_recomputed[0]) << row.why << ": no level above 0 needs recomputing";
      EXPECT_EQ(snapshot(nb), before) << row.why;
    }
    const UpdateStats st = nb.update(img, {3, 4, 20, 20});
    EXPECT_EQ(st.texels_recomputed[0], 400) << "a dirty rectangle is level-0 work for each of its pixels";
    EXPECT_EQ(st.total_recomputed(), 400) << "rewriting a rectangle with its own values stops at level 0";
    EXPECT_EQ(st.total_changed(), 0);
  }
}

// Dirty rectangles that are empty or outside the image do nothing.
TEST(UpdateTest, EmptyOrOutsideDirtyRectIsNoOp) {
  const DepthImage img = ref::uniform(16, 9, 11);
  NBuffer nb(img);
  const Snapshot before = snapshot(nb);
  const DepthImage other = ref::uniform(16, 9, 12);
  for (const Rect r : {Rect{0, 0, 0, 5}, Rect{16, 0, 3, 3}, Rect{0, 9, 3, 3}, Rect{-3, -3, 3, 3}, Rect{2, 2, -1, 4}}) {
    const UpdateStats st = nb.update(other, r);
    EXPECT_EQ(st.total_recomputed(), 0) << ref::str(r);
    EXPECT_EQ(st.texels_recomputed.size(), static_cast<std::size_t>(nb.level_count())) << "stats always have one entry per level";
    EXPECT_EQ(snapshot(nb), before) << ref::str(r) << " must not touch the buffer";
  }
}

// Pixel writes outside the image are the user's error, and a rejected batch leaves the buffer as
// it was (no half-applied level 0 that the levels above do not reflect).
TEST(UpdateTest, WritesOutsideThrow) {
  const DepthImage img = ref::uniform(16, 9, 13);
  struct Row { PixelWrite bad; const char* why; };
  const Row rows[] = {
      {{-1, 0, 0.5f}, "left of the image"}, {{16, 0, 0.5f}, "x == width"},
      {{0, -1, 0.5f}, "below the image"},   {{0, 9, 0.5f}, "y == height"},
      {{1 << 30, 1 << 30, 0.5f}, "far away"},
  };
  for (const Row& row : rows) {
    NBuffer nb(img);
    const Snapshot before = snapshot(nb);
    const std::vector<PixelWrite> batch{{3, 3, 1.0f}, {15, 8, 1.0f}, row.bad, {0, 0, 1.0f}};
    EXPECT_THROW(nb.update(batch), InputError) << row.why;
    EXPECT_EQ(snapshot(nb), before) << row.why << ": the valid writes before the bad one must not stay half-applied";
    EXPECT_THROW(nb.update(std::span(&row.bad, 1)), InputError) << row.why << " alone";
  }
}

}  // namespace
}  // namespace nbsim
