// NBufferCliTest: `nbsim nbuffer query|build|coverage` from the outside: exit statuses, messages
// and outputs, including every refused input (exit 2 with a message naming the problem).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include "io/image_io.h"
#include "tests/common/run_nbsim.h"
#include "tests/io/tiff_builder.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return nbsim::testing::scratch_path("nbsim_cli", name);
}

using nbsim::testing::CliResult;
using nbsim::testing::has;

CliResult nbsim(const std::string& args) { return nbsim::testing::run_nbsim(args); }

// A 4x4 depth image, y up, whose farthest pixel is (3, 0) at 0.9.
fs::path small_depth(const std::string& name) {
  nbsim::DepthImage img(4, 4, 0.25f);
  img.at(3, 0) = 0.9f;
  img.at(0, 3) = 0.5f;
  const fs::path f = scratch(name);
  nbsim::io::write_depth(img, f);
  return f;
}

fs::path depth_with(float bad, int x, int y, const std::string& name) {
  nbsim::DepthImage img(8, 6, 0.5f);
  img.at(x, y) = bad;
  const fs::path f = scratch(name);
  nbsim::io::write_depth(img, f);
  return f;
}


// --help works on every nbuffer subcommand and exits 0.
TEST(NBufferCliTest, HelpExitsZero) {
  for (const char* sub : {"", "nbuffer", "nbuffer query", "nbuffer build", "nbuffer coverage", "nbuffer memory", "info"}) {
    const CliResult r = nbsim(std::string(sub) + " --help");
    EXPECT_EQ(r.status, 0) << sub << ": " << r.err;
    EXPECT_TRUE(has(r.out, "Usage")) << sub << ": " << r.out;
  }
}

// A query prints one JSON line per rectangle with the farthest depth and the texels read.
TEST(NBufferCliTest, QueryPrintsOneJsonLinePerRect) {
  const fs::path f = small_depth("q.exr");
  const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,4,4 --rect 0,1,2,3 --rect 3,0,1,1");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::vector<nlohmann::json> js;
  while (std::getline(lines, line)) js.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(js.size(), 3u) << r.out;
  EXPECT_EQ(js[0]["rect"], nlohmann::json({0, 0, 4, 4}));
  EXPECT_FLOAT_EQ(js[0]["value"].get<float>(), 0.9f) << "the far pixel (3,0) is inside the whole image";
  EXPECT_EQ(js[0]["level"], 1) << "a 4x4 image has levels 0 and 1; four level-1 squares cover it";
  EXPECT_EQ(js[0]["texels"], nlohmann::json({{0, 0}, {2, 0}, {0, 2}, {2, 2}}));
  EXPECT_FLOAT_EQ(js[1]["value"].get<float>(), 0.5f) << "rows 1..3 of columns 0..1 hold 0.5 at (0,3)";
  EXPECT_FLOAT_EQ(js[2]["value"].get<float>(), 0.9f);
  EXPECT_EQ(js[2]["texels"], nlohmann::json({{3, 0}}));
}

