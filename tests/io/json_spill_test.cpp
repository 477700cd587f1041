// SpilledJsonArrayTest: a document written with its array spilled to a temporary file is, byte
// for byte, what nlohmann's dump(2) writes with the array in place, at any depth and for any
// element (objects, nested containers, empty ones, strings with escapes).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <string>

#include "io/json_spill.h"

namespace {

using nlohmann::ordered_json;
using nbsim::io::SpilledJsonArray;

// What write_document() wrote, read back from a temporary file.
std::string written(SpilledJsonArray& a, const ordered_json& doc) {
  std::FILE* f = std::tmpfile();
  a.write_document(f, doc);
  std::fflush(f);
  std::rewind(f);
  std::string s;
  for (int c; (c = std::fgetc(f)) != EOF;) s += static_cast<char>(c);
  std::fclose(f);
  return s;
}

// Elements of every shape dump(2) indents differently.
std::vector<ordered_json> elements() {
  return {ordered_json{{"frame", 0}, {"draws", 12}, {"relief", ordered_json::object()}},
          ordered_json{{"frame", 1}, {"levels", ordered_json::array()}, {"depth", {"after_occluders", "final"}}},
          ordered_json{{"frame", 2}, {"name", "a \"quoted\"\nline\twith\x01 control"}, {"x", 1.5e-7}, {"n", nullptr}},
          ordered_json(42), ordered_json::array({1, ordered_json::array({2, 3}), ordered_json::object({{"k", "v"}})})};
}

// run.json's shape: the array is the top-level object's last member.
TEST(SpilledJsonArrayTest, LastMemberAsDump) {
  ordered_json doc = {{"nbsim_version", "0.1.0"}, {"summary", {{"frames", 5}, {"ok", true}}}};
  SpilledJsonArray a;
  ordered_json whole = doc;
  whole["frames"] = ordered_json::array();
  for (const ordered_json& e : elements()) a.push_back(e), whole["frames"].push_back(e);
  doc["frames"] = SpilledJsonArray::placeholder();
  EXPECT_EQ(written(a, doc), whole.dump(2) + "\n");
  EXPECT_EQ(a.size(), elements().size());
  // Written twice, the same bytes (the file is read back from its start each time).
  EXPECT_EQ(written(a, doc), whole.dump(2) + "\n");
}

// `trace info --json`'s shape: members follow the array; and a deeper array (summary.shadows.per_frame).
TEST(SpilledJsonArrayTest, MiddleAndNestedMembersAsDump) {
  for (int depth = 0; depth < 3; ++depth) {
    SpilledJsonArray a;
    ordered_json arr = ordered_json::array();
    for (const ordered_json& e : elements()) a.push_back(e), arr.push_back(e);
    const auto build = [depth](const ordered_json& value) {
      ordered_json inner = {{"before", 1}, {"frames", value}, {"totals", {{"frames", 5}}}};
      for (int d = 0; d < depth; ++d) inner = ordered_json{{"level", d}, {"inner", inner}, {"after", "x"}};
      return inner;
    };
    EXPECT_EQ(written(a, build(SpilledJsonArray::placeholder())), build(arr).dump(2) + "\n") << "depth " << depth;
  }
}

// No elements: "[]", as dump(2) writes an empty array.
TEST(SpilledJsonArrayTest, EmptyArrayAsDump) {
  SpilledJsonArray a;
  const ordered_json doc = {{"a", 1}, {"frames", SpilledJsonArray::placeholder()}};
  const ordered_json whole = {{"a", 1}, {"frames", ordered_json::array()}};
  EXPECT_EQ(written(a, doc), whole.dump(2) + "\n");
}

// A document without the placeholder is a bug of the caller: it aborts.
TEST(SpilledJsonArrayDeathTest, MissingPlaceholderAborts) {
  SpilledJsonArray a;
  EXPECT_DEATH(written(a, ordered_json{{"a", 1}}), "placeholder");
}

}  // namespace
