// NBufferUnitTest: the N-buffer unit's SystemC wrapper (model/nbuffer/unit.h): a query takes its
// latency plus lookups over throughput (plus memory on misses), queries wait for the update work
// posted before them and no more, and a unit's latency changes cycles but never lookup counts.
// One elaboration per process: ctest runs each TEST in its own process.
#include "model/nbuffer/unit.h"

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tests/common/reference.h"
#include "tests/common/sc_driver.h"

extern "C" int sc_main(int, char*[]) { return 1; }  // libsystemc's main() needs one; gtest's main runs

namespace nbsim::nbuffer {
namespace {

using Driver = testing::ScriptDriver;

NBufferUnitConfig timing(int latency, double per_cycle, const char* policy = "eager") {
  NBufferUnitConfig c;
  c.lookup_latency_cycles = latency;
  c.lookups_per_cycle = per_cycle;
  c.update_texels_per_cycle = 16.0;
  c.update_latency_cycles = 16;
  c.update_policy = policy;
  return c;
}

// Cycles a call takes, measured in the calling thread.
template <class F>
std::uint64_t timed(F&& f) {
  const std::uint64_t t0 = sim::now_cycles();
  f();
  return sim::now_cycles() - t0;
}

// Without memory (no channel), a query takes ceil(lookups / lookups_per_cycle) + latency cycles.
TEST(NBufferUnitTest, QueryTakesLatencyPlusThroughput) {
  sim::install_report_handler();
  stats::Registry reg;
  NBufferUnit fast("fast", reg, timing(8, 4.0), 64, 64, FarOp::Max, nullptr);
  NBufferUnit slow("slow", reg, timing(8, 1.0), 64, 64, FarOp::Max, nullptr);
  struct Row {
    Rect r;
    int lookups;
    std::uint64_t fast, slow;
  };
  const Row rows[] = {
      {{3, 5, 30, 30}, 4, 1 + 8, 4 + 8},  // level 4, two anchors per axis
      {{0, 0, 20, 16}, 2, 1 + 8, 2 + 8},  // level 4, side by side
      {{0, 0, 16, 16}, 4, 1 + 8, 4 + 8},  // the paper's covering: four quadrants of level 3
      {{70, 0, 4, 4}, 0, 0, 0},           // off the image: no lookups, no cycles
  };
  std::vector<std::string> errors;
  Driver d("driver", [&] {
    for (const Row& row : rows) {
      QueryAnswer a;
      const std::uint64_t tf = timed([&] { a = fast.query(row.r, 0.5f); });
      if (a.lookups != row.lookups) errors.push_back(ref::str(row.r) + ": lookups " + std::to_string(a.lookups));
      if (tf != row.fast) errors.push_back(ref::str(row.r) + ": fast unit took " + std::to_string(tf));
      const std::uint64_t ts = timed([&] { slow.query(row.r, 0.5f); });
      if (ts != row.slow) errors.push_back(ref::str(row.r) + ": slow unit took " + std::to_string(ts));
    }
  });
  sc_core::sc_start();
  for (const auto& e : errors) ADD_FAILURE() << e;
  EXPECT_EQ(reg.values()["fast"]["busy_cycles"], 27) << "busy cycles are the query cycles";
  EXPECT_EQ(reg.values()["slow"]["busy_cycles"], 12 + 10 + 12);
  EXPECT_EQ(reg.values()["fast"]["lookups"]["4"], 6);
  EXPECT_EQ(reg.values()["fast"]["lookups"]["3"], 4);
}

// Cache misses go to the memory channel: a cold query waits for the line fills, a warm one does not.
TEST(NBufferUnitTest, MissesWaitForMemory) {
  sim::install_report_handler();
  stats::Registry reg;
  memory::Channel channel(memory::ChannelConfig{32.0, 100});
  struct Gpu : sc_core::sc_module {
    NBufferUnit nbuffer;
    Gpu(const sc_core::sc_module_name& n, stats::Registry& r, memory::Channel* ch)
        : sc_core::sc_module(n), nbuffer("nbuffer", r, timing(8, 4.0), 64, 64, FarOp::Max, ch) {}
  } gpu("gpu", reg, &channel);
  NBufferUnit& unit = gpu.nbuffer;
  std::uint64_t cold = 0, warm = 0;
  QueryAnswer a;
  Driver d("driver", [&] {
    cold = timed([&] { a = unit.query({3, 5, 30, 30}, 0.5f); });
    warm = timed([&] { unit.query({3, 5, 30, 30}, 0.5f); });
  });
  sc_core::sc_start();
  ASSERT_EQ(a.cache_misses, 4u);
  EXPECT_EQ(cold, 4u * 256u / 32u + 100u) << "four 256-byte lines at 32 B/cycle, then the channel's latency";
  EXPECT_EQ(warm, 9u) << "all hits: latency plus throughput only";
  EXPECT_EQ(channel.bytes(0), 1024u) << "bytes are charged to the unit's client";
  EXPECT_EQ(channel.clients().at(0), "gpu.nbuffer");
  EXPECT_EQ(reg.values()["gpu.nbuffer"]["memory_stall_cycles"], 132 - 9);
}

// Eager updates run on the unit's update engine: the depth unit does not wait, a query waits for
// the work posted before it arrived, and not for work posted after.
TEST(NBufferUnitTest, QueriesWaitForEarlierUpdatesOnly) {
  sim::install_report_handler();
  stats::Registry reg;
  NBufferUnit unit("nb", reg, timing(8, 4.0), 32, 32, FarOp::Max, nullptr);
  // The same changes on a plain core give the update work to expect.
  stats::Registry ref_reg;
  NBufferUnitCore ref_core(timing(8, 4.0), 32, 32, FarOp::Max, ref_reg.group("ref"));
  const DepthImage first(32, 32, 0.5f);
  DepthImage second = first;
  second.at(3, 3) = 0.25f;
  const std::uint64_t batch1 = sim::batch_cycles(ref_core.depth_changed(first, {0, 0, 32, 32}).recomputed(), 16.0, 16);
  const std::uint64_t batch2 = sim::batch_cycles(ref_core.depth_changed(second, {0, 0, 8, 8}).recomputed(), 16.0, 16);
  std::uint64_t posted_by = 0, answered_at = 0;
  QueryAnswer a;
  Driver depth("depth", [&] {
    unit.depth_changed(first, {0, 0, 32, 32});
    posted_by = sim::now_cycles();
    sc_core::wait(sim::cycles(5));
    unit.depth_changed(second, {0, 0, 8, 8});
  });
  Driver cull("cull", [&] {
    sc_core::wait(sim::cycles(1));
    a = unit.query({0, 0, 4, 4}, 0.75f);
    answered_at = sim::now_cycles();
  });
  sc_core::sc_start();
  EXPECT_EQ(posted_by, 0u) << "posting a change does not block the depth unit";
  EXPECT_TRUE(a.hidden) << "the answer sees the first change";
  EXPECT_EQ(answered_at, batch1 + 9) << "the query waits for the first batch only, then takes 9 cycles";
  EXPECT_EQ(sim::now_cycles(), batch1 + batch2) << "the second batch runs after the first";
  const auto v = reg.values()["nb"];
  EXPECT_EQ(v["update_batches"], 2);
  EXPECT_EQ(v["update_cycles"], batch1 + batch2);
  EXPECT_EQ(v["query_wait_cycles"], batch1 - 1);
  EXPECT_EQ(v["busy_cycles"], batch1 + batch2 + 9);
}

// Lazy: the query pays for the pending changes it applies; the engine does nothing.
TEST(NBufferUnitTest, LazyQueryPaysForItsUpdates) {
  sim::install_report_handler();
  stats::Registry reg;
  NBufferUnit unit("nb", reg, timing(8, 4.0, "lazy"), 32, 32, FarOp::Max, nullptr);
  QueryAnswer a;
  std::uint64_t took = 0;
  Driver d("driver", [&] {
    unit.depth_changed(DepthImage(32, 32, 0.5f), {0, 0, 32, 32});
    took = timed([&] { a = unit.query({0, 0, 4, 4}, 0.75f); });
  });
  sc_core::sc_start();
  ASSERT_GT(a.update.recomputed(), 0u);
  EXPECT_TRUE(a.hidden);
  EXPECT_EQ(took, sim::batch_cycles(a.update.recomputed(), 16.0, 16) + 9);
  EXPECT_EQ(reg.values()["nb"]["update_batches"], 0);
}

// The same workload on units that differ only in lookup latency: cycles change, lookups, answers
// and update work do not (for every policy).
TEST(NBufferUnitTest, LatencyChangesCyclesNotLookups) {
  sim::install_report_handler();
  stats::Registry reg;
  struct Run {
    std::unique_ptr<memory::Channel> channel;
    std::unique_ptr<NBufferUnit> unit;
    std::unique_ptr<Driver> driver;
    std::vector<float> answers;
    std::uint64_t lookups = 0, end = 0;
  };
  std::vector<std::unique_ptr<Run>> runs;
  for (const char* policy : {"eager", "batched", "lazy"})
    for (const int latency : {8, 40}) {
      auto run = std::make_unique<Run>();
      Run* r = run.get();
      const std::string name = std::string(policy) + "_" + std::to_string(latency);
      r->channel = std::make_unique<memory::Channel>(memory::ChannelConfig{});
      r->unit = std::make_unique<NBufferUnit>((name + "_nb").c_str(), reg, timing(latency, 4.0, policy), 48, 40,
                                              FarOp::Max, r->channel.get());
      r->driver = std::make_unique<Driver>((name + "_drv").c_str(), [r] {
        std::mt19937 rng(42);
        DepthImage depth(48, 40, 1.0f);
        for (int pass = 0; pass < 4; ++pass) {
          for (int draw = 0; draw < 10; ++draw) {
            const Rect box = ref::random_rect(rng, 48, 40, false);
            const float z = ref::unit_float(rng);
            const QueryAnswer a = r->unit->query(box, z);
            r->answers.push_back(a.value);
            r->lookups += static_cast<std::uint64_t>(a.lookups);
            if (a.hidden) continue;
            for (int y = box.y; y < box.y1(); ++y)
              for (int x = box.x; x < box.x1(); ++x) depth.at(x, y) = std::min(depth.at(x, y), z);
            r->unit->depth_changed(depth, box);
            sc_core::wait(sim::cycles(static_cast<std::uint64_t>(box.area() / 16 + 1)));  // rasterizing the box
          }
          r->unit->end_of_pass();
        }
        r->unit->drain();
        r->end = sim::now_cycles();
      });
      runs.push_back(std::move(run));
    }
  sc_core::sc_start();
  const auto v = reg.values();
  for (std::size_t i = 0; i < runs.size(); i += 2) {
    const Run &fast = *runs[i], &slow = *runs[i + 1];
    const std::string fn = fast.unit->name(), sn = slow.unit->name();
    EXPECT_GT(fast.lookups, 0u);
    EXPECT_EQ(fast.lookups, slow.lookups) << fn << " vs " << sn << ": lookup counts must not depend on latency";
    EXPECT_EQ(fast.answers, slow.answers) << fn << " vs " << sn;
    EXPECT_LT(fast.end, slow.end) << fn << " vs " << sn << ": a longer latency must cost cycles";
    EXPECT_EQ(v[fn]["lookups"], v[sn]["lookups"]);
    EXPECT_EQ(v[fn]["texels_recomputed"], v[sn]["texels_recomputed"]);
    EXPECT_EQ(v[fn]["queries"], v[sn]["queries"]);
  }
}

}  // namespace
}  // namespace nbsim::nbuffer