// Min op (reversed Z) and quantized formats are accepted; u16 rounds toward far.
TEST(NBufferCliTest, QueryMinOpAndFormats) {
  const fs::path f = small_depth("m.exr");
  CliResult r = nbsim("nbuffer query --depth " + f.string() + " --op min --rect 0,0,4,4");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FLOAT_EQ(nlohmann::json::parse(r.out)["value"].get<float>(), 0.25f);
  r = nbsim("nbuffer query --depth " + f.string() + " --format u16 --rect 1,1,1,1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_GE(nlohmann::json::parse(r.out)["value"].get<float>(), 0.25f) << "u16 must round toward far";
}

// TIFF and PFM files are read like EXR, with the same y-up orientation.
TEST(NBufferCliTest, ReadsTiffAndPfm) {
  const fs::path tif = small_depth("fmt.tif");
  // PFM by hand (OpenImageIO reads PFM but does not write it): rows go bottom to top, so the
  // first float is pixel (0, 0) and the fourth is (3, 0).
  const fs::path pfm = scratch("fmt.pfm");
  {
    std::ofstream o(pfm, std::ios::binary);
    o << "Pf\n4 4\n-1.0\n";
    std::array<float, 16> px;
    px.fill(0.25f);
    px[3] = 0.9f;
    o.write(reinterpret_cast<const char*>(px.data()), sizeof px);
  }
  for (const fs::path& f : {tif, pfm}) {
    const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 3,0,1,1");
    ASSERT_EQ(r.status, 0) << f << ": " << r.err;
    EXPECT_FLOAT_EQ(nlohmann::json::parse(r.out)["value"].get<float>(), 0.9f) << f << " read upside down?";
  }
}

// Each bad depth file is refused with exit 2 and a message naming the file and the first bad pixel.
TEST(NBufferCliTest, RefusesBadDepthValues) {
  struct Row { float v; const char* what; };
  const Row rows[] = {{std::numeric_limits<float>::quiet_NaN(), "NaN"},
                      {std::numeric_limits<float>::infinity(), "infinite"},
                      {1.5f, "outside [0, 1]"},
                      {-0.25f, "outside [0, 1]"}};
  int i = 0;
  for (const Row& row : rows) {
    const fs::path f = depth_with(row.v, 5, 2, "bad" + std::to_string(i++) + ".exr");
    const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,2,2");
    EXPECT_EQ(r.status, 2) << row.what;
    EXPECT_TRUE(has(r.err, f.string())) << "message must name the file: " << r.err;
    EXPECT_TRUE(has(r.err, row.what)) << r.err;
    EXPECT_TRUE(has(r.err, "(5, 2)")) << "message must name the first bad pixel: " << r.err;
    EXPECT_TRUE(r.out.empty()) << "nothing may be printed for a refused file";
  }
}

// Several channels, a missing file and a garbage file are refused with exit 2 naming the file.
TEST(NBufferCliTest, RefusesUnreadableFiles) {
  const fs::path rgb = scratch("rgb.exr");
  {
    namespace OIIO = OIIO_NAMESPACE;
    std::vector<float> px(4 * 4 * 3, 0.5f);
    auto out = OIIO::ImageOutput::create(rgb.string());
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(rgb.string(), OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::FLOAT)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
    out->close();
  }
  CliResult r = nbsim("nbuffer query --depth " + rgb.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "3 channels") && has(r.err, rgb.string())) << r.err;

  r = nbsim("nbuffer query --depth /nonexistent/depth.exr --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "/nonexistent/depth.exr") && has(r.err, "does not exist")) << r.err;

  const fs::path junk = scratch("junk.exr");
  std::ofstream(junk) << "this is not an image at all";
  r = nbsim("nbuffer query --depth " + junk.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, junk.string()) && has(r.err, "cannot be read")) << r.err;

  const fs::path empty = scratch("empty.exr");
  std::ofstream(empty).flush();
  r = nbsim("nbuffer query --depth " + empty.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, empty.string())) << r.err;
}

// A PFM whose header says `header` ("Pf\nW H\n-1.0\n") followed by `pixel_bytes` bytes of 0.5f.
fs::path pfm_with(const std::string& name, const std::string& header, std::size_t pixel_bytes) {
  const fs::path f = scratch(name);
  std::ofstream o(f, std::ios::binary);
  o << header;
  const float half = 0.5f;
  for (std::size_t i = 0; i < pixel_bytes / 4; ++i) o.write(reinterpret_cast<const char*>(&half), 4);
  return f;
}

