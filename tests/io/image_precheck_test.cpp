// ImagePrecheckTest: io/image_precheck.h on TIFF files built byte by byte: every layout a
// writer produces is accepted, and every declared strip, tile, value array or buffer that does not
// fit the file or the limits is refused with a reason naming the field (fuzz_depth_image found a
// TIFF whose strip lay past the end of the file: it was read as zeros, after a 2.98 GB buffer).
#include <gtest/gtest.h>

#include <fstream>
#include <tuple>
#include <string>

#include "io/image_precheck.h"
#include "tests/common/scratch.h"
#include "tests/io/tiff_builder.h"

namespace {

using nbsim::testing::TiffBuilder;
constexpr long long kSide = 16384, kPixels = 4096LL * 4096LL;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string check(const TiffBuilder& t) {
  const auto path = nbsim::testing::scratch_path("nbsim_precheck", "t.tif");
  const auto b = t.bytes();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  const nbsim::io::ImagePrecheck p = nbsim::io::precheck_depth_file(path.string(), kSide, kPixels);
  EXPECT_EQ(p.format, "tif");
  return p.refusal;
}

// A w x h float image, 0.5 everywhere.
TiffBuilder image(int w, int h) { return TiffBuilder(w, h, std::vector<float>(static_cast<std::size_t>(w * h), 0.5f)); }

// Layouts writers produce: one strip, a strip a row, a last strip shorter than the others,
// RowsPerStrip larger than the image (a few rows more, or 2^32 - 1, "one strip"), tiles (the
// edge tiles hanging over the image), big-endian files and BigTIFF.
TEST(ImagePrecheckTest, AcceptsWhatWritersWrite) {
  EXPECT_EQ(check(image(4, 3)), "");
  EXPECT_EQ(check(image(4, 3).set(278, TiffBuilder::kShort, {1}).strips({{0, 16}, {16, 16}, {32, 16}})), "");
  EXPECT_EQ(check(image(4, 3).set(278, TiffBuilder::kLong, {2}).strips({{0, 32}, {32, 16}})), "");
  EXPECT_EQ(check(image(4, 3).set(278, TiffBuilder::kLong, {8})), "");
  EXPECT_EQ(check(image(4, 3).set(278, TiffBuilder::kLong, {0xFFFFFFFFu})), "");
  EXPECT_EQ(check(image(4, 3).erase(278)), "") << "RowsPerStrip absent: one strip";
  // 20x20 in 16x16 tiles: four tiles, each stored whole (16 * 16 * 4 bytes).
  TiffBuilder tiled(20, 20, std::vector<float>(4 * 256, 0.5f));
  tiled.erase(278).set(322, TiffBuilder::kShort, {16}).set(323, TiffBuilder::kShort, {16});
  tiled.strips({{0, 1024}, {1024, 1024}, {2048, 1024}, {3072, 1024}}, true);
  EXPECT_EQ(check(tiled), "");
  EXPECT_EQ(check(image(4, 3).big_endian()), "");
  EXPECT_EQ(check(image(4, 3).bigtiff()), "");
  EXPECT_EQ(check(image(4, 3).bigtiff().big_endian().strips({{0, 48}})), "");
  EXPECT_EQ(check(image(4, 3).set(259, TiffBuilder::kShort, {8}).strips({{0, 7}})), "")
      << "a compressed strip may be shorter than its pixels (the decoder says if it is damaged)";
}

// The finding: 4 rows declared with 63008 rows a strip, 11825 pixels wide (OpenImageIO's read
// buffer would be 63008 rows), and its one strip past the end of the file.
TEST(ImagePrecheckTest, RefusesRowsPerStripThatWouldCostAHugeBuffer) {
  TiffBuilder t(11825, 4, {});
  t.set(278, TiffBuilder::kShort, {63008}).set(339, TiffBuilder::kShort, {1}).strips({{0, 39}});
  const std::string e = check(t);
  EXPECT_TRUE(has(e, "RowsPerStrip 63008 for an image of 4 rows") && has(e, "2842 MiB, above the 256 MiB limit")) << e;
  // The long runs' finding: no BitsPerSample (1 bit a sample): the file packs a row in 1,479 bytes
  // but OpenImageIO holds each sample in a byte, 63008 rows of 11825 bytes (710 MiB).
  TiffBuilder one_bit(11825, 4, {});
  one_bit.erase(258).erase(339).set(278, TiffBuilder::kShort, {63008}).strips({{0, 39}});
  const std::string e1 = check(one_bit);
  EXPECT_TRUE(has(e1, "a buffer of 63008 rows of 11825 bytes (710 MiB, above the 256 MiB limit)")) << e1;
  // The same strip with 4 rows a strip: the strip past the end is what is refused.
  t.set(278, TiffBuilder::kShort, {4});
  const std::string e2 = check(t);
  EXPECT_TRUE(has(e2, "is a damaged TIFF: strip 0 declares 39 bytes at offset") && has(e2, "past the end of the")) << e2;
}

// One row per case: what is broken, and the words the refusal must hold.
TEST(ImagePrecheckTest, RefusesLayoutsThatDoNotFitTheFile) {
  const struct {
    const char* why;
    TiffBuilder tiff;
    const char* expect;
  } rows[] = {
      {"strip past the end", image(4, 3).strips({{1000, 48}}), "strip 0 declares 48 bytes at offset"},
      {"strip count past the end", image(4, 3).strips({{0, 4800}}), "strip 0 declares 4800 bytes"},
      {"uncompressed strip short of its rows", image(4, 3).strips({{0, 40}}),
       "uncompressed strip 0 holds 40 bytes (StripByteCounts 0), fewer than the 48 bytes of its 3 rows"},
      {"last strip short", image(4, 3).set(278, TiffBuilder::kShort, {2}).strips({{0, 32}, {32, 8}}),
       "uncompressed strip 1 holds 8 bytes (StripByteCounts 1), fewer than the 16 bytes of its 1 row"},
      {"too few strips", image(4, 3).set(278, TiffBuilder::kShort, {1}).strips({{0, 16}, {16, 16}}),
       "its 4x3 image needs 3 strips, and it declares 2 StripOffsets and 2 StripByteCounts"},
      {"no StripByteCounts", image(4, 3).erase(279), "needs 1 strip, and it declares 1 StripOffsets and 0 StripByteCounts"},
      {"no StripOffsets", image(4, 3).erase(273), "declares 0 StripOffsets and 1 StripByteCounts"},
      {"values past the end", image(4, 3).raw_entry(273, TiffBuilder::kLong, 3, 5000),
       "StripOffsets at byte 70 declares 3 values of 4 bytes at offset 5000, past the end"},
      {"value count past the end", image(4, 3).raw_entry(305, TiffBuilder::kLong, 0x40000000u, 8),
       "tag 305 at byte 130 declares 1073741824 values of 4 bytes"},
      {"first directory past the end", image(4, 3).first_directory_at(100000), "first directory's offset 100000 is outside"},
      {"entries past the end", image(4, 3).entry_count(5000), "declares 5000 entries, past the end"},
      {"no width", image(4, 3).erase(256), "has no ImageWidth"},
      {"no length", image(4, 3).erase(257), "has no ImageLength"},
      {"too wide", image(20000, 1).strips({{0, 80000}}), "declares 20000x1 pixels, above the depth image limit"},
      {"zero rows a strip", image(4, 3).set(278, TiffBuilder::kShort, {0}), "declares 0 RowsPerStrip"},
      {"no bits", image(4, 3).set(258, TiffBuilder::kShort, {0}), "declares 0 bits a sample"},
      {"too many bits", image(4, 3).set(258, TiffBuilder::kShort, {65}), "declares 65 bits a sample"},
      {"big-endian strip past the end", image(4, 3).big_endian().strips({{1000, 48}}), "strip 0 declares 48 bytes"},
      {"BigTIFF strip past the end", image(4, 3).bigtiff().strips({{1000, 48}}), "strip 0 declares 48 bytes"},
  };
  for (const auto& row : rows) {
    const std::string e = check(row.tiff);
    EXPECT_TRUE(has(e, row.expect)) << row.why << ": " << e;
  }
}

TEST(ImagePrecheckTest, RefusesTilesThatDoNotFit) {
  const auto tiled = [](std::uint64_t tw, std::uint64_t tl) {
    TiffBuilder t(20, 20, std::vector<float>(4 * 256, 0.5f));
    t.erase(278).set(322, TiffBuilder::kLong, {tw}).set(323, TiffBuilder::kLong, {tl});
    t.strips({{0, 1024}, {1024, 1024}, {2048, 1024}, {3072, 1024}}, true);
    return t;
  };
  EXPECT_EQ(check(tiled(16, 16)), "");
  std::string e = check(tiled(16, 16).strips({{0, 1024}, {1024, 1024}, {2048, 1024}, {9000, 1024}}, true));
  EXPECT_TRUE(has(e, "tile 3 declares 1024 bytes at offset") && has(e, "(TileOffsets 3, TileByteCounts 3)")) << e;
  e = check(tiled(16, 16).strips({{0, 1024}, {1024, 1024}, {2048, 1024}, {3072, 1000}}, true));
  EXPECT_TRUE(has(e, "uncompressed tile 3 holds 1000 bytes (TileByteCounts 3), fewer than the 1024 bytes")) << e;
  e = check(tiled(16, 8));
  EXPECT_TRUE(has(e, "needs 6 tiles, and it declares 4 TileOffsets and 4 TileByteCounts")) << e;
  e = check(tiled(0, 16));
  EXPECT_TRUE(has(e, "without a TileWidth and a TileLength of at least 1")) << e;
  e = check(tiled(65536, 16));
  EXPECT_TRUE(has(e, "tiles of 65536x16 pixels, above the depth image limit")) << e;
}

// An OpenEXR header written byte by byte: the required attributes of a 4x3 scanline image, then
// `extra` ones (name, type, declared size, value bytes), the header's end and no pixels (the
// precheck reads the headers only).
std::string check_exr(const std::vector<std::tuple<std::string, std::string, std::int32_t, std::vector<std::uint8_t>>>& extra) {
  std::vector<std::uint8_t> b = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
  const auto put_i32 = [&b](std::int32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> (8 * i)));
  };
  const auto attribute = [&](const std::string& name, const std::string& type, std::int32_t size, const std::vector<std::uint8_t>& value) {
    b.insert(b.end(), name.begin(), name.end()), b.push_back(0);
    b.insert(b.end(), type.begin(), type.end()), b.push_back(0);
    put_i32(size);
    b.insert(b.end(), value.begin(), value.end());
  };
  std::vector<std::uint8_t> box = {0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 2, 0, 0, 0};
  attribute("channels", "chlist", 19, {'Z', 0, 2, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0});
  attribute("compression", "compression", 1, {0});
  attribute("dataWindow", "box2i", 16, box);
  attribute("displayWindow", "box2i", 16, box);
  attribute("lineOrder", "lineOrder", 1, {0});
  for (const auto& [name, type, size, value] : extra) attribute(name, type, size, value);
  b.push_back(0);
  const auto path = nbsim::testing::scratch_path("nbsim_precheck", "t.exr");
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  const nbsim::io::ImagePrecheck p = nbsim::io::precheck_depth_file(path.string(), kSide, kPixels);
  EXPECT_EQ(p.format, "exr");
  return p.refusal;
}

