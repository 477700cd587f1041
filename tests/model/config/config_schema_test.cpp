// ConfigSchemaTest: configuration keys, JSON and --set application, and refusals.
#include "model/config/schema.h"

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>

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

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// A wrong value nested 10,000 deep is refused with a short message (the echo is cut, not dumped whole).
TEST(ConfigSchemaTest, DeepValueEchoedBriefly) {
  // 2,000 levels: a message that dumps the value would echo all 4,000 brackets (and deeper values
  // would crash the dump). Moved, never copied: nlohmann's copy recurses, and under ASan's larger
  // frames a copy of 10,000 levels overflows the test's own stack.
  nlohmann::json deep = 1;
  for (int i = 0; i < 2000; ++i) deep = nlohmann::json::array({std::move(deep)});
  nlohmann::json config = nlohmann::json::object();
  config["nbuffer.lookup_latency_cycles"] = std::move(deep);
  Fixture f;
  const std::string e = error_of([&] { f.s.apply(config); });
  EXPECT_NE(e.find("must be an integer, got [[[["), std::string::npos) << e;
  EXPECT_LT(e.size(), 300u) << "the value is echoed as a short excerpt";
}

// --set with a deeply nested value is refused by the nesting limit before anything walks it.
TEST(ConfigSchemaTest, SetRefusesDeepValue) {
  Fixture f;
  const std::string e = error_of([&] { f.s.set("nbuffer.lookup_latency_cycles=" + std::string(100000, '[') + std::string(100000, ']')); });
  EXPECT_NE(e.find("deeper than 64 levels"), std::string::npos) << e.substr(0, 300);
  EXPECT_LT(e.size(), 300u);
}

// --set with bytes that are not UTF-8 is refused as the user's error (not a JSON library exception).
TEST(ConfigSchemaTest, SetRefusesNonUtf8) {
  for (const char* a : {"nbuffer.update_policy=\xff", "nbuffer.lookup_latency_cycles=\"\xfe\"", "nbuffer.\xc0=1"}) {
    Fixture f;
    const std::string e = error_of([&] { f.s.set(a); });
    EXPECT_NE(e.find("not valid UTF-8"), std::string::npos) << e;
  }
}

// A 20 MB unknown key is refused at once, echoed as a short excerpt, with no quadratic "did you mean" search.
TEST(ConfigSchemaTest, HugeKeyRefusedQuickly) {
  Fixture f;
  const std::string key = "nbuffer." + std::string(20 << 20, 'k');
  const auto start = std::chrono::steady_clock::now();
  const std::string e = error_of([&] { f.s.apply({{key, 1}}); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(e.find("unknown config key 'nbuffer.kkk"), std::string::npos) << e.substr(0, 300);
  EXPECT_LT(e.size(), 400u) << "the key is echoed as a short excerpt";
  EXPECT_LT(seconds, 2.0) << "the hint search must not be quadratic in the key's length";
  EXPECT_NE(error_of([&] { f.s.set("nbuffer.lookup_latency_cyclesX=1"); }).find("did you mean 'nbuffer.lookup_latency_cycles'"),
            std::string::npos)
      << "close keys still get a hint";
}

}  // namespace
}  // namespace nbsim::config