// A depth image whose header declares more than the limit (16384 a side, 4096x4096 pixels in all)
// is refused with exit 2 before its pixels are allocated, the message naming the file, the size
// and the limit (without the check, a tiny PFM declaring 32768x32768 would allocate 4 GiB before
// failing). The sizes here stay small enough that even an unchecked read would not allocate much.
TEST(NBufferCliTest, RefusesDepthImageAboveSizeLimit) {
  const struct {
    const char* header;
    const char* size;
  } rows[] = {{"Pf\n20000 1\n-1.0\n", "20000x1"}, {"Pf\n1 16385\n-1.0\n", "1x16385"}, {"Pf\n4097 4097\n-1.0\n", "4097x4097"}};
  int i = 0;
  for (const auto& row : rows) {
    const fs::path f = pfm_with("huge" + std::to_string(i++) + ".pfm", row.header, 64);
    const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
    EXPECT_EQ(r.status, 2) << row.size << ": " << r.err;
    EXPECT_TRUE(has(r.err, f.string()) && has(r.err, "declares " + std::string(row.size) + " pixels") &&
                has(r.err, "above the depth image limit of 16384 pixels a side and 16777216 pixels in all"))
        << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

// A PFM with fewer pixel bytes than its header declares is refused with exit 2 and a reason that
// gives the sizes (never an empty "cannot be read: ").
TEST(NBufferCliTest, RefusesTruncatedPfm) {
  const fs::path f = pfm_with("short.pfm", "Pf\n4 4\n-1.0\n", 40);
  const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, f.string()) && has(r.err, "is a PFM of 52 bytes, too short for the 12-byte header and the 4x4 float "
                                                    "pixels (64 bytes) it declares (the pixel data is truncated)"))
      << r.err;
  EXPECT_FALSE(has(r.err, "cannot be read: \n")) << "a refusal always says why: " << r.err;
  const fs::path whole = pfm_with("whole.pfm", "Pf\n4 4\n-1.0\n", 64);
  EXPECT_EQ(nbsim("nbuffer query --depth " + whole.string() + " --rect 0,0,1,1").status, 0) << "the complete file reads";
}

// A 402-byte PNG whose text chunk declares 1.8 GB (a fuzz_depth_image finding). libpng allocates
// and clears the declared length before reading it (2 GB and a 15 s timeout), so every PNG chunk
// is checked against the file's size before OpenImageIO opens it. The input is the finding as the
// fuzzer kept it (its first byte picked the extension).
// A fuzz finding kept in tests/fuzz/corpus/fuzz_depth_image/, written as the file it stood for.
fs::path finding_file(const std::string& finding, const std::string& name) {
  std::ifstream in(fs::path(NBSIM_SOURCE_DIR) / "tests/fuzz/corpus/fuzz_depth_image" / finding, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_GT(bytes.size(), 10u) << finding;
  const fs::path f = scratch(name);
  std::ofstream(f, std::ios::binary) << bytes.substr(1);
  return f;
}

TEST(NBufferCliTest, RefusesPngChunkPastTheFileEnd) {
  const fs::path f = finding_file("png_text_chunk_past_end", "chunk_past_end.png");
  const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, f.string()) && has(r.err, "is a damaged PNG: chunk 5 ('tEXt') at byte 110 declares 1886545267 "
                                                    "bytes of data, past the end of the 401-byte file"))
      << r.err;
  // A whole PNG still reads (16-bit grey, as `nbuffer build --preview` writes them).
  const fs::path png = scratch("whole.png");
  nbsim::io::write_preview(nbsim::DepthImage(4, 4, 0.5f), png, 0.0f, 1.0f);
  EXPECT_EQ(nbsim("nbuffer query --depth " + png.string() + " --rect 0,0,1,1").status, 0);
}

