// SweepTest: sweep files of `nbsim explore` without running anything: the cartesian product and
// listed points, stable ids, type normalization through the config schema, and refused files.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/config/schema.h"
#include "pipeline/explore/results.h"
#include "pipeline/explore/sweep.h"

namespace {

using nbsim::InputError;
using nbsim::explore::Point;
using nlohmann::json;
using ojson = nlohmann::ordered_json;  // sweep files keep their key order
namespace ex = nbsim::explore;

// A small stand-in for GpuConfig: three keys of the three kinds, checked by the real Schema.
json toy_check(const json& settings, const std::string& origin, ex::CheckScope scope = ex::CheckScope::Whole) {
  struct {
    std::string mode = "trace";
    int divisor = 1;
    double bandwidth = 32.0;
    int tile = 8;
  } c;
  nbsim::config::Schema s;
  s.add("cull.mode", c.mode, "culling mode", {"trace", "nb", "nb_hier", "oq"});
  s.add("nbuffer.resolution_divisor", c.divisor, "", "divisor", 1, 8);
  s.add("memory.bandwidth_bytes_per_cycle", c.bandwidth, "bytes/cycle", "bandwidth", 0.01, 1e6);
  s.add("hiz.tile_px", c.tile, "pixels", "tile", 1, 256);
  s.apply(settings, origin);
  // A rule between two keys (a unit's consistency rule): checked on whole configs only.
  if (scope == ex::CheckScope::Whole && c.tile > 64 && c.divisor == 1)
    throw InputError(origin + ": hiz.tile_px above 64 needs nbuffer.resolution_divisor 2 or more");
  json flat = json::object();
  const nlohmann::ordered_json values = s.values();  // kept alive for the loop
  for (const auto& [unit, fields] : values.items())
    for (const auto& [field, v] : fields.items()) flat[unit + "." + field] = v;
  return flat;
}

std::vector<Point> expand_checked(const ojson& j) {
  const ex::SweepSpec spec = ex::parse_sweep(j, "sweep.json");
  std::vector<Point> points = ex::expand(spec);
  ex::check_points(spec, points, toy_check, "sweep.json");
  return points;
}

std::string error_of(const ojson& j) {
  try {
    expand_checked(j);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// Axes give every combination per trace, the last axis fastest, with "set" in every point.
TEST(SweepTest, CartesianProductInFileOrder) {
  const ojson j = ojson::parse(R"({"traces": ["a.nbt", "b.nbt"], "set": {"memory.bandwidth_bytes_per_cycle": 16},
    "axes": {"cull.mode": ["nb", "nb_hier"], "nbuffer.resolution_divisor": [1, 2, 4]}})");
  const auto points = expand_checked(j);
  ASSERT_EQ(points.size(), 12u) << "2 traces x 2 modes x 3 divisors";
  EXPECT_EQ(points[0].trace, "a.nbt");
  EXPECT_EQ(points[6].trace, "b.nbt") << "trace-major order";
  EXPECT_EQ(points[1].settings["nbuffer.resolution_divisor"], 2) << "the last axis varies fastest";
  EXPECT_EQ(points[3].settings["cull.mode"], "nb_hier");
  EXPECT_EQ(points[3].settings["nbuffer.resolution_divisor"], 1);
  for (const auto& p : points) {
    EXPECT_EQ(p.settings["memory.bandwidth_bytes_per_cycle"], 16.0) << "set applies to every point";
    EXPECT_EQ(p.settings.size(), 3u);
  }
  const auto keys = ex::parameter_keys(ex::parse_sweep(j, "s"));
  EXPECT_EQ(keys, (std::vector<std::string>{"memory.bandwidth_bytes_per_cycle", "cull.mode", "nbuffer.resolution_divisor"}));
}

// Listed points run on every trace unless one names its trace; parameters are filled with defaults.
TEST(SweepTest, ListedPoints) {
  const auto points = expand_checked(ojson::parse(R"({"traces": ["a.nbt", "b.nbt"], "points": [
    {"cull.mode": "nb"}, {"cull": {"mode": "nb_hier"}, "nbuffer.resolution_divisor": 2, "trace": "b.nbt"}]})"));
  ASSERT_EQ(points.size(), 3u) << "point 0 on both traces, point 1 on b.nbt only";
  EXPECT_EQ(points[0].trace, "a.nbt");
  EXPECT_EQ(points[1].trace, "b.nbt");
  EXPECT_EQ(points[2].trace, "b.nbt");
  EXPECT_EQ(points[2].settings, json::parse(R"({"cull.mode": "nb_hier", "nbuffer.resolution_divisor": 2})")) << "nested keys flatten";
  EXPECT_EQ(points[0].parameters["nbuffer.resolution_divisor"], 1) << "a key another point sets gets its default";
  EXPECT_FALSE(points[0].settings.contains("nbuffer.resolution_divisor")) << "defaults are not settings: the id stays put";
}

// Ids depend on the trace and the settings only, not on their order in the file, and are fixed.
TEST(SweepTest, StableIds) {
  const auto a = expand_checked(ojson::parse(R"({"traces": ["t.nbt"], "points": [{"cull.mode": "nb", "nbuffer.resolution_divisor": 2}]})"));
  const auto b = expand_checked(ojson::parse(R"({"traces": ["t.nbt"], "points": [{"nbuffer.resolution_divisor": 2, "cull.mode": "nb"}]})"));
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].id, b[0].id) << "key order must not change the id";
  EXPECT_EQ(a[0].id.size(), 16u);
  EXPECT_EQ(a[0].id, ex::point_id("t.nbt", json::parse(R"({"cull.mode": "nb", "nbuffer.resolution_divisor": 2})")));
  EXPECT_NE(a[0].id, ex::point_id("u.nbt", a[0].settings)) << "the trace is part of the id";
  // Golden value: changing it makes every existing sweep folder run again.
  EXPECT_EQ(ex::point_id("traces/samples/city_small_oq.nbt", json::object()), "2fd8ffe3aeac73ec") << "FNV-1a 64 of the trace, a line break and the sorted settings";
}

