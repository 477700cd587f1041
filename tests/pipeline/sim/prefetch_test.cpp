// PrefetchTest: the read-ahead of pipeline/sim/prefetch.h hands over every item in the source's
// order, rethrows the source's error on the caller's thread (at the item where it happened, and
// again after), stays at the end once there, reads at most one item ahead, and stops cleanly when
// dropped before the end.
#include "pipeline/sim/prefetch.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace nbsim::sim {
namespace {

TEST(PrefetchTest, HandsOverEveryItemInOrderThenTheEnd) {
  int produced = 0;
  Prefetch<std::vector<int>> p([&]() -> std::optional<std::vector<int>> {
    if (produced == 500) return std::nullopt;
    const int k = produced++;
    return std::vector<int>(static_cast<std::size_t>(k % 7 + 1), k);
  });
  for (int k = 0; k < 500; ++k) {
    const std::optional<std::vector<int>> item = p.next();
    ASSERT_TRUE(item.has_value()) << "item " << k;
    ASSERT_EQ(item->size(), static_cast<std::size_t>(k % 7 + 1));
    EXPECT_EQ(item->front(), k) << "items out of order";
  }
  EXPECT_FALSE(p.next().has_value());
  EXPECT_FALSE(p.next().has_value()) << "the end stays the end";
}

TEST(PrefetchTest, RethrowsTheSourcesErrorWhereItHappened) {
  int produced = 0;
  Prefetch<int> p([&]() -> std::optional<int> {
    if (produced == 3) throw std::runtime_error("frame 3: damaged chunk");
    return produced++;
  });
  for (int k = 0; k < 3; ++k) EXPECT_EQ(p.next(), k);
  for (int again = 0; again < 2; ++again) {
    try {
      p.next();
      ADD_FAILURE() << "no error rethrown";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "frame 3: damaged chunk");
    }
  }
}

TEST(PrefetchTest, ReadsAtMostOneItemAhead) {
  std::atomic<int> produced{0};
  Prefetch<int> p([&]() -> std::optional<int> { return produced++; });
  for (int k = 0; k < 20; ++k) {
    EXPECT_EQ(p.next(), k);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // time to read ahead, if it would
    EXPECT_LE(produced.load(), k + 2) << "more than one item read ahead of the caller";
  }
}

TEST(PrefetchTest, StopsWhenDroppedBeforeTheEnd) {
  for (int taken = 0; taken < 3; ++taken) {
    std::atomic<int> produced{0};
    {
      Prefetch<int> p([&]() -> std::optional<int> { return produced++; });  // never ends by itself
      for (int k = 0; k < taken; ++k) EXPECT_EQ(p.next(), k);
    }  // the destructor must not hang
    EXPECT_LE(produced.load(), taken + 1);
  }
}

}  // namespace
}  // namespace nbsim::sim
