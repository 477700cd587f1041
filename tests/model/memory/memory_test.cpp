// MemoryTest: the memory channel's bandwidth and latency, and the cache's hits, misses and
// write-backs (model/memory/memory.h).
#include "model/memory/memory.h"

#include <gtest/gtest.h>

namespace nbsim::memory {
namespace {

// Back-to-back transfers queue behind each other; an idle channel costs only size and latency.
TEST(MemoryTest, ChannelQueuesTransfers) {
  Channel ch({32.0, 100});
  const int depth = ch.add_client("depth"), nb = ch.add_client("nbuffer");
  EXPECT_EQ(ch.transfer(0, 320, depth), 10u + 100u) << "320 B at 32 B/cycle take 10 cycles, plus latency";
  EXPECT_EQ(ch.transfer(0, 64, nb), 12u + 100u) << "the second transfer waits for the first";
  EXPECT_EQ(ch.transfer(1000, 32, nb), 1001u + 100u) << "an idle channel starts at once";
  EXPECT_EQ(ch.bytes(depth), 320u);
  EXPECT_EQ(ch.bytes(nb), 96u);
  EXPECT_EQ(ch.busy_cycles(), 13u);
}

// A cache hits on a line it holds, evicts the least recently used way, and writes back dirty lines.
TEST(MemoryTest, CacheLruAndWriteBack) {
  Cache c({2 * 64, 64, 2});  // one set of two 64-byte ways
  EXPECT_FALSE(c.access(0, true).hit);
  EXPECT_TRUE(c.access(8, false).hit) << "same line";
  EXPECT_FALSE(c.access(64, false).hit);
  EXPECT_TRUE(c.access(0, false).hit);  // line 0 is now most recent
  const auto r = c.access(128, false);  // evicts line 1 (clean)
  EXPECT_FALSE(r.hit);
  EXPECT_FALSE(r.writeback);
  const auto r2 = c.access(192, false);  // evicts line 0 (dirty)
  EXPECT_TRUE(r2.writeback);
  EXPECT_EQ(c.hits(), 2u);
  EXPECT_EQ(c.misses(), 4u);
  EXPECT_EQ(c.writebacks(), 1u);
}

// A cache of size 0 is no cache: every access misses.
TEST(MemoryTest, ZeroSizeCacheAlwaysMisses) {
  Cache c({0, 64, 4});
  EXPECT_FALSE(c.access(0, false).hit);
  EXPECT_FALSE(c.access(0, false).hit);
  EXPECT_EQ(c.misses(), 2u);
}

}  // namespace
}  // namespace nbsim::memory
