// NBufferUnitConfigTest: the N-buffer unit's and the Hi-Z baselines' config keys (defaults, units,
// --set) and their refusals of bad keys and values, each with a message naming the key.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "model/common/error.h"
#include "model/hiz/hiz_config.h"
#include "model/nbuffer/unit_core.h"

namespace nbsim::nbuffer {
namespace {

// Every field is a key "nbuffer.<field>" with its default, unit and limits.
TEST(NBufferUnitConfigTest, DescribesEveryKeyWithDefaults) {
  NBufferUnitConfig c;
  config::Schema s;
  NBufferUnitConfig::describe(s, c);
  const auto d = s.describe();
  ASSERT_EQ(d.size(), 22u);
  auto find = [&](const std::string& key) {
    for (const auto& e : d)
      if (e["key"] == key) return e;
    ADD_FAILURE() << key << " not declared";
    return nlohmann::ordered_json{};
  };
  EXPECT_EQ(find("nbuffer.resolution_divisor")["default"], 1);
  EXPECT_EQ(find("nbuffer.format")["default"], "f32");
  EXPECT_EQ(find("nbuffer.level_cap")["default"], -1);
  EXPECT_EQ(find("nbuffer.covering")["default"], "trace");
  EXPECT_EQ(find("nbuffer.align")["default"], "trace");
  EXPECT_EQ(find("nbuffer.levels")["default"], "square");
  EXPECT_EQ(find("nbuffer.max_aspect_log2")["default"], -1);
  EXPECT_EQ(find("nbuffer.update_policy")["default"], "eager");
  EXPECT_EQ(find("nbuffer.invalidations_per_cycle")["default"], 64.0);
  EXPECT_EQ(find("nbuffer.fast_clear")["default"], false);
  EXPECT_EQ(find("nbuffer.level0")["default"], "copy");
  EXPECT_EQ(find("nbuffer.dirty_tile")["default"], 1);
  EXPECT_EQ(find("nbuffer.demand_levels")["default"], false);
  EXPECT_EQ(find("nbuffer.demand_margin")["default"], 0);
  EXPECT_EQ(find("nbuffer.lookup_latency_cycles")["unit"], "cycles");
  EXPECT_EQ(find("nbuffer.lookups_per_cycle")["default"], 4.0);
  EXPECT_EQ(find("nbuffer.cache_size_bytes")["default"], 16384);
  EXPECT_EQ(find("nbuffer.cache_line_bytes")["default"], 256);
  EXPECT_EQ(find("nbuffer.cache_ways")["default"], 4);
  for (const auto& e : d) EXPECT_FALSE(e["description"].get<std::string>().empty()) << e["key"];
  EXPECT_NO_THROW(c.validate()) << "the defaults are valid";
}

// --set and JSON reach the bound fields, and the validated values parse.
TEST(NBufferUnitConfigTest, SetReachesTheFields) {
  NBufferUnitConfig c;
  config::Schema s;
  NBufferUnitConfig::describe(s, c);
  s.set("nbuffer.update_policy=lazy");
  s.set("nbuffer.format=u16");
  s.set("nbuffer.lookup_latency_cycles=20");
  s.apply(nlohmann::json::parse(R"({"nbuffer": {"resolution_divisor": 4, "cache_ways": 8}})"));
  c.validate();
  EXPECT_EQ(c.policy(), UpdatePolicy::Lazy);
  EXPECT_EQ(c.storage_format(), StorageFormat::U16);
  EXPECT_EQ(c.lookup_latency_cycles, 20);
  EXPECT_EQ(c.resolution_divisor, 4);
  EXPECT_EQ(c.cache.ways, 8);
}

// Bad keys and values set through the schema are refused with the key named.
TEST(NBufferUnitConfigTest, SchemaRefusesBadKeysAndValues) {
  struct Row {
    std::string assignment, message;
  };
  const Row rows[] = {
      {"nbuffer.lookup_latency_cycle=3", "did you mean 'nbuffer.lookup_latency_cycles'"},
      {"nbuffer.update_policy=sometimes", "must be one of eager, batched, lazy"},
      {"nbuffer.format=f16", "must be one of f32, u24, u16"},
      {"nbuffer.resolution_divisor=16", "outside its limits"},
      {"nbuffer.level_cap=-2", "outside its limits"},
      {"nbuffer.lookups_per_cycle=0", "outside its limits"},
      {"nbuffer.cache_ways=0", "outside its limits"},
      {"nbuffer.update_latency_cycles=1.5", "must be an integer"},
  };
  for (const Row& row : rows) {
    NBufferUnitConfig c;
    config::Schema s;
    NBufferUnitConfig::describe(s, c);
    try {
      s.set(row.assignment);
      ADD_FAILURE() << row.assignment << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(row.message), std::string::npos) << row.assignment << ": " << e.what();
    }
  }
}

// Values inside the schema's limits but inconsistent are refused by validate(), with the key named.
TEST(NBufferUnitConfigTest, ValidateRefusesInconsistentValues) {
  struct Row {
    void (*edit)(NBufferUnitConfig&);
    std::string message;
  };
  const Row rows[] = {
      {[](NBufferUnitConfig& c) { c.resolution_divisor = 3; },
       "nbuffer.resolution_divisor must be 1, 2, 4 or 8, got 3"},
      {[](NBufferUnitConfig& c) { c.cache.line_bytes = 96; }, "nbuffer.cache_line_bytes must be a power of two"},
      {[](NBufferUnitConfig& c) { c.cache.size_bytes = 1000; }, "nbuffer.cache_size_bytes must be 0 or a multiple"},
      {[](NBufferUnitConfig& c) { c.format = "f64"; }, "nbuffer.format must be one of f32, u24, u16, got 'f64'"},
      {[](NBufferUnitConfig& c) { c.update_policy = "never"; }, "nbuffer.update_policy must be one of"},
      {[](NBufferUnitConfig& c) { c.lookups_per_cycle = -1.0; }, "nbuffer.lookups_per_cycle must be"},
      {[](NBufferUnitConfig& c) { c.update_texels_per_cycle = std::numeric_limits<double>::infinity(); },
       "nbuffer.update_texels_per_cycle must be"},
      {[](NBufferUnitConfig& c) { c.lookup_latency_cycles = -1; }, "nbuffer.lookup_latency_cycles must be"},
      {[](NBufferUnitConfig& c) { c.capped_max_lookups = -1; }, "nbuffer.capped_max_lookups must be"},
      {[](NBufferUnitConfig& c) { c.covering = "four"; }, "nbuffer.covering must be one of trace, paper, corners, one, got 'four'"},
      {[](NBufferUnitConfig& c) { c.align = "left"; }, "nbuffer.align must be one of trace, top, bottom, got 'left'"},
      {[](NBufferUnitConfig& c) { c.levels = "ripmap"; }, "nbuffer.levels must be square or rect, got 'ripmap'"},
      {[](NBufferUnitConfig& c) { c.levels = "rect", c.max_aspect_log2 = 0; }, "nbuffer.max_aspect_log2 must be -1"},
      {[](NBufferUnitConfig& c) { c.levels = "rect", c.level_cap = 3; },
       "nbuffer.levels=rect builds every level: nbuffer.level_cap must be -1, got 3"},
      {[](NBufferUnitConfig& c) { c.levels = "rect", c.update_policy = "on_demand"; },
       "nbuffer.update_policy=on_demand computes square levels only"},
      {[](NBufferUnitConfig& c) { c.level0 = "depth", c.resolution_divisor = 4; }, "nbuffer.level0=depth reads the depth buffer"},
      {[](NBufferUnitConfig& c) { c.level0 = "depth", c.format = "u16"; }, "nbuffer.level0=depth reads the depth buffer"},
      {[](NBufferUnitConfig& c) { c.level0 = "texture"; }, "nbuffer.level0 must be copy or depth"},
      {[](NBufferUnitConfig& c) { c.dirty_tile = 3, c.update_policy = "lazy"; }, "nbuffer.dirty_tile must be a power of two"},
      {[](NBufferUnitConfig& c) { c.dirty_tile = 128, c.update_policy = "lazy"; }, "nbuffer.dirty_tile must be a power of two"},
      {[](NBufferUnitConfig& c) { c.dirty_tile = 8; }, "nbuffer.dirty_tile=8 tracks pending changes"},
      {[](NBufferUnitConfig& c) { c.demand_levels = true, c.update_policy = "on_demand"; }, "nbuffer.demand_levels has nothing to cap"},
      {[](NBufferUnitConfig& c) { c.demand_levels = true, c.levels = "rect"; }, "nbuffer.levels=rect builds every level"},
      {[](NBufferUnitConfig& c) { c.demand_margin = -1; }, "nbuffer.demand_margin must be 0 to"},
      {[](NBufferUnitConfig& c) { c.invalidations_per_cycle = 0.0; }, "nbuffer.invalidations_per_cycle must be"},
  };
  for (const Row& row : rows) {
    NBufferUnitConfig c;
    row.edit(c);
    try {
      c.validate();
      ADD_FAILURE() << "accepted: expected '" << row.message << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(row.message), std::string::npos) << e.what();
    }
    stats::Registry reg;
    EXPECT_THROW(NBufferUnitCore(c, 8, 8, FarOp::Max, reg.group("u")), InputError) << "the core validates its config";
  }
}