// A 43-byte OpenEXR header whose string attribute declares 1.8 GB (a fuzz_depth_image finding;
// OpenEXR would allocate it: out of memory). The file is recognised by its first bytes, whatever
// its extension, and opened by that format's reader only, never offered to every reader
// OpenImageIO has (DICOM, video, raw, ...).
TEST(NBufferCliTest, RefusesExrAttributePastTheFileEnd) {
  const fs::path f = finding_file("exr_attribute_past_end", "attribute_past_end.exr");
  CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "is a damaged OpenEXR file: attribute 'Exif:ImageHistory' at byte 33 declares 1833519362 bytes, "
                         "past the end of the 42-byte file"))
      << r.err;
  // The same bytes named .png or .tif are still read as what they are.
  const fs::path renamed = scratch("attribute_past_end.png");
  fs::copy_file(f, renamed, fs::copy_options::overwrite_existing);
  r = nbsim("nbuffer query --depth " + renamed.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "is a damaged OpenEXR file")) << r.err;
  // A text file is none of the formats read.
  const fs::path text = scratch("text.tif");
  std::ofstream(text) << "P5 not really";
  r = nbsim("nbuffer query --depth " + text.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "not a depth image format nbsim reads (OpenEXR, TIFF, PNG or PFM")) << r.err;
}

// A 230-byte TIFF declaring 11825x4 pixels in strips of 63008 rows, its one strip past the end of
// the file (a fuzz_depth_image finding). OpenImageIO sizes its read buffer by RowsPerStrip
// (2.98 GB) and, when that fits, returns zeros without an error, so an unchecked `nbuffer build`
// would write 14 levels of 0.0 and exit 0. It is refused (exit 2, the file and the field named)
// before OpenImageIO opens it, within a few hundred MB, and the output folder it asked for is not
// left.
TEST(NBufferCliTest, RefusesTiffWhoseStripsDoNotFitTheFile) {
  const fs::path f = finding_file("tiff_strip_past_end", "strip_past_end.tif");
  const fs::path out = scratch("tiff_levels/deeper");
  const CliResult r = nbsim("nbuffer build --depth " + f.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, f.string()) && has(r.err, "declares RowsPerStrip 63008 for an image of 4 rows")) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(scratch("tiff_levels"))) << "a refused command removes the folders it created";
  // The same with 1-bit samples, which OpenImageIO holds a byte each (745 MB; a long fuzz run's
  // finding).
  const fs::path g = finding_file("tiff_one_bit_rows_per_strip", "one_bit.tif");
  const CliResult s = nbsim("nbuffer query --depth " + g.string() + " --rect 0,0,1,1");
  EXPECT_EQ(s.status, 2) << s.err;
  EXPECT_TRUE(has(s.err, "declares RowsPerStrip 63008 for an image of 4 rows")) << s.err;
}

// A TIFF whose deflate strip does not decode (a fuzz_depth_image finding): libtiff passes on
// zlib's empty message and OpenImageIO reports "ZLib error: ", which would stop at a colon. The
// reason is completed.
TEST(NBufferCliTest, RefusalNeverEndsAtAColon) {
  const fs::path f = finding_file("tiff_zlib_error_without_message", "zlib.tif");
  const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "ZLib error: OpenImageIO cannot decode its pixel data")) << r.err;
  EXPECT_FALSE(has(r.err, ": \n")) << r.err;
}