// OpenEXR reads a fixed-size type's value at its own size whatever the declared one, so a size that
// differs would make the next attribute be read from inside this one (fuzz_depth_image in CI: a v2f
// of 0 bytes, then a 1.9 GB "attribute"); and it allocates a preview's pixels and a string
// vector's strings as they declare them.
TEST(ImagePrecheckTest, OpenExrAttributeValuesHoldWhatTheirTypesDeclare) {
  using Attr = std::tuple<std::string, std::string, std::int32_t, std::vector<std::uint8_t>>;
  EXPECT_EQ(check_exr({}), "");
  EXPECT_EQ(check_exr({Attr{"screenWindowCenter", "v2f", 8, std::vector<std::uint8_t>(8, 0)}}), "");
  std::string e = check_exr({Attr{"screenWindowCenter", "v2f", 0, {}}});
  EXPECT_TRUE(has(e, "attribute 'screenWindowCenter'") && has(e, "of type v2f declares 0 bytes, and a v2f holds 8")) << e;
  e = check_exr({Attr{"pixelAspectRatio", "float", 8, std::vector<std::uint8_t>(8, 0)}});
  EXPECT_TRUE(has(e, "of type float declares 8 bytes, and a float holds 4")) << e;
  // A 2x1 preview: 8 + 2 * 1 * 4 bytes.
  EXPECT_EQ(check_exr({Attr{"preview", "preview", 16, {2, 0, 0, 0, 1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8}}}), "");
  e = check_exr({Attr{"preview", "preview", 16, {0xff, 0xff, 0, 0, 0xff, 0xff, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8}}});
  EXPECT_TRUE(has(e, "preview attribute 'preview'") && has(e, "do not hold its 65535x65535 pixels")) << e;
  // A string vector of "ab" and "": (4 + 2) + 4 bytes.
  EXPECT_EQ(check_exr({Attr{"names", "stringvector", 10, {2, 0, 0, 0, 'a', 'b', 0, 0, 0, 0}}}), "");
  e = check_exr({Attr{"names", "stringvector", 10, {2, 0, 0, 0, 'a', 'b', 0, 0, 0, 0x70}}});
  EXPECT_TRUE(has(e, "string vector attribute 'names'") && has(e, "holds a string that does not fit its 10 bytes")) << e;
}