// A disabled cache (size 0) is valid: every lookup misses.
TEST(NBufferUnitConfigTest, ZeroCacheMissesEveryLookup) {
  NBufferUnitConfig c;
  c.cache.size_bytes = 0;
  stats::Registry reg;
  NBufferUnitCore core(c, 32, 32, FarOp::Max, reg.group("u"));
  core.query({0, 0, 9, 9}, 0.5f);
  const QueryAnswer a = core.query({0, 0, 9, 9}, 0.5f);
  EXPECT_EQ(a.cache_misses, static_cast<std::uint64_t>(a.lookups));
}

// Two instances of one unit (a min and a max N-buffer) have their own keys, and each names its own
// keys in messages (pipeline/sim/programs.h: the instance's name is its prefix).
TEST(NBufferUnitConfigTest, InstancesHaveTheirOwnKeys) {
  NBufferUnitConfig min_levels, max_levels;
  config::Schema s;
  NBufferUnitConfig::describe(s, min_levels, "litmap_min");
  NBufferUnitConfig::describe(s, max_levels, "litmap_max");
  s.set("litmap_min.format=u16");
  s.set("litmap_max.resolution_divisor=4");
  EXPECT_EQ(min_levels.format, "u16");
  EXPECT_EQ(max_levels.format, "f32") << "one instance's key reached the other";
  EXPECT_EQ(max_levels.resolution_divisor, 4);
  EXPECT_EQ(min_levels.resolution_divisor, 1);
  EXPECT_THROW(s.set("nbuffer.format=u16"), InputError) << "no instance is named nbuffer here";
  max_levels.update_policy = "sometimes";
  try {
    max_levels.validate();
    ADD_FAILURE() << "update_policy 'sometimes' accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("litmap_max.update_policy must be"), std::string::npos) << e.what();
  }
}