// TIFFs built byte by byte (tests/io/tiff_builder.h) are real TIFFs to OpenImageIO: each
// layout the precheck accepts reads back the pixel values written, and a compressed strip that
// does not decode is refused (OpenImageIO's TIFF reader reports it only through its error state:
// the pixels stay zero and the read succeeds).
TEST(NBufferCliTest, ReadsHandBuiltTiffsAndRefusesUndecodableStrips) {
  using nbsim::testing::TiffBuilder;
  // 4x3, file rows top-down: the far value 0.9 is in the file's first row, last column, so at
  // (3, 2) with y up.
  std::vector<float> px(12, 0.25f);
  px[3] = 0.9f;
  const auto write = [](const TiffBuilder& t, const std::string& name) {
    const fs::path f = scratch(name);
    const auto b = t.bytes();
    std::ofstream(f, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
    return f;
  };
  const struct {
    const char* name;
    TiffBuilder tiff;
  } rows[] = {
      {"le.tif", TiffBuilder(4, 3, px)},
      {"be.tif", TiffBuilder(4, 3, px).big_endian()},
      {"big.tif", TiffBuilder(4, 3, px).bigtiff()},
      {"strips.tif", TiffBuilder(4, 3, px).set(278, TiffBuilder::kShort, {1}).strips({{0, 16}, {16, 16}, {32, 16}})},
      {"rows_above.tif", TiffBuilder(4, 3, px).set(278, TiffBuilder::kLong, {8})},
      {"rows_all.tif", TiffBuilder(4, 3, px).set(278, TiffBuilder::kLong, {0xFFFFFFFFu})},
      {"rows_2_31.tif", TiffBuilder(4, 3, px).set(278, TiffBuilder::kLong, {0x80000005u})},
      {"no_rows_per_strip.tif", TiffBuilder(4, 3, px).erase(278)},
  };
  for (const auto& row : rows) {
    const fs::path f = write(row.tiff, row.name);
    const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 3,2,1,1 --rect 0,0,3,2");
    ASSERT_EQ(r.status, 0) << row.name << ": " << r.err;
    std::istringstream lines(r.out);
    std::string a, b;
    std::getline(lines, a), std::getline(lines, b);
    EXPECT_FLOAT_EQ(nlohmann::json::parse(a)["value"].get<float>(), 0.9f) << row.name;
    EXPECT_FLOAT_EQ(nlohmann::json::parse(b)["value"].get<float>(), 0.25f) << row.name;
  }
  const fs::path bad = write(TiffBuilder(4, 3, px).set(259, TiffBuilder::kShort, {8}), "not_deflate.tif");
  const CliResult r = nbsim("nbuffer query --depth " + bad.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, bad.string()) && has(r.err, "cannot be read: ") && has(r.err, "Decoding error")) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// fuzz_depth_image in CI (with its 512 MB allocation limit): an OpenEXR header whose v2f attribute
// declares 0 bytes; OpenEXR reads the v2f's 8 bytes anyway and then an "attribute" of 1.9 GB from
// inside the next one. A fixed-size type must declare its size.
TEST(NBufferCliTest, RefusesExrAttributeOfTheWrongSize) {
  const fs::path f = finding_file("exr_fixed_size_attribute_desync", "desync.exr");
  const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "attribute 'screenWindowCenter' at byte 484 of type v2f declares 0 bytes, and a v2f holds 8")) << r.err;
}

// The OpenImageIO backend is loaded only when an image is touched: without it, a query on the
// built-in scene still runs, and an image read names the missing backend (exit 2, no crash).
TEST(NBufferCliTest, ImageBackendLoadedOnlyWhenNeeded) {
  const fs::path f = small_depth("backend.exr");
  CliResult r = nbsim("nbuffer query --scene city --size 64x64 --rect 0,0,8,8");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string missing = "NBSIM_IMAGE_IO=/nonexistent/libnbsim_oiio.so ";
  CliResult without = nbsim::testing::run_nbsim_env(missing, "nbuffer query --scene city --size 64x64 --rect 0,0,8,8");
  EXPECT_EQ(without.status, 0) << without.err;
  EXPECT_EQ(without.out, r.out);
  without = nbsim::testing::run_nbsim_env(missing, "nbuffer query --depth " + f.string() + " --rect 0,0,1,1");
  EXPECT_EQ(without.status, 2);
  EXPECT_TRUE(has(without.err, "libnbsim_oiio.so") && has(without.err, "/nonexistent/libnbsim_oiio.so")) << without.err;
}