// Reference points: the culling reference of every mode is nb_hier on the full-resolution N-buffer,
// found among the sweep's points by effective config or added once; the trace mode has none; keys the
// config lacks (here the timing knobs) are left out.
TEST(SweepTest, ReferencePoints) {
  const ojson j = ojson::parse(R"({"traces": ["t.nbt"], "points": [
    {"cull.mode": "nb"}, {"cull.mode": "nb", "nbuffer.resolution_divisor": 4}, {"cull.mode": "nb", "nbuffer.resolution_divisor": 2},
    {"cull.mode": "oq"}, {"cull.mode": "oq", "nbuffer.resolution_divisor": 8}, {}, {"cull.mode": "oq", "hiz.tile_px": 4}]})");
  const ex::SweepSpec spec = ex::parse_sweep(j, "s");
  std::vector<Point> points = ex::expand(spec);
  ex::check_points(spec, points, toy_check, "s");
  for (Point& p : points) p.technique = "occlusion_culling";
  ex::add_reference_points(points, ex::parameter_keys(spec), toy_check, "s");
  ASSERT_EQ(points.size(), 8u) << "one reference added: nb_hier at full resolution";
  const Point& added = points[7];
  for (int i = 0; i < 3; ++i) EXPECT_EQ(points[i].technique_reference, added.id) << "point " << i << ": the flat nb query is measured too";
  EXPECT_EQ(points[6].technique_reference, added.id) << "Hi-Z keys go back to their defaults: one reference";
  EXPECT_EQ(added.role, "reference");
  EXPECT_EQ(added.settings, json::parse(R"({"cull.mode": "nb_hier"})")) << "only what differs is set";
  EXPECT_EQ(added.parameters["nbuffer.resolution_divisor"], 1);
  EXPECT_EQ(added.technique_reference, added.id);
  EXPECT_EQ(points[3].technique_reference, added.id);
  EXPECT_EQ(points[4].technique_reference, added.id) << "the divisor goes back to 1 as well";
  EXPECT_TRUE(points[5].technique_reference.empty()) << "the trace mode culls nothing";
  for (const Point& p : points) {
    EXPECT_EQ(p.timing_reference, p.id) << "no timing key in this config: every point is its own";
    EXPECT_EQ(p.role, &p == &added ? "reference" : "sweep");
    EXPECT_EQ(p.technique, "occlusion_culling") << "a reference point keeps its trace's technique";
  }
}

