// JsonInputTest: user-given JSON parsed within its limits (nesting depth, repeated keys, NUL
// bytes, UTF-8) and echoed into messages only as bounded excerpts.
#include "model/config/json_input.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "model/common/error.h"
#include "tests/common/scratch.h"

namespace nbsim::config {
namespace {

namespace fs = std::filesystem;

std::string nested(int depth, const std::string& inner = "1") {
  return std::string(static_cast<std::size_t>(depth), '[') + inner + std::string(static_cast<std::size_t>(depth), ']');
}

std::string error_of(const std::string& text) {
  try {
    parse_input(text, "input");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Nesting up to the limit parses; one level more is refused, and 200,000 levels are refused
// quickly without exhausting the stack.
TEST(JsonInputTest, NestingDepthLimited) {
  EXPECT_NO_THROW(parse_input(nested(kMaxJsonDepth), "input")) << "the limit itself is allowed";
  EXPECT_TRUE(has(error_of(nested(kMaxJsonDepth + 1)), "deeper than 64 levels")) << error_of(nested(kMaxJsonDepth + 1));
  EXPECT_TRUE(has(error_of(nested(200000)), "deeper than 64 levels"));
  EXPECT_TRUE(has(error_of(R"({"a": {"b": )" + nested(100) + "}}"), "deeper than")) << "objects count as levels too";
  EXPECT_THROW(parse_input_ordered(nested(200000), "input"), InputError) << "the ordered form has the same limit";
}

// A key given twice in one object is refused with the key named; the same key in two objects is fine.
TEST(JsonInputTest, RepeatedKeyRefused) {
  const std::string e = error_of(R"({"gpu": {"quantum_cycles": 1, "quantum_cycles": 2}})");
  EXPECT_TRUE(has(e, "gives the key \"quantum_cycles\" twice")) << e;
  EXPECT_NO_THROW(parse_input(R"({"a": {"k": 1}, "b": {"k": 1}, "c": [{"k": 1}, {"k": 2}]})", "input"));
  EXPECT_TRUE(has(error_of(R"({"a": 1, "b": {"x": 1}, "a": 2})"), "key \"a\" twice")) << "checked after a nested object closes";
}

// An embedded NUL byte is refused (the JSON library would stop reading there and accept the rest).
TEST(JsonInputTest, NulByteRefused) {
  const std::string text = std::string(R"({"a": 1})") + '\0' + "garbage";
  EXPECT_TRUE(has(error_of(text), "NUL byte at offset 8")) << error_of(text);
}

// Text that is not UTF-8 is refused as not valid JSON; the parser's message is cut.
TEST(JsonInputTest, NotUtf8OrNotJsonRefusedBriefly) {
  EXPECT_TRUE(has(error_of("{\"a\": \"\xff\"}"), "is not valid JSON")) << error_of("{\"a\": \"\xff\"}");
  const std::string e = error_of("{\"a\": \"" + std::string(100000, 'x') + "\xff\"}");
  EXPECT_TRUE(has(e, "is not valid JSON")) << e;
  EXPECT_LT(e.size(), 400u) << "a message, not the input";
}

// A number out of the double range is refused as an InputError, not the library's out_of_range
// (found by fuzz_sweep: the sweep file "444E2222ce").
TEST(JsonInputTest, NumberOutOfRangeRefused) {
  EXPECT_TRUE(has(error_of("444E2222ce"), "is not valid JSON")) << error_of("444E2222ce");
  EXPECT_TRUE(has(error_of(R"({"nbuffer": {"level_cap": 1E999}})"), "is not valid JSON"));
  EXPECT_THROW(parse_input_ordered("-1e400", "input"), nbsim::InputError);
}

// UTF-8 validation: well-formed sequences pass; bad bytes, overlongs, surrogates and cut sequences fail at their offset.
TEST(JsonInputTest, Utf8Validation) {
  std::size_t at = 0;
  EXPECT_TRUE(valid_utf8("plain ascii, caf\xc3\xa9, \xe2\x82\xac, \xf0\x9f\x98\x80"));
  struct Row { std::string text; std::size_t bad; const char* why; };
  const Row rows[] = {{"ab\xff", 2, "0xFF is never UTF-8"},
                      {"\xc0\xaf", 0, "overlong two-byte form"},
                      {"x\xed\xa0\x80", 1, "UTF-16 surrogate"},
                      {"xy\xe2\x82", 2, "sequence cut at the end"},
                      {"\xf4\x90\x80\x80", 0, "above U+10FFFF"}};
  for (const Row& r : rows) {
    EXPECT_FALSE(valid_utf8(r.text, &at)) << r.why;
    EXPECT_EQ(at, r.bad) << r.why;
  }
}

// Excerpts stay short for huge, deep and non-UTF-8 values.
TEST(JsonInputTest, ExcerptsBounded) {
  nlohmann::json deep = 1;
  for (int i = 0; i < 10000; ++i) deep = nlohmann::json::array({std::move(deep)});
  EXPECT_LE(excerpt(deep).size(), kMaxEchoChars + 3) << "a value nested 10,000 deep";
  EXPECT_LE(excerpt(nlohmann::json(std::string(1 << 20, 'k'))).size(), kMaxEchoChars + 3);
  EXPECT_EQ(excerpt(nlohmann::json("\xff")), "\"\xef\xbf\xbd\"") << "bytes that are not UTF-8 become U+FFFD, no exception";
  EXPECT_EQ(excerpt(nlohmann::json{{"a", 1}}), "{\"a\":1}");
  const std::string cut = excerpt_text(std::string(1000, 'x'));
  EXPECT_TRUE(has(cut, "... (1000 bytes)")) << cut;
  EXPECT_EQ(excerpt_text("short"), "short");
}

// Reading a file: a directory and a missing file are named as such, a whole file is read past NUL bytes.
TEST(JsonInputTest, ReadsWholeFilesOnly) {
  const fs::path dir = nbsim::testing::scratch_dir("nbsim_json_input");
  try {
    read_input_file(dir.string(), "config file");
    ADD_FAILURE() << "a directory was read";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "is a directory")) << e.what();
  }
  EXPECT_THROW(read_input_file((dir / "missing.json").string(), "config file"), InputError);
  const std::string bytes = std::string("{}") + '\0' + "tail";
  std::ofstream(dir / "nul.json", std::ios::binary) << bytes;
  EXPECT_EQ(read_input_file((dir / "nul.json").string(), "config file"), bytes) << "read whole, past the NUL";
  fs::remove_all(dir);
}

// A file or device larger than the limit is refused after reading just past the limit, not read to its end.
TEST(JsonInputTest, FileSizeLimited) {
  try {
    read_input_file("/dev/zero", "config file");
    ADD_FAILURE() << "an endless device was read";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "is larger than 64 MiB (the limit)")) << e.what();
  }
}

}  // namespace
}  // namespace nbsim::config
