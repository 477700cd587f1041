// ReliefLookupLinesTest: a walk that records its lookups (walk.h LookupLines) gives the observer
// walk's result, and the texel cache fed the records run by run (replay.h TexelCache) counts the hits
// and misses a memory::Cache counts when it sees every lookup as the walks issue them.
// ReliefWorkerPoolTest: the pool (workers.h) runs every work once and hands them on in order.
// ReliefReplayThreadsTest: a frame's replay counts the same with one thread and with several.
#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <stdexcept>
#include <vector>

#include "model/nbuffer/nbuffer.h"
#include "model/relief/heightfield.h"
#include "model/relief/radius.h"
#include "model/relief/records.h"
#include "model/relief/replay.h"
#include "model/relief/roles.h"
#include "model/relief/walk.h"
#include "model/relief/workers.h"

namespace nbsim::relief {
namespace {

constexpr int kN = 32;
constexpr int kMaxRadius = 8;

std::vector<float> max_nbuffer(const Heightfield& field) {
  DepthImage image(field.size, field.size, 0.0f);
  image.texels = field.heights;
  const NBuffer nb(image, NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
  std::vector<float> out;
  for (int l = 0; l < nb.level_count(); ++l) out.insert(out.end(), nb.level(l).begin(), nb.level(l).end());
  return out;
}

// A random terrain with its radius and N-buffer.
struct Field {
  Heightfield field = make_heightfield("fbm", kN, 0, 7);
  SafetyRadius radius = safety_radius(field, kMaxRadius);
  std::vector<float> nbuffer = max_nbuffer(field);
  FieldView view() const { return {kN, field.heights, radius.radius, nbuffer, nbuffer_level_count(kN, kN)}; }
};

// The unit's former per-lookup cache model: every lookup of a texel in memory to a memory::Cache at
// its address, a repeat of the line just before counted as a hit when the cache has bytes.
struct PerLookupCache {
  memory::Cache cache;
  int line_shift = 0;
  std::uint64_t last_line = ~std::uint64_t{0}, hits = 0, misses = 0;

  explicit PerLookupCache(const memory::CacheConfig& c) : cache(c) {
    while ((1 << line_shift) < c.line_bytes) ++line_shift;
  }
  static void observe(void* self, Texture texture, std::int64_t index) {
    auto* p = static_cast<PerLookupCache*>(self);
    if (index < 0) return;
    const std::uint64_t a = texel_address(texture, index), line = a >> p->line_shift;
    if (line == p->last_line && p->cache.config().size_bytes > 0) {
      ++p->hits;
      return;
    }
    p->last_line = line;
    ++(p->cache.access(a, false).hit ? p->hits : p->misses);
  }
};

// Rays from above one side of the box across it, every method, several cache geometries (the
// default, direct-mapped, 3 ways and non-power-of-two sets, fewer bytes than a set, no bytes) and
// run lengths: the same walks, and the same hits and misses.
TEST(ReliefLookupLinesTest, RecordedRunsCountAsEveryLookup) {
  const Field f;
  const FieldView view = f.view();
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<FragmentRay> rays;
  while (rays.size() < 600) {
    FragmentRay r;
    r.o = {unit(random) * kN, -4.0f * unit(random), 1.0f + 2.0f * unit(random)};
    r.d = {unit(random) - 0.5f, 0.2f + unit(random), -0.05f - 0.3f * unit(random)};
    float t_in = 0.0f, t_out = 3.0e38f;
    const float hi[3] = {static_cast<float>(kN), static_cast<float>(kN), 1.0f};
    for (std::size_t k = 0; k < 3; ++k) {
      const float t1 = (0.0f - r.o[k]) / r.d[k], t2 = (hi[k] - r.o[k]) / r.d[k];
      t_in = std::max(t_in, std::min(t1, t2));
      t_out = std::min(t_out, std::max(t1, t2));
    }
    if (!(t_in <= t_out)) continue;
    r.t_in = t_in, r.t_out = t_out;
    rays.push_back(r);
  }
  const memory::CacheConfig configs[] = {{16 * 1024, 64, 4}, {4096, 64, 1}, {12000, 64, 3}, {100, 64, 4}, {0, 64, 4}};
  for (const memory::CacheConfig& config : configs)
    for (const std::size_t run_length : {std::size_t{1}, std::size_t{7}, std::size_t{256}})
      for (const Method m : kAllMethods) {
        PerLookupCache want(config);
        TexelCache got(config);
        LookupLines run;
        std::uint64_t lookups = 0;
        for (std::size_t k = 0; k < rays.size(); ++k) {
          if (k % run_length == 0) {
            if (k > 0) got.take(run);
            run.reset(got.geometry());
          }
          const WalkResult a = walk(m, view, WalkParams{}, rays[k], &PerLookupCache::observe, &want);
          const WalkResult b = walk(m, view, WalkParams{}, rays[k], run);
          ASSERT_TRUE(a.hit == b.hit && a.t == b.t && a.lookups == b.lookups && a.steps == b.steps && a.bisections == b.bisections &&
                      a.capped == b.capped)
              << to_string(m) << " ray " << k;
          lookups += a.lookups;
        }
        got.take(run);
        EXPECT_EQ(got.draw_hits, want.hits) << to_string(m) << ", " << config.size_bytes << " bytes, " << config.ways << " ways, runs of " << run_length;
        EXPECT_EQ(got.draw_misses, want.misses) << to_string(m) << ", " << config.size_bytes << " bytes, " << config.ways << " ways";
        EXPECT_GT(lookups, 10 * rays.size()) << to_string(m);
      }
}

TEST(ReliefWorkerPoolTest, EveryWorkOnceThenInOrder) {
  for (const int threads : {1, 2, 4}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (const std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{500}}) {  // the pool is reused
      std::vector<std::atomic<int>> runs(count);
      std::vector<std::size_t> order;
      std::vector<int> seen(count, 0), slot(count, -1);
      pool.run(
          count,
          [&](std::size_t k) {
            runs[k].fetch_add(1), seen[k] = static_cast<int>(k) * 3;
            slot[k] = WorkerPool::slot();
          },
          [&](std::size_t k) {
            EXPECT_EQ(seen[k], static_cast<int>(k) * 3) << "then(k) sees what work(k) wrote";
            EXPECT_EQ(WorkerPool::slot(), 0) << "then runs on the calling thread";
            EXPECT_TRUE(slot[k] >= 0 && slot[k] < threads) << "work " << k << " on slot " << slot[k];
            order.push_back(k);
          });
      ASSERT_EQ(order.size(), count) << threads << " threads";
      for (std::size_t k = 0; k < count; ++k) {
        EXPECT_EQ(order[k], k);
        EXPECT_EQ(runs[k].load(), 1) << "work " << k << ", " << threads << " threads";
      }
    }
  }
}

TEST(ReliefWorkerPoolTest, WorkErrorIsRethrown) {
  for (const int threads : {1, 3}) {
    WorkerPool pool(threads);
    std::vector<std::size_t> handed;
    EXPECT_THROW(pool.run(
                     100, [](std::size_t k) { if (k == 40) throw std::runtime_error("work 40"); },
                     [&](std::size_t k) { handed.push_back(k); }),
                 std::runtime_error);
    ASSERT_LE(handed.size(), 40u) << "nothing handed on from the failed work on";
    std::atomic<int> after{0};
    pool.run(10, [&](std::size_t) { ++after; }, [](std::size_t) {});
    EXPECT_EQ(after.load(), 10) << "the pool still works";
  }
}

// `first` runs once on the calling thread, beside the works and before every then(k); its exception
// is rethrown once every started work has finished, with nothing handed on.
TEST(ReliefWorkerPoolTest, FirstRunsOnTheCallingThreadBeforeThen) {
  for (const int threads : {1, 2, 3}) {
    WorkerPool pool(threads);
    std::atomic<int> works{0};
    int firsts = 0, first_slot = -1;
    bool then_before_first = false;
    pool.run(
        64, [&](std::size_t) { ++works; }, [&](std::size_t) { then_before_first = then_before_first || firsts == 0; },
        [&] { ++firsts, first_slot = WorkerPool::slot(); });
    EXPECT_EQ(works.load(), 64);
    EXPECT_EQ(firsts, 1);
    EXPECT_EQ(first_slot, 0);
    EXPECT_FALSE(then_before_first);
    std::vector<std::size_t> handed;
    works = 0;
    EXPECT_THROW(pool.run(
                     50, [&](std::size_t) { ++works; }, [&](std::size_t k) { handed.push_back(k); },
                     [] { throw std::runtime_error("first"); }),
                 std::runtime_error);
    EXPECT_EQ(works.load(), 50) << "every work ran, as the pool cannot stop its helpers midway";
    EXPECT_TRUE(handed.empty());
    pool.run(3, [&](std::size_t) { ++works; }, [](std::size_t) {});
    EXPECT_EQ(works.load(), 53) << "the pool still works";
  }
}

// A frame: RLFH of the random field, seen from above the box's front edge, and one box draw a method
// covering the whole viewport (two triangles at depth 0), each with an empty RLFF (the comparison
// with GL is not what this checks: its pixel mismatches are the same for any thread count anyway).
scene::Frame box_frame(const Field& f, int width) {
  using scene::TechniqueField;
  scene::Frame frame;
  frame.begin.frame = 3;
  frame.end.frame = 3;
  scene::TechniqueRecord field;
  field.type = kReliefFieldRecordType;
  field.decoded = true;
  const float step = 1.0f / static_cast<float>(width);
  field.fields = {TechniqueField{"size", std::uint64_t{kN}},
                  TechniqueField{"levels", static_cast<std::uint64_t>(nbuffer_level_count(kN, kN))},
                  TechniqueField{"max_radius", std::uint64_t{kMaxRadius}},
                  TechniqueField{"field", std::string("fbm 32")},
                  TechniqueField{"heights", f.field.heights},
                  TechniqueField{"radius", f.radius.radius},
                  TechniqueField{"nbuffer", f.nbuffer},
                  TechniqueField{"linear_steps", std::uint64_t{16}},
                  TechniqueField{"binary_steps", std::uint64_t{8}},
                  TechniqueField{"root_steps", std::uint64_t{16}},
                  TechniqueField{"origin", std::vector<float>{16.0f, -10.0f, 1.5f}},
                  TechniqueField{"ray_a", std::vector<float>{step, 0.0f, 0.0f}},
                  TechniqueField{"ray_b", std::vector<float>{0.0f, 0.5f * step, 0.04f * step}},
                  TechniqueField{"ray_c", std::vector<float>{-0.5f, 0.6f, -0.06f}},
                  TechniqueField{"view_angle", 30.0},
                  TechniqueField{"frustum_apex", 0.0},
                  TechniqueField{"eye_h", std::vector<float>{}},
                  TechniqueField{"ray_q", std::vector<float>{}}};
  frame.technique_records.push_back(field);
  for (const Method m : kAllMethods) {
    scene::DrawRecord d;
    d.index = static_cast<std::uint32_t>(frame.draws.size());
    d.role = kReliefBoxRole;
    d.state.write = false;
    d.clip_positions = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {1, 1, 0, 1}, {-1, -1, 0, 1}, {1, 1, 0, 1}, {-1, 1, 0, 1}};
    scene::TechniqueRecord r;
    r.type = kReliefFragmentsRecordType;
    r.decoded = true;
    r.fields = {TechniqueField{"draw", std::uint64_t{d.index}},
                TechniqueField{"method", static_cast<std::uint64_t>(m)},
                TechniqueField{"count", std::uint64_t{0}},
                TechniqueField{"pixel", std::vector<std::uint32_t>{}},
                TechniqueField{"hit", std::vector<std::uint32_t>{}},
                TechniqueField{"t", std::vector<float>{}},
                TechniqueField{"lookups", std::vector<std::uint32_t>{}},
                TechniqueField{"steps", std::vector<std::uint32_t>{}},
                TechniqueField{"bisections", std::vector<std::uint32_t>{}}};
    frame.draws.push_back(d);
    frame.technique_records.push_back(r);
  }
  frame.end.draws = static_cast<std::uint32_t>(frame.draws.size());
  return frame;
}

struct DrawCache {
  TexelCache* cache;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> per_draw;  // hits, misses
  static void done(void* self, const BoxDrawCounts&) {
    auto* d = static_cast<DrawCache*>(self);
    d->per_draw.emplace_back(d->cache->draw_hits, d->cache->draw_misses);
    d->cache->draw_hits = d->cache->draw_misses = 0;
  }
};

// `frames` replays of a box frame at width x height with a 16 KiB texel cache emptied at each:
// every frame's counts and the cache's hits and misses per draw.
struct BoxReplay {
  std::vector<ReliefFrameCounts> frames;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> cache;
};
BoxReplay replay_box(const scene::Frame& frame, int width, int height, int threads, bool scoring = true, int frames = 1) {
  ReliefReplay r(width, height, true, {}, BoxDepth::None, threads);
  r.set_scoring(scoring);
  TexelCache cache(memory::CacheConfig{16 * 1024, 64, 4});
  DrawCache draws{&cache, {}};
  BoxReplay out;
  for (int k = 0; k < frames; ++k) {
    cache.invalidate();
    out.frames.push_back(r.run_frame(frame, 0.25, 0.25, &cache, &draws, &DrawCache::done));
  }
  out.cache = draws.per_draw;
  return out;
}

// The counts of two replays of a draw alike, the scores aside.
bool same_walks(const BoxDrawCounts& a, const BoxDrawCounts& b) {
  return a.fragments == b.fragments && a.samples == b.samples && a.pixel_mismatches == b.pixel_mismatches &&
         a.walk_mismatches == b.walk_mismatches && a.lookups == b.lookups && a.steps == b.steps && a.bisections == b.bisections &&
         a.hits == b.hits && a.capped == b.capped && a.longest_walk == b.longest_walk;
}

// Every count of every draw, and the texel cache's hits and misses per draw, with 1, 2 and 3
// threads (the runs of fragments then finish out of order), over two frames (the cache and the
// frame's references carried from draw to draw).
TEST(ReliefReplayThreadsTest, CountsDoNotDependOnThreads) {
  constexpr int kWidth = 96, kHeight = 80;
  const Field f;
  const scene::Frame frame = box_frame(f, kWidth);
  const auto replay = [&](int threads) {
    BoxReplay b = replay_box(frame, kWidth, kHeight, threads, true, 2);
    return std::pair{b.frames, b.cache};
  };
  const auto [one, one_cache] = replay(1);
  ASSERT_EQ(one.size(), 2u);
  ASSERT_EQ(one[0].draws.size(), 5u);
  for (const BoxDrawCounts& d : one[0].draws) {
    EXPECT_EQ(d.fragments, static_cast<std::uint64_t>(kWidth * kHeight)) << "the box covers the viewport";
    EXPECT_GT(d.hits, d.fragments / 4) << to_string(d.method);
    EXPECT_GT(d.lookups, 10 * d.fragments) << to_string(d.method);
  }
  for (const int threads : {2, 3}) {
    const auto [many, many_cache] = replay(threads);
    EXPECT_EQ(many_cache, one_cache) << threads << " threads";
    ASSERT_EQ(many.size(), one.size());
    for (std::size_t fr = 0; fr < one.size(); ++fr)
      for (std::size_t k = 0; k < one[fr].draws.size(); ++k) {
        const BoxDrawCounts &a = one[fr].draws[k], &b = many[fr].draws[k];
        EXPECT_TRUE(same_walks(a, b) && a.reference_hits == b.reference_hits && a.wrong_hit == b.wrong_hit && a.wrong_miss == b.wrong_miss &&
                    a.far_hit == b.far_hit && a.distance_sum == b.distance_sum)
            << "frame " << fr << ", " << to_string(a.method) << ", " << threads << " threads";
      }
  }
}

// Unscored walks (set_scoring(false), the bench's replay): every count but the five scores is the
// scored replay's, with the same cache outcomes, and the scores are 0 with `scored` false.
TEST(ReliefReplayScoringTest, UnscoredWalksCountAsScoredOnes) {
  constexpr int kWidth = 64, kHeight = 48;
  const Field f;
  const scene::Frame frame = box_frame(f, kWidth);
  const auto replay = [&](bool scoring) {
    BoxReplay b = replay_box(frame, kWidth, kHeight, 2, scoring);
    return std::pair{b.frames[0], b.cache};
  };
  const auto [scored, scored_cache] = replay(true);
  const auto [unscored, unscored_cache] = replay(false);
  EXPECT_EQ(unscored_cache, scored_cache);
  ASSERT_EQ(unscored.draws.size(), scored.draws.size());
  std::uint64_t reference_hits = 0;
  for (std::size_t k = 0; k < scored.draws.size(); ++k) {
    const BoxDrawCounts &a = scored.draws[k], &b = unscored.draws[k];
    EXPECT_TRUE(a.scored);
    EXPECT_FALSE(b.scored);
    EXPECT_TRUE(same_walks(a, b)) << to_string(a.method);
    EXPECT_EQ(b.reference_hits + b.wrong_hit + b.wrong_miss + b.far_hit, 0u) << to_string(b.method);
    EXPECT_EQ(b.distance_sum, 0.0);
    reference_hits += a.reference_hits;
  }
  EXPECT_GT(reference_hits, 0u) << "the scored replay computed references";
}

// The N-buffer walk's level reads computed on demand: the same values as the full build it read,
// part of the texels, the same counts for any thread count, and nothing for the other methods.
TEST(ReliefReplayLevelsTest, OnDemandLevelsEqualTheFullBuild) {
  constexpr int kWidth = 64, kHeight = 48;
  const Field f;
  const scene::Frame frame = box_frame(f, kWidth);
  const ReliefFrameCounts one = replay_box(frame, kWidth, kHeight, 1).frames[0], two = replay_box(frame, kWidth, kHeight, 2).frames[0];
  const int levels = nbuffer_level_count(kN, kN);
  for (std::size_t k = 0; k < one.draws.size(); ++k) {
    const BoxDrawCounts& d = one.draws[k];
    EXPECT_EQ(d.levels_on_demand_mismatches, 0u) << to_string(d.method);
    EXPECT_EQ(d.levels_on_demand_texels, two.draws[k].levels_on_demand_texels) << to_string(d.method);
    if (d.method != Method::NBuffer) {
      EXPECT_EQ(d.levels_eager_texels + d.levels_on_demand_texels, 0u) << to_string(d.method);
      continue;
    }
    EXPECT_EQ(d.levels_eager_texels, static_cast<std::uint64_t>(levels - 1) * kN * kN);
    EXPECT_GT(d.levels_on_demand_texels, 0u);
    EXPECT_LT(d.levels_on_demand_texels, d.levels_eager_texels);
  }
}

}  // namespace
}  // namespace nbsim::relief
