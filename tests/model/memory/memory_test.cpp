// MemoryTest: the memory channel's bandwidth and latency, and the cache's hits, misses and
// write-backs (model/memory/memory.h). LineCacheTest: the read-only line cache against Cache.
#include "model/memory/memory.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

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


// LineCache must give every read the hit or miss Cache gives it, for any geometry: associativities
// with an unrolled path (1, 2, 4, 8; 4 ways in AVX2 registers in read_all where the CPU has AVX2)
// and without (3, 16), set counts that are powers of two and not, fewer bytes than one set, and none. The random streams mix a hot region (hits at every LRU depth)
// with a wide one (misses and evictions).
TEST(LineCacheTest, SameHitsAndMissesAsCache) {
  const CacheConfig configs[] = {{16 * 1024, 64, 4}, {16 * 1024, 64, 1}, {8 * 1024, 32, 2},  {4096, 64, 8},  {12000, 64, 3},
                                 {16 * 1024, 64, 16}, {64 * 6 * 4, 64, 4}, {100, 64, 4},      {0, 64, 4},     {2048, 4, 4}};
  for (const CacheConfig& config : configs) {
    std::mt19937_64 random(config.size_bytes * 131 + config.ways);
    Cache reference(config);
    LineCache lines(config);
    std::uint64_t hits = 0;
    for (int k = 0; k < 200000; ++k) {
      const std::uint64_t address = random() % 4 != 0 ? random() % (2 * static_cast<std::uint64_t>(config.size_bytes) + 256)
                                                      : random() % (1u << 24);
      const bool want = reference.access(address, false).hit;
      ASSERT_EQ(lines.read(address / static_cast<std::uint64_t>(config.line_bytes)), want)
          << "read " << k << " of address " << address << ", cache of " << config.size_bytes << " bytes, " << config.ways << " ways";
      hits += want;
    }
    // read_all of a sequence is read() of each.
    LineCache all(config), each(config);
    std::vector<std::uint64_t> sequence(5000);
    for (std::uint64_t& line : sequence) line = random() % (4 * static_cast<std::uint64_t>(config.size_bytes / config.line_bytes) + 8);
    std::uint64_t each_hits = 0;
    for (const std::uint64_t line : sequence) each_hits += each.read(line) ? 1 : 0;
    EXPECT_EQ(all.read_all(sequence), each_hits);
    EXPECT_EQ(all.misses(), each.misses());
    // ... and leaves the same ways in the same order: a second sequence hits and misses alike.
    for (const std::uint64_t line : sequence) ASSERT_EQ(all.read((line * 7 + 3) % (sequence.size() / 2 + 1)), each.read((line * 7 + 3) % (sequence.size() / 2 + 1)));
    EXPECT_EQ(all.read_all(sequence), [&] {
      std::uint64_t h = 0;
      for (const std::uint64_t line : sequence) h += each.read(line) ? 1 : 0;
      return h;
    }());
    EXPECT_EQ(lines.hits(), reference.hits());
    EXPECT_EQ(lines.misses(), reference.misses());
    if (config.size_bytes >= config.line_bytes * config.ways) {
      EXPECT_GT(hits, 1000u) << "the stream must exercise hits";
    }
    // After invalidate both start cold again.
    reference.invalidate();
    lines.invalidate();
    EXPECT_EQ(lines.read(0), reference.access(0, false).hit);
  }
}

}  // namespace
}  // namespace nbsim::memory
