// ConfigSchemaTest: configuration keys, JSON and --set application, and refusals.
#include "model/config/schema.h"

#include <gtest/gtest.h>

#include "model/common/error.h"

namespace nbsim::config {
namespace {

struct Unit {
  int lookup_latency_cycles = 4;
  double bandwidth_bytes_per_cycle = 64.0;
  bool enabled = true;
  std::string policy = "eager";
};

struct Fixture {
  Unit u;
  Schema s;
  Fixture() {
    s.add("nbuffer.lookup_latency_cycles", u.lookup_latency_cycles, "cycles", "latency of one lookup", 0, 1000);
    s.add("memory.bandwidth_bytes_per_cycle", u.bandwidth_bytes_per_cycle, "bytes/cycle", "bandwidth", 0.5, 4096.0);
    s.add("nbuffer.enabled", u.enabled, "unit on");
    s.add("nbuffer.update_policy", u.policy, "when levels are updated", {"eager", "batched", "lazy"});
  }
};

// Nested and flat JSON both set the bound fields.
TEST(ConfigSchemaTest, AppliesNestedAndFlatJson) {
  Fixture f;
  f.s.apply(nlohmann::json::parse(R"({"nbuffer": {"lookup_latency_cycles": 7, "update_policy": "lazy"},
                                      "memory.bandwidth_bytes_per_cycle": 32})"));
  EXPECT_EQ(f.u.lookup_latency_cycles, 7);
  EXPECT_EQ(f.u.policy, "lazy");
  EXPECT_DOUBLE_EQ(f.u.bandwidth_bytes_per_cycle, 32.0);
}

// --set parses the value by the key's type.
TEST(ConfigSchemaTest, SetParsesByType) {
  Fixture f;
  f.s.set("nbuffer.lookup_latency_cycles=12");
  f.s.set("nbuffer.enabled=false");
  f.s.set("nbuffer.update_policy=batched");
  EXPECT_EQ(f.u.lookup_latency_cycles, 12);
  EXPECT_FALSE(f.u.enabled);
  EXPECT_EQ(f.u.policy, "batched");
}

// Unknown keys, wrong types and values outside the limits are refused with the key named.
TEST(ConfigSchemaTest, RefusesBadKeysAndValues) {
  struct Row { std::string assignment, message; };
  const Row rows[] = {
      {"nbuffer.lookup_latency_cycle=3", "did you mean 'nbuffer.lookup_latency_cycles'"},
      {"gpu.nothing=3", "unknown config key 'gpu.nothing'"},
      {"nbuffer.lookup_latency_cycles=2.5", "must be an integer"},
      {"nbuffer.lookup_latency_cycles=-1", "outside its limits"},
      {"memory.bandwidth_bytes_per_cycle=0", "outside its limits"},
      {"nbuffer.enabled=maybe", "not a valid bool"},
      {"nbuffer.update_policy=never", "must be one of eager, batched, lazy"},
      {"novalue", "expected unit.field=value"},
  };
  for (const Row& r : rows) {
    Fixture f;
    try {
      f.s.set(r.assignment);
      ADD_FAILURE() << r.assignment << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(r.message), std::string::npos) << r.assignment << ": " << e.what();
    }
  }
  Fixture f;
  EXPECT_THROW(f.s.apply(nlohmann::json::parse(R"({"nbuffer": {"typo": 1}})")), InputError);
  EXPECT_THROW(f.s.apply(nlohmann::json::parse("[1, 2]")), InputError);
}

// describe() lists every key with the default it had when declared, even after changes.
TEST(ConfigSchemaTest, DescribesDefaults) {
  Fixture f;
  f.s.set("nbuffer.lookup_latency_cycles=9");
  const auto d = f.s.describe();
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[0]["key"], "nbuffer.lookup_latency_cycles");
  EXPECT_EQ(d[0]["default"], 4);
  EXPECT_EQ(d[0]["unit"], "cycles");
  EXPECT_EQ(f.s.values()["nbuffer"]["lookup_latency_cycles"], 9);
}

}  // namespace
}  // namespace nbsim::config
