// AppsChunkTest: the apps technique's records (traces/format/apps/apps_chunk.h) read back by every
// reader, every flipped byte refused naming the chunk, and each rule beyond the field types.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/traces/format/chunk_builder.h"
#include "traces/format/apps/apps_chunk.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

TechniqueRecord draws_record() {
  TechniqueRecord r;
  r.type = kAppDrawsChunk;
  r.decoded = true;
  const std::vector<std::uint32_t> u{4, 5};
  const std::vector<std::int32_t> i{0, 256};
  r.fields = {{"count", std::uint64_t{2}},
              {"mode", u},
              {"call", std::vector<std::uint32_t>{0, 1}},
              {"skipped", std::vector<std::uint32_t>{0, 1}},
              {"primitive", std::vector<std::uint32_t>{4, 0}},
              {"flags", std::vector<std::uint32_t>{3, 7}},
              {"framebuffer", std::vector<std::uint32_t>{0, 3}},
              {"target_width", std::vector<std::uint32_t>{256, 512}},
              {"target_height", std::vector<std::uint32_t>{256, 512}},
              {"depth_bits", std::vector<std::uint32_t>{24, 32}},
              {"depth_float", std::vector<std::uint32_t>{0, 1}},
              {"polygon_mode", std::vector<std::uint32_t>{0x1B02, 0x1B02}},
              {"viewport_x", i},
              {"viewport_y", i},
              {"viewport_w", i},
              {"viewport_h", i},
              {"scissor_x", i},
              {"scissor_y", i},
              {"scissor_w", i},
              {"scissor_h", i},
              {"depth_near", std::vector<float>{0.0f, 0.1f}},
              {"depth_far", std::vector<float>{1.0f, 0.9f}},
              {"offset_factor", std::vector<float>{0.0f, -1.0f}},
              {"offset_units", std::vector<float>{0.0f, -2.0f}}};
  return r;
}

TechniqueRecord clears_record() {
  TechniqueRecord r;
  r.type = kAppClearsChunk;
  r.decoded = true;
  r.fields = {{"count", std::uint64_t{2}},
              {"before_draw", std::vector<std::uint32_t>{0, 2}},
              {"framebuffer", std::vector<std::uint32_t>{0, 3}},
              {"buffers", std::vector<std::uint32_t>{1, 3}},
              {"flags", std::vector<std::uint32_t>{2, 34}},
              {"stencil_write_mask", std::vector<std::uint32_t>{255, 255}},
              {"scissor_x", std::vector<std::int32_t>{0, 4}},
              {"scissor_y", std::vector<std::int32_t>{0, 4}},
              {"scissor_w", std::vector<std::int32_t>{256, 8}},
              {"scissor_h", std::vector<std::int32_t>{256, 8}},
              {"stencil", std::vector<std::int32_t>{0, 128}},
              {"depth", std::vector<float>{1.0f, 0.0f}}};
  return r;
}

TechniqueRecord change_record() {
  TechniqueRecord r;
  r.type = kAppDepthChangeChunk;
  r.decoded = true;
  r.fields = {{"draw", std::uint64_t{1}},       {"framebuffer", std::uint64_t{3}},
              {"width", std::uint64_t{4}},      {"height", std::uint64_t{2}},
              {"pixel", std::vector<std::uint32_t>{0, 5, 7}}, {"depth", std::vector<float>{0.5f, 0.25f, 1.0f}}};
  return r;
}

TechniqueRecord frame_record() {
  TechniqueRecord r;
  r.type = kAppFrameChunk;
  r.decoded = true;
  r.fields = {{"framebuffer", std::uint64_t{0}}, {"width", std::uint64_t{256}}, {"height", std::uint64_t{256}},
              {"unhandled", std::string("glBegin (immediate mode) x 3")}};
  return r;
}

TEST(AppsChunkTest, DecodedAndDamageRefused) {
  for (TechniqueRecord r : {draws_record(), clears_record(), change_record(), frame_record()}) {
    r.payload = encode(r);
    const char name[5] = {static_cast<char>(r.type), static_cast<char>(r.type >> 8), static_cast<char>(r.type >> 16),
                          static_cast<char>(r.type >> 24), 0};
    SCOPED_TRACE(name);
    expect_reads_back_and_flips_refused(r, name);
  }
}

// Each rule names the broken value.
TEST(AppsChunkTest, RulesNameTheBrokenValue) {
  const auto problem = [](const ChunkSpec& spec, const TechniqueRecord& r) { return spec.rule(r); };
  const auto set = [](TechniqueRecord r, const std::string& name, decltype(TechniqueField::value) v) {
    for (TechniqueField& f : r.fields)
      if (f.name == name) f.value = std::move(v);
    return r;
  };
  EXPECT_EQ(problem(app_draws_chunk_spec(), draws_record()), "");
  EXPECT_EQ(problem(app_clears_chunk_spec(), clears_record()), "");
  EXPECT_EQ(problem(app_depth_change_chunk_spec(), change_record()), "");
  EXPECT_EQ(problem(app_frame_chunk_spec(), frame_record()), "");
  EXPECT_TRUE(has(problem(app_draws_chunk_spec(), set(draws_record(), "skipped", std::vector<std::uint32_t>{0, 7})), "'skipped' of draw 1 is 7"));
  EXPECT_TRUE(has(problem(app_draws_chunk_spec(), set(draws_record(), "mode", std::vector<std::uint32_t>{4})), "field 'mode' has 1 elements"));
  EXPECT_TRUE(has(problem(app_draws_chunk_spec(), set(draws_record(), "depth_far", std::vector<float>{1.0f, std::nanf("")})), "is NaN"));
  EXPECT_TRUE(has(problem(app_clears_chunk_spec(), set(clears_record(), "buffers", std::vector<std::uint32_t>{0, 1})), "'buffers' of clear 0 is 0"));
  EXPECT_TRUE(has(problem(app_clears_chunk_spec(), set(clears_record(), "before_draw", std::vector<std::uint32_t>{3, 2})), "clear 1 runs before draw 2"));
  EXPECT_TRUE(has(problem(app_clears_chunk_spec(), set(clears_record(), "depth", std::vector<float>{1.5f, 0.0f})), "outside [0, 1]"));
  EXPECT_TRUE(has(problem(app_depth_change_chunk_spec(), set(change_record(), "pixel", std::vector<std::uint32_t>{0, 8, 9})), "pixel 8 is outside the 4x2 target"));
  EXPECT_TRUE(has(problem(app_depth_change_chunk_spec(), set(change_record(), "pixel", std::vector<std::uint32_t>{0, 5, 5})), "pixel 5 does not follow pixel 5"));
  EXPECT_TRUE(has(problem(app_depth_change_chunk_spec(), set(change_record(), "depth", std::vector<float>{0.5f})), "3 pixels but 1 depths"));
  EXPECT_TRUE(has(problem(app_frame_chunk_spec(), set(frame_record(), "width", std::uint64_t{20000})), "20000x256"));
}

}  // namespace