// The Hi-Z keys: defaults, --set, and refusals.
TEST(NBufferUnitConfigTest, HiZKeys) {
  HiZUnitConfig c;
  config::Schema s;
  HiZUnitConfig::describe(s, c);
  EXPECT_EQ(s.size(), 6u) << "tile_px, format and four timing keys";
  EXPECT_EQ(s.values()["hiz"]["tile_px"], 8);
  EXPECT_EQ(s.values()["hiz"]["lookup_latency_cycles"], 8);
  EXPECT_EQ(s.values()["hiz"]["format"], "f32");
  s.set("hiz.tile_px=16");
  s.set("hiz.format=u24");
  c.validate();
  EXPECT_EQ(c.tile(FarOp::Min).tile_px, 16);
  EXPECT_EQ(c.tile(FarOp::Min).op, FarOp::Min);
  EXPECT_EQ(c.pyramid(FarOp::Max).format, StorageFormat::U24);
  EXPECT_THROW(s.set("hiz.tile_px=0"), InputError);
  EXPECT_THROW(s.set("hiz.tiles_px=4"), InputError);
  // The Hi-Z timing keys belong to the Hi-Z unit: their cull-stage spellings are refused naming it.
  try {
    s.set("cull.hiz_lookups_per_cycle=2");
    ADD_FAILURE() << "the old key cull.hiz_lookups_per_cycle was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is now 'hiz.lookups_per_cycle'"), std::string::npos) << e.what();
  }
  s.set("hiz.lookups_per_cycle=2");
  EXPECT_EQ(c.lookups_per_cycle, 2.0);
  c.format = "f16";
  try {
    c.validate();
    ADD_FAILURE() << "hiz.format f16 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hiz.format must be one of f32, u24, u16"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim::nbuffer
