// CullPrimitiveTest: per-primitive culling (cull.granularity=primitive, model/cull/primitive.h).
// The core's query of a triangle against brute force on random and adversarial triangles (its
// rectangle holds every covered pixel, its nearest depth bounds every fragment depth), and
// `nbsim replay` on the sample traces, one replay per process: triangles are culled, none with a
// fragment that could pass, and every drawn object keeps the passed samples it gets at object
// granularity while fewer depth tests are drawn.
#include "model/cull/primitive.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "model/raster/rasterizer.h"
#include "tests/common/run_nbsim.h"
#include "tests/model/raster/coverage.h"

namespace nbsim {
namespace {

using raster::testing::reference_covers;

constexpr int kW = 203, kH = 141;  // no multiple of 4, 16 or 64

// Random window-space triangles from sub-pixel to larger than the target, some on the half-pixel
// grid (edges through pixel centres), some slivers (a vertex near the opposite edge), with depths
// over [0, 1] (steep planes), and some with one depth outside [0, 1] (the clamp).
std::vector<geometry::WindowTriangle> random_triangles(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<geometry::WindowTriangle> out;
  for (int i = 0; i < n; ++i) {
    const float scale = std::pow(2.0f, unit(rng) * 10.0f - 2.0f);  // 0.25 .. 256 px
    const float cx = -40.0f + unit(rng) * (kW + 80.0f), cy = -40.0f + unit(rng) * (kH + 80.0f);
    geometry::WindowTriangle t;
    for (auto& v : t.v) {
      v = geometry::WindowVertex{cx + (unit(rng) - 0.5f) * scale, cy + (unit(rng) - 0.5f) * scale, unit(rng), 1.0f};
      if (i % 4 == 1) {
        v.x = std::round(v.x * 2.0f) / 2.0f;
        v.y = std::round(v.y * 2.0f) / 2.0f;
      }
    }
    if (i % 4 == 2) {  // sliver: vertex 2 just off the middle of edge 0-1
      const float s = (unit(rng) - 0.5f) * 0.02f;
      t.v[2].x = 0.5f * (t.v[0].x + t.v[1].x) + s * (t.v[1].y - t.v[0].y);
      t.v[2].y = 0.5f * (t.v[0].y + t.v[1].y) - s * (t.v[1].x - t.v[0].x);
    }
    if (i % 8 == 3) t.v[0].z = -0.5f + 2.0f * unit(rng);
    out.push_back(t);
  }
  return out;
}

// The rectangle holds every pixel whose centre the snapped triangle covers (brute-force reference
// over the whole target) and every pixel the tile walk reports.
TEST(CullPrimitiveTest, RectangleHoldsEveryCoveredPixel) {
  const raster::TriangleSetup setup(raster::SetupConfig{kW, kH});
  const raster::Rasterizer walk(kW, kH);
  raster::SetupCounters sc;
  raster::TileCounters tc;
  int tested = 0, covered = 0, failures = 0;
  for (const auto& t : random_triangles(1200, 11)) {
    raster::SetupTriangle s;
    if (setup.setup(t, raster::testing::kNoCull, s, sc) != raster::SetupResult::Accepted) continue;
    const cull::PrimitiveQuery q = cull::primitive_query(t, s, FarOp::Max, true);
    ++tested;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        if (!reference_covers(t, x, y)) continue;
        ++covered;
        if (!q.rect.contains(x, y) && failures++ < 10)
          ADD_FAILURE() << "pixel (" << x << "," << y << ") covered outside the rectangle " << q.rect;
      }
    walk.rasterize(s, tc, [&](int x, int y, std::uint16_t mask) {
      for (int b = 0; b < 16; ++b)
        if ((mask & (1u << b)) && !q.rect.contains(x + (b & 3), y + (b >> 2)) && failures++ < 10)
          ADD_FAILURE() << "walked pixel (" << x + (b & 3) << "," << y + (b >> 2) << ") outside " << q.rect;
    });
    EXPECT_TRUE(clip(q.rect, kW, kH) == q.rect) << "the rectangle must lie inside the target";
  }
  EXPECT_GT(tested, 500) << "too few triangles accepted: the test could not fail";
  EXPECT_GT(covered, 100000) << "the random triangles must cover a meaningful area";
}

// No fragment the depth unit computes (fused or not) is nearer than the nearest depth, under LESS
// (a lower bound) and under reversed Z (an upper bound).
TEST(CullPrimitiveTest, NearestDepthBoundsEveryFragment) {
  const raster::TriangleSetup setup(raster::SetupConfig{kW, kH});
  const raster::Rasterizer walk(kW, kH);
  raster::SetupCounters sc;
  raster::TileCounters tc;
  int failures = 0;
  long fragments = 0;
  for (const bool fused : {true, false})
    for (const auto& t : random_triangles(3000, fused ? 5 : 6)) {
      raster::SetupTriangle s;
      if (setup.setup(t, raster::testing::kNoCull, s, sc) != raster::SetupResult::Accepted) continue;
      const cull::PrimitiveQuery lo = cull::primitive_query(t, s, FarOp::Max, fused);
      const cull::PrimitiveQuery hi = cull::primitive_query(t, s, FarOp::Min, fused);
      walk.rasterize(s, tc, [&](int x, int y, std::uint16_t mask) {
        for (int b = 0; b < 16; ++b) {
          if (!(mask & (1u << b))) continue;
          ++fragments;
          const float z = s.depth.at(x + (b & 3), y + (b >> 2), fused);
          if (lo.testable && z < lo.nearest && failures++ < 10)
            ADD_FAILURE() << "fragment depth " << z << " nearer than the LESS bound " << lo.nearest << (fused ? " (fused)" : "");
          if (hi.testable && z > hi.nearest && failures++ < 10)
            ADD_FAILURE() << "fragment depth " << z << " nearer than the GREATER bound " << hi.nearest << (fused ? " (fused)" : "");
        }
      });
    }
  EXPECT_GT(fragments, 100000);
}

// Why the bound comes from setup's plane and not the vertices: snapping and the float plane put
// some fragments nearer than every vertex, so min vertex z would cull visible fragments.
TEST(CullPrimitiveTest, MinVertexDepthIsNoBound) {
  const raster::TriangleSetup setup(raster::SetupConfig{kW, kH});
  const raster::Rasterizer walk(kW, kH);
  raster::SetupCounters sc;
  raster::TileCounters tc;
  int below = 0;
  for (const auto& t : random_triangles(3000, 7)) {
    raster::SetupTriangle s;
    if (setup.setup(t, raster::testing::kNoCull, s, sc) != raster::SetupResult::Accepted) continue;
    const float zmin = std::max(0.0f, std::min({t.v[0].z, t.v[1].z, t.v[2].z}));
    bool found = false;
    walk.rasterize(s, tc, [&](int x, int y, std::uint16_t mask) {
      for (int b = 0; b < 16; ++b)
        if ((mask & (1u << b)) && s.depth.at(x + (b & 3), y + (b >> 2)) < zmin) found = true;
    });
    below += found ? 1 : 0;
  }
  EXPECT_GT(below, 0) << "no triangle had a fragment nearer than its nearest vertex: the design note is stale";
}

// Edge cases, each with its reason: the bound is tight where it can be.
TEST(CullPrimitiveTest, NearestDepthCases) {
  const raster::TriangleSetup setup(raster::SetupConfig{kW, kH});
  struct Row {
    geometry::WindowTriangle t;
    FarOp op;
    float want_at_least, want_at_most;
    const char* why;
  };
  using raster::testing::tri;
  // Depth 0.5 + 0.002 (x - 10) - 0.002 (y - 10): 0.5, 0.58, 0.42 at the vertices, 0.34 at the box
  // corner (10, 90) and 0.66 at (90, 10), which no fragment reaches.
  geometry::WindowTriangle tilted = tri(10.0f, 10.0f, 90.0f, 50.0f, 50.0f, 90.0f);
  tilted.v[0].z = 0.5f, tilted.v[1].z = 0.58f, tilted.v[2].z = 0.42f;
  geometry::WindowTriangle off_far = tri(-50.0f, 10.0f, 50.0f, 10.0f, -50.0f, 60.0f);
  off_far.v[0].z = 0.1f, off_far.v[1].z = 0.9f, off_far.v[2].z = 0.1f;
  const Row rows[] = {
      {tri(10.0f, 10.0f, 60.0f, 10.0f, 10.0f, 60.0f, 0.5f), FarOp::Max, 0.5f, 0.5f, "a flat triangle: its depth, exactly"},
      {tri(10.0f, 10.0f, 60.0f, 10.0f, 10.0f, 60.0f, 0.5f), FarOp::Min, 0.5f, 0.5f, "reversed Z: the same"},
      {tri(10.0f, 10.0f, 60.0f, 10.0f, 10.0f, 60.0f, 1.0f), FarOp::Max, 1.0f, 1.0f, "at the far plane: 1 (culled behind a nearer depth)"},
      {tilted, FarOp::Max, 0.4199f, 0.4201f, "tilted: the nearest vertex, not the box corner the plane extrapolates to"},
      {tilted, FarOp::Min, 0.5799f, 0.5801f, "tilted, reversed Z: the vertex of largest depth"},
      {off_far, FarOp::Max, 0.5f, 0.5041f,
       "crossing the left border: the box's corner pixel (0.5 + 50 px from the vertices at 0.1) bounds it tighter"},
  };
  for (const Row& row : rows) {
    raster::SetupTriangle s;
    raster::SetupCounters sc;
    ASSERT_EQ(setup.setup(row.t, raster::testing::kNoCull, s, sc), raster::SetupResult::Accepted) << row.why;
    const cull::PrimitiveQuery q = cull::primitive_query(row.t, s, row.op, true);
    EXPECT_TRUE(q.testable) << row.why;
    EXPECT_GE(q.nearest, row.want_at_least) << row.why;
    EXPECT_LE(q.nearest, row.want_at_most) << row.why;
  }
}

// The granularity names round-trip and only the depth-query modes support "primitive".
TEST(CullPrimitiveTest, GranularityNames) {
  EXPECT_EQ(cull::parse_granularity("object"), cull::Granularity::Object);
  EXPECT_EQ(cull::parse_granularity("primitive"), cull::Granularity::Primitive);
  EXPECT_FALSE(cull::parse_granularity("triangle").has_value());
  EXPECT_EQ(cull::to_string(cull::Granularity::Primitive), "primitive");
  for (const cull::CullMode m : {cull::CullMode::Nb, cull::CullMode::NbHier, cull::CullMode::HizTile, cull::CullMode::HizPyramid})
    EXPECT_TRUE(cull::supports_primitive_granularity(m)) << cull::to_string(m);
  for (const cull::CullMode m : {cull::CullMode::Trace, cull::CullMode::None, cull::CullMode::Oq, cull::CullMode::OqHier})
    EXPECT_FALSE(cull::supports_primitive_granularity(m)) << cull::to_string(m);
}

// --- Replays (each runs the nbsim executable: one SystemC elaboration per process) ---

std::string sample(const std::string& name) { return (std::filesystem::path(NBSIM_SAMPLES) / name).string(); }

struct ReplayRun {
  nlohmann::json run;  // run.json
  std::map<std::pair<long, long>, std::tuple<long, long, std::string>> draws;  // (frame, draw) -> passed, fragments, role
};

ReplayRun replay(const std::string& trace, const std::string& mode, const std::string& granularity) {
  ReplayRun r;
  const auto out = testing::scratch_path("nbsim_prim", trace + "_" + mode + "_" + granularity);
  std::filesystem::remove_all(out);
  const auto res = testing::run_nbsim("replay " + sample(trace) + " --set cull.mode=" + mode +
                                      " --set cull.granularity=" + granularity + " --out " + out.string());
  EXPECT_EQ(res.status, 0) << res.err;
  std::ifstream in(out / "run.json");
  r.run = nlohmann::json::parse(in, nullptr, false);
  std::ifstream csv(out / "draws.csv");
  std::string line;
  std::getline(csv, line);  // frame,draw,object,role,triangles,...,model_fragments(7),gl_fragments,model_passed(9),...
  while (std::getline(csv, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
    if (f.size() < 10) continue;
    r.draws[{std::stol(f[0]), std::stol(f[1])}] = {std::stol(f[9]), std::stol(f[7]), f[3]};
  }
  std::filesystem::remove_all(out);
  return r;
}

// (sample trace, cull mode) as strings: GoogleTest prints them as text (const char*s in a tuple
// print with their addresses, which then change the ctest names from build to build).
class CullPrimitiveReplayTest : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

// Primitive granularity culls triangles, none with a fragment that could pass; every drawn object
// keeps its passed samples; fewer depth tests are drawn; the query counts include the lookups.
TEST_P(CullPrimitiveReplayTest, CullsTrianglesAndKeepsPassedSamples) {
  const auto [trace, mode] = GetParam();
  const ReplayRun object = replay(trace, mode, "object");
  const ReplayRun prim = replay(trace, mode, "primitive");
  ASSERT_TRUE(object.run.is_object() && prim.run.is_object());
  const nlohmann::json& o = object.run["summary"]["cull"];
  const nlohmann::json& p = prim.run["summary"]["cull"];
  EXPECT_EQ(p["granularity"], "primitive");
  EXPECT_EQ(o["primitive_tests"], 0u) << "object granularity tests no triangle";
  EXPECT_GT(p["primitive_tests"].get<std::uint64_t>(), 0u);
  EXPECT_GT(p["primitives_culled"].get<std::uint64_t>(), 0u) << mode << " culled no triangle: the test could not fail";
  EXPECT_EQ(p["primitive_false_culls"], 0u) << "a culled triangle had a fragment passing against the occluders' depth";
  EXPECT_EQ(p["false_culls"], 0u);
  EXPECT_EQ(p["visible_draws_passed_below_gl"], 0u) << "a drawn object passed fewer samples than GL counted";
  EXPECT_EQ(p["culled"], o["culled"]) << "the objects' decisions must not change";
  EXPECT_LT(p["drawn_depth_tests"].get<std::uint64_t>(), o["drawn_depth_tests"].get<std::uint64_t>());
  EXPECT_EQ(o["drawn_depth_tests"].get<std::uint64_t>() - p["drawn_depth_tests"].get<std::uint64_t>(),
            p["primitive_fragments_culled"].get<std::uint64_t>())
      << "the saved depth tests are the culled triangles' fragments";
  EXPECT_EQ(p["query_depth_tests"].get<std::uint64_t>(),
            p["box_depth_tests"].get<std::uint64_t>() + p["lookups"].get<std::uint64_t>() + p["primitive_lookups"].get<std::uint64_t>());
  EXPECT_EQ(p["lookups"], o["lookups"]) << "the bounds tests are unchanged";
  std::uint64_t per_frame = 0;
  for (const auto& f : prim.run["frames"]) per_frame += f["primitives_culled"].get<std::uint64_t>();
  EXPECT_EQ(per_frame, p["primitives_culled"].get<std::uint64_t>()) << "per-frame entries must add up";
  EXPECT_EQ(prim.run["stats"]["gpu.cull"]["primitives_culled"], p["primitives_culled"]) << "the unit's statistic";

  ASSERT_EQ(object.draws.size(), prim.draws.size()) << "the same draws are replayed";
  int differ = 0;
  for (const auto& [key, ob] : object.draws) {
    const auto it = prim.draws.find(key);
    ASSERT_NE(it, prim.draws.end()) << "frame " << key.first << " draw " << key.second;
    if (std::get<0>(it->second) != std::get<0>(ob) && differ++ < 5)
      ADD_FAILURE() << "frame " << key.first << " draw " << key.second << " (" << std::get<2>(ob) << "): passed "
                    << std::get<0>(it->second) << " at primitive granularity, " << std::get<0>(ob) << " at object granularity";
    EXPECT_LE(std::get<1>(it->second), std::get<1>(ob)) << "dropping triangles cannot add fragments";
  }
}

INSTANTIATE_TEST_SUITE_P(Samples, CullPrimitiveReplayTest,
                         ::testing::Combine(::testing::Values("city_small_oq.nbt", "city_small_nb_reversed.nbt"),
                                            ::testing::Values("nb", "nb_hier", "hiz_tile", "hiz_pyramid")),
                         [](const auto& param_info) {
                           const std::string file = std::get<0>(param_info.param);
                           return file.substr(0, file.find('.')) + "_" + std::get<1>(param_info.param);
                         });

// A mode without a depth-query structure refuses primitive granularity (exit 2, the key named),
// and so does an unknown value.
TEST(CullPrimitiveReplayTest, RefusesPrimitiveWithoutQueryStructure) {
  const auto out = testing::scratch_path("nbsim_prim", "refused");
  for (const char* mode : {"oq", "oq_hier", "none", "trace"}) {
    const auto r = testing::run_nbsim("replay " + sample("city_small_oq.nbt") + " --set cull.mode=" + mode +
                                      " --set cull.granularity=primitive --out " + out.string());
    EXPECT_EQ(r.status, 2) << mode << ": " << r.err;
    EXPECT_TRUE(testing::has(r.err, "cull.granularity")) << mode << ": " << r.err;
  }
  const auto r = testing::run_nbsim("replay " + sample("city_small_oq.nbt") +
                                    " --set cull.mode=nb --set cull.granularity=triangle --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(testing::has(r.err, "cull.granularity")) << r.err;
  std::filesystem::remove_all(out.parent_path());
}

}  // namespace
}  // namespace nbsim