// A trace whose technique declares no results (or names none) has no technique reference: no point
// is added for it, and the generic timing reference still applies.
TEST(SweepTest, NoTechniqueReferenceWithoutADeclaration) {
  const ojson j = ojson::parse(R"({"traces": ["t.nbt"], "points": [{"cull.mode": "nb"}, {"cull.mode": "oq"}]})");
  const ex::SweepSpec spec = ex::parse_sweep(j, "s");
  for (const char* technique : {"", "particles_not_declared"}) {
    std::vector<Point> points = ex::expand(spec);
    ex::check_points(spec, points, toy_check, "s");
    for (Point& p : points) p.technique = technique;
    ex::add_reference_points(points, ex::parameter_keys(spec), toy_check, "s");
    ASSERT_EQ(points.size(), 2u) << "technique '" << technique << "': no reference point";
    for (const Point& p : points) {
      EXPECT_TRUE(p.technique_reference.empty()) << technique;
      EXPECT_EQ(p.timing_reference, p.id);
    }
  }
}

// A float key given as an integer is the same point as the float: the schema's typed value counts.
TEST(SweepTest, ValuesNormalizedBySchema) {
  const auto a = expand_checked(ojson::parse(R"({"traces": ["t.nbt"], "axes": {"memory.bandwidth_bytes_per_cycle": [2]}})"));
  const auto b = expand_checked(ojson::parse(R"({"traces": ["t.nbt"], "axes": {"memory.bandwidth_bytes_per_cycle": [2.0]}})"));
  EXPECT_EQ(a[0].id, b[0].id);
  EXPECT_TRUE(a[0].settings["memory.bandwidth_bytes_per_cycle"].is_number_float());
}

// Refused sweep files: each message names what is wrong (one row per rule).
TEST(SweepTest, RefusedFiles) {
  struct Case {
    const char* sweep;
    const char* message;
    const char* why;
  };
  const Case cases[] = {
      {R"([1])", "a sweep is a JSON object", "not an object"},
      {R"({"axes": {"cull.mode": ["nb"]}})", "traces must be a non-empty list", "no traces"},
      {R"({"traces": ["t"], "axes": {"cull.mode": ["nb"]}, "points": [{}]})", "exactly one of axes", "both forms"},
      {R"({"traces": ["t"]})", "exactly one of axes", "neither form"},
      {R"({"traces": ["t"], "axes": {"cull.mode": []}})", "axes.cull.mode must be a non-empty list", "empty axis"},
      {R"({"traces": ["t"], "axes": {"cull.mode": [["nb"]]}})", "is not a single value", "nested value"},
      {R"({"traces": ["t"], "axis": {}})", "unknown sweep entry 'axis'", "typo at the top"},
      {R"({"traces": ["t"], "points": [{"trace": "u"}]})", "trace 'u' is not one of traces", "unlisted trace"},
      {R"({"traces": ["t", "t"], "points": [{}]})", "listed twice", "same trace twice"},
      {R"({"traces": ["t"], "set": {"cull.mode": "nb"}, "axes": {"cull.mode": ["nb"]}})", "both in set and in axes", "key twice"},
      {R"({"traces": ["t"], "axes": {"cull.mdoe": ["nb"]}})", "unknown config key 'cull.mdoe'; did you mean 'cull.mode'", "unknown key"},
      {R"({"traces": ["t"], "axes": {"nbuffer.resolution_divisor": [1, 9]}})", "axes.nbuffer.resolution_divisor[1]", "value out of limits"},
      {R"({"traces": ["t"], "axes": {"cull.mode": ["nb", "xx"]}})", "cull.mode must be one of", "bad enum"},
      {R"({"traces": ["t"], "points": [{"cull.mode": "nb"}, {"cull.mode": "nb"}]})", "listed twice", "duplicate point"},
      {R"({"traces": ["t"], "axes": {"memory.bandwidth_bytes_per_cycle": [2, 2.0]}})", "listed twice", "same after normalization"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(ojson::parse(c.sweep));
    EXPECT_NE(e.find(c.message), std::string::npos) << c.why << ": got '" << e << "'";
    EXPECT_EQ(e.rfind("sweep.json", 0), 0u) << c.why << ": the message starts with the file: " << e;
  }
}

// A sweep of 1,000 x 1,000 (or 1,000^3, whose count overflows nothing) is refused by counting,
// before any point is built; the limit is a parameter (explore's --max-points).
TEST(SweepTest, PointCountLimited) {
  ojson big = ojson::parse(R"({"traces": ["a", "b"], "axes": {}})");
  for (const char* key : {"nbuffer.resolution_divisor", "memory.bandwidth_bytes_per_cycle", "hiz.tile_px"}) {
    big["axes"][key] = ojson::array();
    for (int i = 0; i < 1000; ++i) big["axes"][key].push_back(i);
  }
  try {
    ex::parse_sweep(big, "sweep.json");
    ADD_FAILURE() << "2 x 1000^3 points were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("2 traces x 1000 x 1000 x 1000 = 2000000000 points, more than the limit of 10000"),
              std::string::npos)
        << e.what();
  }
  const ojson small = ojson::parse(R"({"traces": ["a"], "axes": {"hiz.tile_px": [1, 2, 4], "nbuffer.resolution_divisor": [1, 2]}})");
  EXPECT_NO_THROW(ex::parse_sweep(small, "sweep.json", 6)) << "exactly at the limit";
  EXPECT_THROW(ex::parse_sweep(small, "sweep.json", 5), InputError) << "one over the limit";
  ojson listed = ojson::parse(R"({"traces": ["a", "b"], "points": [{"hiz.tile_px": 1}, {"hiz.tile_px": 2, "trace": "a"}]})");
  EXPECT_NO_THROW(ex::parse_sweep(listed, "sweep.json", 3)) << "2 traces for the first point, 1 for the second";
  EXPECT_THROW(ex::parse_sweep(listed, "sweep.json", 2), InputError);
}

