// TraceHeaderTest: the HEAD properties are parsed into the typed header once, when a trace is
// opened; a malformed value is refused naming the file, chunk 0 (HEAD), the property and its value.
#include <gtest/gtest.h>

#include "model/common/error.h"
#include "traces/format/technique_chunks.h"
#include "tests/traces/format/sample_trace.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;
using nbsim::InputError;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string open_error(const Properties& props) {
  try {
    TraceReader t(header_only(props), "h.nbtrace");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A capture's header reads into typed fields; unknown keys stay as written.
TEST(TraceHeaderTest, TypedFields) {
  const Properties props = {{"viewport", "640x480"},   {"depth_format", "DEPTH_COMPONENT32F"},
                            {"depth_func", "GREATER"}, {"clip_control", "ZERO_TO_ONE"},
                            {"depth_clear", "0"},      {"technique", "occlusion_culling"},
                            {"test_mode", "nb_hier"},  {"scene", "city"},
                            {"path", "fly"},           {"seed", "18446744073709551615"},
                            {"objects", "6000"},       {"frames", "10"},
                            {"levels_every", "0"},     {"fov_y_deg", "60"},
                            {"near", "0.5"},           {"far", "4000"},
                            {"nearest_margin", "1e-06"}, {"my.key", "kept as it is"}};
  const TraceReader t(header_only(props), "h");
  const Header& h = t.header();
  ASSERT_TRUE(h.viewport);
  EXPECT_EQ(h.viewport->width, 640);
  EXPECT_EQ(h.viewport->height, 480);
  EXPECT_EQ(h.depth_format, "DEPTH_COMPONENT32F");
  EXPECT_EQ(h.depth_func, DepthFunc::Greater);
  EXPECT_EQ(h.far_op(), nbsim::FarOp::Min) << "GREATER is reversed Z";
  EXPECT_EQ(h.clip_control, ClipControl::ZeroToOne);
  EXPECT_EQ(h.depth_clear, 0.0f);
  EXPECT_EQ(h.technique, "occlusion_culling");
  EXPECT_EQ(h.text("test_mode"), "nb_hier");  // occlusion culling's key, checked as it declares it
  EXPECT_EQ(h.scene, "city");
  EXPECT_EQ(h.path, "fly");
  EXPECT_EQ(h.seed, 18446744073709551615ull);
  EXPECT_EQ(h.objects, 6000u);
  EXPECT_EQ(h.frames, 10u);
  EXPECT_EQ(h.levels_every, 0u);
  EXPECT_EQ(h.fov_y_deg, 60.0);
  EXPECT_EQ(h.near_m, 0.5);
  EXPECT_EQ(h.far_m, 4000.0);
  EXPECT_EQ(h.nearest_margin, 1e-6);
  ASSERT_NE(t.property("my.key"), nullptr);
  EXPECT_EQ(*t.property("my.key"), "kept as it is");
  EXPECT_EQ(h.properties, props) << "every property kept in order";
}

// Absent keys keep the defaults a capture without them meant (LESS, clear 1, no viewport).
TEST(TraceHeaderTest, Defaults) {
  const TraceReader t(header_only({}), "h");
  const Header& h = t.header();
  EXPECT_FALSE(h.viewport);
  EXPECT_EQ(h.depth_func, DepthFunc::Less);
  EXPECT_EQ(h.far_op(), nbsim::FarOp::Max);
  EXPECT_EQ(h.clip_control, ClipControl::NegativeOneToOne);
  EXPECT_EQ(h.depth_clear, 1.0f);
  EXPECT_FALSE(h.frames);
}

// The header spells depth funcs and clip controls as GL does, from the model's one name table per
// enum (upper case): every value round-trips, and the refusal lists every spelling.
TEST(TraceHeaderTest, GlNamesComeFromTheModelsTables) {
  for (int i = 0; i <= static_cast<int>(DepthFunc::Always); ++i) {
    const auto f = static_cast<DepthFunc>(i);
    const Header h = parse_header({{"depth_func", gl_name(f)}});
    EXPECT_EQ(h.depth_func, f) << gl_name(f);
    try {
      parse_header({{"depth_func", "SOMETIMES"}});
      ADD_FAILURE() << "depth_func SOMETIMES accepted";
    } catch (const nbsim::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(gl_name(f)), std::string::npos) << "the refusal does not list " << gl_name(f);
    }
  }
  EXPECT_EQ(gl_name(DepthFunc::Lequal), "LEQUAL");
  for (const auto c : {ClipControl::NegativeOneToOne, ClipControl::ZeroToOne})
    EXPECT_EQ(parse_header({{"clip_control", gl_name(c)}}).clip_control, c) << gl_name(c);
  EXPECT_EQ(gl_name(ClipControl::ZeroToOne), "ZERO_TO_ONE");
}

// Malformed values are refused with the property, its value and what it must be.
TEST(TraceHeaderTest, RefusesMalformedValues) {
  struct Row {
    const char* key;
    const char* value;
    const char* expected;
  };
  const Row rows[] = {
      {"viewport", "128x96x", "WIDTHxHEIGHT"},       // trailing text
      {"viewport", "0x5", "each 1 .. 16384"},        // a side of 0
      {"viewport", "128", "WIDTHxHEIGHT"},           // no height
      {"viewport", "-4x4", "each 1 .. 16384"},       // negative side
      {"viewport", "20000x4", "each 1 .. 16384"},    // above the image limit
      {"viewport", " 8x8", "WIDTHxHEIGHT"},          // spaces
      {"depth_func", "less", "one of NEVER, LESS"},  // GL names are upper case
      {"clip_control", "ZERO", "NEGATIVE_ONE_TO_ONE, ZERO_TO_ONE"},
      {"depth_format", "RGBA8", "DEPTH_COMPONENT32F"},
      {"depth_clear", "2", "a depth in 0 .. 1"},
      {"depth_clear", "nan", "a depth in 0 .. 1"},
      {"seed", "-1", "a whole number"},
      {"frames", "10 frames", "a whole number"},
      {"objects", "", "a whole number"},
      {"near", "0", "a distance above 0"},
      {"near", "inf", "a distance above 0"},
      {"fov_y_deg", "180", "above 0 and below 180"},
      {"nearest_margin", "-1e-6", "0 .. 1"},
      {"nbuffer_covering", "four", "paper, corners or one, '/', top or bottom"},   // nbsim's old covering name
      {"nbuffer_covering", "paper/left", "paper, corners or one, '/', top or bottom"},
  };
  for (const Row& row : rows) {
    const std::string e = open_error({{"scene", "city"}, {row.key, row.value}});
    EXPECT_TRUE(has(e, std::string("header property '") + row.key + "' is '" + row.value + "': expected")) << e;
    EXPECT_TRUE(has(e, row.expected)) << "expected '" << row.expected << "' in: " << e;
    EXPECT_TRUE(has(e, "h.nbtrace: chunk 0 (HEAD) at byte 16:")) << "names the file, chunk and offset: " << e;
  }
  const std::string e = open_error({{"near", "10"}, {"far", "5"}});
  EXPECT_TRUE(has(e, "header property 'far' is '5'") && has(e, "above near (10)")) << e;
}

// A technique's declared keys are checked when a trace of that technique is opened, with the same
// refusal as the core keys; a trace of another technique (or none) keeps them as free text.
TEST(TraceHeaderTest, TechniqueKeysCheckedForTheirTechnique) {
  struct Row {
    const char* technique;
    const char* key;
    const char* value;
    const char* expected;
  };
  const Row rows[] = {
      {"occlusion_culling", "test_mode", "hier", "one of oq, oq_hier, nb, nb_hier, none"},
      {"particles", "particle_mode", "zbuffer", "one of none, center, nb, hiz"},
      {"particles", "levels_built", "32", "a whole number, 0 .. 31"},
      {"particles", "levels_built", "-1", "a whole number, 0 .. 31"},
      {"particles", "sprite", "0", "a side in pixels, 1 .. 4096, or atten"},
      {"particles", "cull_margin", "0.5", "a number, 0 .. 0.01"},
      {"shadows", "litmap_size", "0", "a whole number, 1 .. 16384"},
      {"shadows", "clamp_margin", "0.01 + 0.1", "'<relative> + <metres> m'"},
      {"shadows", "light_fov_deg", "0", "a number above 0, at most 180"},
      {"ldi", "grid", "8x", "HxV, each 1 .. 1024"},
      {"ldi", "max_layers", "0", "a whole number, 1 .. 2048"},
      {"relief", "relief_box_height", "0", "a number above 0"},
      {"relief", "relief_box_height", "nan", "a number above 0"},
      {"relief", "relief_methods", "binary,,exact", "comma-separated: binary, exact"},
      {"relief", "relief_angles", "0,180", "0 to below 180"},
      {"relief", "relief_placement", "beside", "one of own, city"},
  };
  for (const Row& row : rows) {
    const std::string e = open_error({{"technique", row.technique}, {row.key, row.value}});
    EXPECT_TRUE(has(e, std::string("header property '") + row.key + "' is '" + row.value + "': expected")) << e;
    EXPECT_TRUE(has(e, row.expected)) << "expected '" << row.expected << "' in: " << e;
    EXPECT_TRUE(has(e, "h.nbtrace: chunk 0 (HEAD)")) << e;
    const char* other = std::string(row.technique) == "particles" ? "relief" : "particles";
    EXPECT_EQ(open_error({{"technique", other}, {row.key, row.value}}), "")
        << row.key << " is " << row.technique << "'s: another technique keeps it as text";
    EXPECT_EQ(open_error({{row.key, row.value}}), "") << row.key << ": a trace without a technique keeps it as text";
  }
  // Order does not matter: the technique may come after its keys.
  EXPECT_NE(open_error({{"litmap_size", "0"}, {"technique", "shadows"}}), "");
  // Every declared key's own example is valid.
  for (const HeaderKeySpec& k : technique_header_keys())
    EXPECT_EQ(open_error({{"technique", k.technique}, {k.name, k.example}}), "") << k.technique << " " << k.name;
}

// The typed reads a replay makes: a whole number, a number, the text; an absent key is refused
// naming the technique and the key.
TEST(TraceHeaderTest, TypedReadsOfTechniqueKeys) {
  const Header h = parse_header({{"technique", "particles"}, {"levels_built", "5"}, {"cull_margin", "1e-06"},
                                 {"sprite", "atten"}, {"my.count", "twelve"}});
  EXPECT_EQ(h.whole("levels_built"), 5u);
  EXPECT_DOUBLE_EQ(h.real("cull_margin"), 1e-6);
  EXPECT_EQ(h.text("sprite"), "atten");
  try {
    (void)h.whole("level_cap");
    ADD_FAILURE() << "an absent key read as a number";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "the particles trace's header has no 'level_cap' property");
  }
  EXPECT_THROW((void)h.whole("my.count"), InputError) << "an undeclared key that is not a number";
  EXPECT_THROW((void)h.real("sprite"), InputError);
}

// FORMAT.md's HEAD keys list every technique's keys with the technique's name.
TEST(TraceHeaderTest, KeysTableListsTechniqueKeys) {
  const std::string table = header_keys_table();
  ASSERT_FALSE(technique_header_keys().empty());
  for (const HeaderKeySpec& k : technique_header_keys())
    EXPECT_TRUE(has(table, "| " + k.technique + " | `" + k.name + "` | " + k.values + " |")) << k.name;
}

}  // namespace