// OpenEXR reads a channel list by its structure (a name and 16 bytes a channel, until an empty
// name), not by its declared size (fuzz_depth_image in CI: a list whose end byte was not 0 ran on
// into the next attributes, then OpenEXR allocated a 1.85 GB "attribute" from inside one).
TEST(ImagePrecheckTest, OpenExrChannelListEndsAtItsDeclaredSize) {
  using Attr = std::tuple<std::string, std::string, std::int32_t, std::vector<std::uint8_t>>;
  const std::vector<std::uint8_t> channel = {'Y', 0, 2, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  std::vector<std::uint8_t> two = channel;
  two.insert(two.end(), channel.begin(), channel.end());
  two[18] = 'Z';
  two.push_back(0);
  EXPECT_EQ(check_exr({Attr{"extra", "chlist", 37, two}}), "") << "two channels and the end";
  std::vector<std::uint8_t> unended = channel;
  unended.push_back('C');  // no empty name: the list would run on
  std::string e = check_exr({Attr{"extra", "chlist", 19, unended}});
  EXPECT_TRUE(has(e, "channel list attribute 'extra'") && has(e, "declares 19 bytes, and its channel 1 does not end inside them"))
      << e;
  std::vector<std::uint8_t> early = channel;
  early.push_back(0);
  early.push_back(0);  // the list ends one byte before its size
  e = check_exr({Attr{"extra", "chlist", 20, early}});
  EXPECT_TRUE(has(e, "declares 20 bytes, and its 1 channels and end take 19")) << e;
  e = check_exr({Attr{"extra", "chlist", 0, {}}});
  EXPECT_TRUE(has(e, "declares 0 bytes, and its channel 0 does not end inside them")) << e;
}

}  // namespace
