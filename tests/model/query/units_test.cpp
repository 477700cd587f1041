// HiZUnitsTest: the Hi-Z baselines as query structures (model/query/units.h): the tile Hi-Z and the
// Hi-Z pyramid units answer every query as their plain cores (model/hiz/) do, and spend the
// configured time on the caller's thread: a query its latency plus lookups over throughput, a batch
// one latency, a rebuild its texels over the build rate. One elaboration per process.
#include "model/query/units.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "model/hiz/pyramid.h"
#include "model/hiz/tile_hiz.h"
#include "tests/common/sc_driver.h"

extern "C" int sc_main(int, char*[]) { return 1; }  // libsystemc's main() needs one; gtest's main runs

namespace nbsim::query {
namespace {

using Driver = testing::ScriptDriver;

template <class F>
std::uint64_t timed(F&& f) {
  const std::uint64_t t0 = sim::now_cycles();
  f();
  return sim::now_cycles() - t0;
}

TEST(HiZUnitsTest, AnswerAsTheCoresInTheConfiguredTime) {
  sim::install_report_handler();
  DepthImage depth(64, 48, 1.0f);
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) depth.at(x, y) = 0.5f + 0.4f * static_cast<float>((x * 7 + y * 13) % 17) / 17.0f;
  const HiZUnitConfig config;  // 8x8 tiles, f32, 4 lookups a cycle + 8, 16 texels a cycle + 16
  stats::Registry reg;
  TileHiZUnit tile("tile", reg, config, depth.width, depth.height, FarOp::Max);
  HiZPyramidUnit pyramid("pyramid", reg, config, FarOp::Max);
  TileHiZ tile_core(depth.width, depth.height, config.tile(FarOp::Max));
  tile_core.build(depth);
  const HiZPyramid pyramid_core(depth, config.pyramid(FarOp::Max));
  const std::vector<Rect> rects = {{0, 0, 8, 8}, {3, 5, 20, 10}, {40, 30, 24, 18}, {0, 0, 64, 48}, {60, 44, 9, 9}};
  const std::vector<float> nearest = {0.95f, 0.3f, 0.95f, 0.3f, 0.95f};
  std::vector<std::string> errors;
  auto expect = [&](bool ok, const std::string& what) {
    if (!ok) errors.push_back(what);
  };
  Driver d("driver", [&] {
    Structure& t = tile;
    Structure& p = pyramid;
    expect(t.cleared(1.0f) == 0, "a tile Hi-Z clear is a fast clear");
    expect(t.changed(depth, {0, 0, depth.width, depth.height}) == 64u * 48u, "a whole-image change reads every pixel");
    expect(timed([&] { t.prepare(depth); }) == sim::batch_cycles(64 * 48, 16.0, 16), "tile update batch time");
    std::uint64_t texels = 0;
    for (int k = 0; k < pyramid_core.level_count(); ++k)
      texels += static_cast<std::uint64_t>(pyramid_core.level_width(k) * pyramid_core.level_height(k));
    std::uint64_t built = 0;
    expect(timed([&] { built = p.prepare(depth); }) == sim::batch_cycles(texels, 16.0, 16), "pyramid rebuild time");
    expect(built == texels, "the pyramid rebuild counts every level's texels");
    std::uint64_t tile_lookups = 0, pyramid_lookups = 0;
    for (std::size_t i = 0; i < rects.size(); ++i) {
      const std::string at = "rect " + std::to_string(i) + ": ";
      const TileHiZAnswer tc = tile_core.query(rects[i], nearest[i]);
      Answer a;
      const std::uint64_t tt = timed([&] { a = t.query(rects[i], nearest[i]); });
      expect(a.hidden == tc.hidden && a.lookups == static_cast<std::uint64_t>(tc.lookups), at + "tile answer");
      expect(tt == sim::batch_cycles(a.lookups, 4.0, 8), at + "tile query time " + std::to_string(tt));
      tile_lookups += a.lookups;
      const QueryResult pc = pyramid_core.query(rects[i]);
      const std::uint64_t pt = timed([&] { a = p.query(rects[i], nearest[i]); });
      expect(a.hidden == (pc.complete && nearest[i] > pc.value), at + "pyramid answer");
      expect(a.lookups == static_cast<std::uint64_t>(pc.texel_count), at + "pyramid lookups");
      expect(pt == sim::batch_cycles(a.lookups, 4.0, 8), at + "pyramid query time " + std::to_string(pt));
      pyramid_lookups += a.lookups;
    }
    Answer six;
    expect(timed([&] { six = t.query(rects[1], 0.3f); }) == 10 && six.lookups == 6, "6 tiles: 2 cycles after 8 of latency");
    std::vector<Answer> batch;
    expect(timed([&] { t.query_batch(rects, nearest, batch); }) == sim::batch_cycles(tile_lookups, 4.0, 8),
           "a tile batch pays one latency");
    expect(timed([&] { p.query_batch(rects, nearest, batch); }) == sim::batch_cycles(pyramid_lookups, 4.0, 8),
           "a pyramid batch pays one latency");
  });
  sc_core::sc_start();
  for (const auto& e : errors) ADD_FAILURE() << e;
  EXPECT_EQ(to_string(tile.structure_kind()), "hiz_tile");
  EXPECT_EQ(to_string(pyramid.structure_kind()), "hiz_pyramid");
  EXPECT_GT(reg.values()["tile"]["busy_cycles"].get<std::uint64_t>(), 0u);
}

}  // namespace
}  // namespace nbsim::query