// A value repeated in one axis is refused where it is met, naming the value and its place,
// before the rest of a long axis is read.
TEST(SweepTest, RepeatedAxisValueRefusedWhereMet) {
  ojson j = ojson::parse(R"({"traces": ["a"], "axes": {"hiz.tile_px": [8, 16, 8]}})");
  for (int i = 0; i < 5000; ++i) j["axes"]["hiz.tile_px"].push_back(8);
  try {
    ex::parse_sweep(j, "sweep.json");
    ADD_FAILURE() << "a repeated axis value was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("axes.hiz.tile_px: 8 is listed twice (at [2] again)"), std::string::npos) << e.what();
  }
}

// CSV fields with commas, quotes or line breaks are quoted; others are left alone.
TEST(SweepTest, CsvFieldQuoting) {
  EXPECT_EQ(ex::csv_field("nb_hier"), "nb_hier");
  EXPECT_EQ(ex::csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(ex::csv_field("say \"x\""), "\"say \"\"x\"\"\"");
  EXPECT_EQ(ex::csv_field("two\nlines"), "\"two\nlines\"");
}

// A value that is fine on its own but breaks a rule with the default of another key (a tracking
// tile beside the default eager policy, say) does not refuse the sweep: only the points whose
// combination breaks the rule are refused, by name.
TEST(SweepTest, ValueNeedingAnotherKeyRefusesOnlyItsPoints) {
  const auto points = expand_checked(ojson::parse(
      R"({"traces": ["t.nbt"], "axes": {"hiz.tile_px": [8, 128], "nbuffer.resolution_divisor": [1, 2]}})"));
  ASSERT_EQ(points.size(), 4u);
  int refused = 0;
  for (const auto& p : points) {
    const bool bad = p.settings["hiz.tile_px"] == 128 && p.settings["nbuffer.resolution_divisor"] == 1;
    EXPECT_EQ(!p.refused.empty(), bad) << p.settings.dump();
    if (bad) EXPECT_NE(p.refused.find("hiz.tile_px above 64 needs nbuffer.resolution_divisor"), std::string::npos) << p.refused;
    refused += !p.refused.empty();
  }
  EXPECT_EQ(refused, 1);
  // The same value where no point of the sweep can build it: the sweep is refused, naming it.
  const std::string e = error_of(ojson::parse(R"({"traces": ["t.nbt"], "axes": {"hiz.tile_px": [8, 128]}})"));
  EXPECT_NE(e.find("axes.hiz.tile_px[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("hiz.tile_px above 64 needs nbuffer.resolution_divisor"), std::string::npos) << e;
}

}  // namespace