// Bad arguments exit 2 with a message naming the problem; no output is half-written.
TEST(NBufferCliTest, RefusesBadArguments) {
  const fs::path f = small_depth("args.exr");
  const std::string q = "nbuffer query --depth " + f.string();
  struct Row { std::string args; std::string message; };
  const Row rows[] = {
      {q + " --rect 0,0,0,2", "empty rectangle"},
      {q + " --rect 0,0,2", "bad rectangle"},
      {q + " --rect a,b,c,d", "bad rectangle"},
      {q + " --rect 0,0,2,2,2", "bad rectangle"},
      {q + " --rect 1,1,1,1 --rect 10,10,2,2", "outside"},
      {q + " --rect 0,0,2,2 --op mean", "--op"},
      {q + " --rect 0,0,2,2 --format f64", "--format"},
      {q + " --rect 0,0,2,2 --covering three", "--covering"},
      {q, "--rect"},
      {"nbuffer query --rect 0,0,1,1", "--depth"},
      {"nbuffer frobnicate", "frobnicate"},
      {"nbuffer coverage --size 0x4 --out " + scratch("c.png").string(), "--size"},
      {"nbuffer query --scene city --size 12 --rect 0,0,1,1", "--size"},
  };
  for (const Row& row : rows) {
    const CliResult r = nbsim(row.args);
    EXPECT_EQ(r.status, 2) << row.args << "\n" << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.args << ": message should mention '" << row.message << "': " << r.err;
    EXPECT_TRUE(r.out.empty()) << row.args << ": printed " << r.out;
  }
}

// Sizes beyond the stated bounds are refused before anything is allocated or written (they used
// to reach 8.4 GB and std::bad_alloc, or a 3.5 GB image); the bounds are stated in --help.
TEST(NBufferCliTest, SizesBounded) {
  const fs::path out = scratch("big_out");
  struct Row { std::string args, message; };
  const Row rows[] = {
      {"nbuffer query --scene city --size 46341x46341 --rect 0,0,1,1", "the built-in scene is at most 4096x4096"},
      {"nbuffer build --scene city --size 4097x16 --out " + out.string(), "at most 4096x4096"},
      {"nbuffer query --scene city --size 16x99999999999 --rect 0,0,1,1", "--size"},
      {"nbuffer coverage --size 1024x1024 --scale 16 --out " + (out / "c.png").string(), "makes a 82432x17536 image: at most 64 M pixels"},
      {"nbuffer coverage --size 16777216x1 --out " + (out / "c.png").string(), "at most 4096x4096 box sizes"},
  };
  for (const Row& row : rows) {
    const CliResult r = nbsim(row.args);
    EXPECT_EQ(r.status, 2) << row.args << "\n" << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(out)) << "nothing is written for a refused size";
  EXPECT_TRUE(has(nbsim("nbuffer query --help").out, "each side at most 4096"));
  EXPECT_TRUE(has(nbsim("nbuffer build --help").out, "each side at most 4096"));
  EXPECT_TRUE(has(nbsim("nbuffer coverage --help").out, "at most 64 M pixels"));
}

// A partly outside rectangle is clipped: it answers from the pixels inside only.
TEST(NBufferCliTest, ClipsPartlyOutsideRect) {
  const fs::path f = small_depth("clip.exr");
  const CliResult r = nbsim("nbuffer query --depth " + f.string() + " --rect -5,-5,7,7");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FLOAT_EQ(nlohmann::json::parse(r.out)["value"].get<float>(), 0.25f) << "only pixels [0,2)x[0,2) count";
}

// build writes every level as EXR and PNG, readable back with level 0 equal to the input.
TEST(NBufferCliTest, BuildWritesEveryLevel) {
  const fs::path f = small_depth("b.exr");
  const fs::path out = scratch("levels");
  const CliResult r = nbsim("nbuffer build --depth " + f.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(fs::exists(out / ("level_0" + std::to_string(i) + ".exr"))) << i;
    EXPECT_TRUE(fs::exists(out / ("level_0" + std::to_string(i) + ".png"))) << i;
  }
  EXPECT_FALSE(fs::exists(out / "level_02.exr")) << "a 4x4 image has exactly 2 levels";
  const nbsim::DepthImage l1 = nbsim::io::read_depth(out / "level_01.exr");
  EXPECT_FLOAT_EQ(l1.at(2, 0), 0.9f) << "level 1 at (2,0) covers the far pixel (3,0)";
  EXPECT_FLOAT_EQ(l1.at(3, 3), 0.25f);
  EXPECT_TRUE(fs::exists(out / "levels.json"));
}

