// LdiChunkTest: the LDI technique's LDIL and LDIT records (traces/format/ldi/ldi_chunk.h) read back by every
// reader, and every damage to it refused naming the chunk.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "tests/traces/format/chunk_builder.h"
#include "traces/format/ldi/ldi_chunk.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

// The LDI technique's LDIL and LDIT records (traces/format/ldi/ldi_chunk.h) are decoded by every reader;
// each flipped byte, a payload one byte short or long and each broken rule (sizes that disagree,
// a crop outside the LDI, a direction outside the grid, answers and kinds out of range) are refused
// naming the chunk.
TEST(LdiChunkTest, DecodedAndDamageRefused) {
  struct Image {
    std::uint32_t width = 4, height = 3, layers = 2, grid_h = 2, grid_v = 2, direction = 3, side = 3;
    std::vector<float> layer_values = std::vector<float>(2 * 4 * 3, 0.5f);
    std::vector<float> view = std::vector<float>(9, 0.0f);
    std::vector<std::uint32_t> candidate_d{2, 4, 2, 2};
    std::int32_t crop_x = 1, crop_y = 0, crop_w = 3, crop_h = 3;
    std::vector<std::uint32_t> compressed = std::vector<std::uint32_t>(2 * 3 * 3, 0u);
  };
  auto image = [](const Image& f) {
    bytes::Out o;
    o.u32(f.width), o.u32(f.height), o.u32(f.layers), o.u32(f.grid_h), o.u32(f.grid_v), o.u32(f.direction);
    o.counted_words(f.view);
    o.counted_words(std::vector<float>(9, 1.0f));  // rotation
    o.counted_words(f.candidate_d);
    o.counted_words(std::vector<std::uint32_t>{10, 12, 9, 12});  // candidate_coverage
    o.counted_words(f.layer_values);
    o.i32(f.crop_x), o.i32(f.crop_y), o.i32(f.crop_w), o.i32(f.crop_h);
    o.u32(f.side), o.u32(9), o.u32(0);  // comp_side, comp_index, comp_ranges
    o.counted_words(f.compressed);
    return o.take();
  };
  struct Tests {
    std::vector<std::uint32_t> kind{0, 1, 2}, inside{1, 0, 1};
    std::vector<std::int32_t> reference{1, 0, -1};
    double epsilon = 1e-5;
  };
  auto tests = [](const Tests& f) {
    bytes::Out o;
    o.u32(3);
    o.f64(f.epsilon);
    o.counted_words(f.kind);
    o.counted_words(std::vector<std::int32_t>{0, 3, 2});  // x
    o.counted_words(std::vector<std::int32_t>{1, 2, 0});  // y
    o.counted_words(std::vector<float>{0.25f, 0.5f, 1.0f});  // z
    o.counted_words(f.inside);
    o.counted_words(std::vector<std::uint32_t>{2, 0, 1});  // gl_fetches_layers
    o.counted_words(f.inside);
    o.counted_words(std::vector<std::uint32_t>{2, 0, 2});  // gl_fetches_ranges
    o.counted_words(f.reference);
    return o.take();
  };
  for (const std::uint32_t type : {kLdiImageChunk, kLdiTestsChunk}) {
    const std::string name = type == kLdiImageChunk ? "LDIL" : "LDIT";
    TechniqueRecord raw;
    raw.type = type;
    raw.payload = type == kLdiImageChunk ? image(Image{}) : tests(Tests{});
    const TechniqueRecord r = decode_technique(type, raw.payload);
    ASSERT_TRUE(r.decoded) << "the format library registers " << name;
    EXPECT_EQ(encode(r), raw.payload) << name << " encodes back to the same bytes";
    expect_reads_back_and_flips_refused(r, name);
  }
  std::vector<std::uint8_t> shorter = image(Image{});
  shorter.pop_back();
  EXPECT_TRUE(has(record_error(kLdiImageChunk, shorter), "decodes short"));
  std::vector<std::uint8_t> longer = tests(Tests{});
  longer.push_back(0);
  EXPECT_TRUE(has(record_error(kLdiTestsChunk, longer), "decodes long"));
  struct BrokenImage {
    Image f;
    std::string message;
  };
  BrokenImage images[] = {{Image{}, "field 'layers' has 23 values, but layer_count x width x height is 24"},
                          {Image{}, "the crop (1, 0, 4x3) is not inside the 4x3 LDI"},
                          {Image{}, "direction is 4, but the grid has 4 directions"},
                          {Image{}, "field 'candidate_d' has 3 values, but the grid has 4 directions"},
                          {Image{}, "field 'compressed' has 17 values, but comp_side 3 needs 18"},
                          {Image{}, "field 'view' has 8 values, not 9"},
                          {Image{}, "the LDI is 0x3 texels"},
                          {Image{}, "the viewpoint grid is 0x2"}};
  images[0].f.layer_values.pop_back();
  images[1].f.crop_w = 4;
  images[2].f.direction = 4;
  images[3].f.candidate_d.pop_back();
  images[4].f.compressed.pop_back();
  images[5].f.view.pop_back();
  images[6].f.width = 0, images[6].f.layer_values.clear();
  images[7].f.grid_h = 0;
  for (const BrokenImage& b : images) {
    const std::string e = record_error(kLdiImageChunk, image(b.f));
    EXPECT_TRUE(has(e, "chunk 2 (LDIL)") && has(e, b.message)) << b.message << ": " << e;
  }
  struct BrokenTests {
    Tests f;
    std::string message;
  };
  BrokenTests rows[] = {{Tests{}, "field 'kind' has 2 elements, but count is 3"},
                        {Tests{}, "field 'kind' of test point 1 is 4, above 3"},
                        {Tests{}, "field 'gl_inside_layers' of test point 0 is 2, above 1"},
                        {Tests{}, "field 'reference' of test point 2 is -2, below -1"},
                        {Tests{}, "epsilon is nan"}};
  rows[0].f.kind = {0, 1};
  rows[1].f.kind = {0, 4, 2};
  rows[2].f.inside = {2, 0, 1};
  rows[3].f.reference = {1, 0, -2};
  rows[4].f.epsilon = std::nan("");
  for (const BrokenTests& b : rows) {
    const std::string e = record_error(kLdiTestsChunk, tests(b.f));
    EXPECT_TRUE(has(e, "chunk 2 (LDIT)") && has(e, b.message)) << b.message << ": " << e;
  }
}

}  // namespace