// coverage writes the image and the CSV and prints a summary: every covering's mean extra area and
// the shares of the five cases of Fig. 3.
TEST(NBufferCliTest, CoverageWritesImageAndCsv) {
  const fs::path png = scratch("cov.png");
  const CliResult r = nbsim("nbuffer coverage --size 16x8 --out " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(png));
  std::ifstream csv(fs::path(png).replace_extension(".csv"));
  std::string line;
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 1 + 16 * 8) << "one header and one row per box size";
  for (const char* part : {"paper        mean extra", "corners      mean extra", "one          mean extra", "rect         mean extra", "rect_aspect1 mean extra", "four_quadrants", "two_side_by_side",
                           "two_stacked", "four_in_a_row", "four_in_a_column"})
    EXPECT_TRUE(has(r.out, part)) << part << ": " << r.out;
}

// `nbuffer memory` counts the levels and bytes without building them: the square levels of 640x480
// (10 levels), every rectangle level (10 x 9), those with sides at most 2x apart (26), and the
// limit (every rectangle level of 4096x4096 is 9 GiB).
TEST(NBufferCliTest, MemoryOfTheLevels) {
  const auto memory = [](const std::string& args) {
    const CliResult r = nbsim("nbuffer memory " + args);
    EXPECT_EQ(r.status, 0) << args << ": " << r.err;
    return nlohmann::json::parse(r.out);
  };
  nlohmann::json j = memory("--size 640x480");
  EXPECT_EQ(j["level_count"], 10);
  EXPECT_EQ(j["memory_bytes"], 10LL * 640 * 480 * 4);
  j = memory("--size 640x480 --levels rect");
  EXPECT_EQ(j["level_count"], 90);
  EXPECT_EQ(j["level_labels"][1], "1x2");
  EXPECT_EQ(j["level_labels"][2], "2x1");
  j = memory("--size 640x480 --levels rect --max-aspect-log2 1 --format u16");
  EXPECT_EQ(j["level_count"], 26);
  EXPECT_EQ(j["storage_bytes"], 26LL * 640 * 480 * 2);
  EXPECT_EQ(j["within_limit"], true);
  EXPECT_EQ(memory("--size 4096x4096 --levels rect")["within_limit"], false);
  const CliResult r = nbsim("nbuffer query --scene city --size 4096x4096 --levels rect --rect 0,0,4,4");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "an N-buffer of 144 rectangle levels of 4096x4096 floats needs 9216 MiB, above the limit of 4096 MiB")) << r.err;
  EXPECT_TRUE(r.out.empty());
}

// Figure 4 over every box from 1x1 to 256x256: the paper's covering adds 129.7 % of the box on
// average, nbsim's corner covering before it 284.3 %, one square 921.7 % (CoveringTest checks each
// covering's area against a brute-force count of its pixels).
TEST(NBufferCliTest, CoverageOfFigure4) {
  const fs::path png = scratch("fig4.png");
  const CliResult r = nbsim("nbuffer coverage --size 256x256 --scale 1 --out " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "paper        mean extra   129.7% of the box")) << r.out;
  EXPECT_TRUE(has(r.out, "corners      mean extra   284.3% of the box")) << r.out;
  EXPECT_TRUE(has(r.out, "one          mean extra   921.7% of the box")) << r.out;
  EXPECT_TRUE(has(r.out, "rect         mean extra     0.0% of the box, worst 0.0x the box, exact for 100.0% of sizes")) << r.out;
}

}  // namespace
