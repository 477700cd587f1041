// TraceCliTest: `nbsim trace info|verify|dump` from the outside, on traces written by the trace
// library: exit statuses, messages, the JSON summary and the dumped images and CSV.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <sstream>
#include <sys/wait.h>

#include "io/image_io.h"
#include "tests/common/run_nbsim.h"
#include "tests/traces/format/sample_trace.h"
#include "traces/format/describe.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

using nbsim::testing::CliResult;
using nbsim::testing::has;

CliResult nbsim(const std::string& args) { return nbsim::testing::run_nbsim(args); }


const fs::path& sample() {
  static const fs::path f = [] {
    const fs::path p = scratch("cli_sample.nbtrace");
    write_sample_trace(p);
    return p;
  }();
  return f;
}

// --help works on every trace subcommand and exits 0.
TEST(TraceCliTest, HelpExitsZero) {
  for (const char* sub : {"trace", "trace info", "trace verify", "trace dump", "trace format"}) {
    const CliResult r = nbsim(std::string(sub) + " --help");
    EXPECT_EQ(r.status, 0) << sub << ": " << r.err;
    EXPECT_TRUE(has(r.out, "Usage")) << sub << ": " << r.out;
  }
}

// verify prints one summary line and exits 0 for a sound trace.
TEST(TraceCliTest, VerifySoundTrace) {
  const CliResult r = nbsim("trace verify " + sample().string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line: " << r.out;
  EXPECT_TRUE(has(r.out, "sound") && has(r.out, "format version " + std::to_string(kFormatVersion)) && has(r.out, "3 frames") && has(r.out, "9 draws"))
      << r.out;
}

// verify exits 2 for damage, with a message naming the file and, for a damaged chunk, its index,
// type and byte offset; nothing goes to stdout. (Every kind of damage: TraceCorruptionTest.)
TEST(TraceCliTest, VerifyRefusesDamage) {
  const Bytes good = read_file(sample());
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  struct Row {
    std::string name;
    Bytes bytes;
    std::vector<std::string> messages;
  };
  Bytes flipped = good;
  flipped[offsets[3] + kChunkHeaderBytes + 2] ^= 0x10;  // inside the first draw batch's payload
  Bytes newer = good;
  const auto pre = encode_preamble(kFormatVersion + 1);
  std::copy(pre.begin(), pre.end(), newer.begin());
  const Row rows[] = {
      {"flipped.nbtrace", flipped, {"chunk 3 (DRWS) at byte " + std::to_string(offsets[3]), "CRC-32 mismatch"}},
      {"no_end.nbtrace", Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(offsets.back())),
       {"chunk " + std::to_string(offsets.size() - 1) + " at byte " + std::to_string(offsets.back()), "without an END chunk"}},
      {"empty.nbtrace", {}, {"empty"}},
      {"newer.nbtrace", newer, {"newer", "update nbsim"}},
  };
  for (const Row& row : rows) {
    const fs::path f = scratch(row.name);
    write_file(f, row.bytes);
    const CliResult r = nbsim("trace verify " + f.string());
    EXPECT_EQ(r.status, 2) << row.name << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << row.name << ": " << r.out;
    EXPECT_TRUE(has(r.err, f.string())) << row.name << ": must name the file: " << r.err;
    for (const std::string& m : row.messages) EXPECT_TRUE(has(r.err, m)) << row.name << ": expected '" << m << "': " << r.err;
  }
  const CliResult r = nbsim("trace verify /nonexistent/t.nbtrace");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "/nonexistent/t.nbtrace") && has(r.err, "does not exist")) << r.err;
}

// info prints the header properties, the scene and one line per frame with GL's counts and the
// ground truth's visible objects.
TEST(TraceCliTest, InfoText) {
  const CliResult r = nbsim("trace info " + sample().string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "GL_RENDERER: llvmpipe (LLVM 15.0.6, 256 bits)")) << r.out;
  EXPECT_TRUE(has(r.out, "command_line: nbsim capture city")) << r.out;
  EXPECT_TRUE(has(r.out, "scene: 6 objects, 3 BVH nodes")) << r.out;
  for (const SampleFrame& f : sample_frames()) {
    std::uint64_t frags = 0, passed = 0;
    for (const DrawRecord& d : f.draws) {
      frags += d.gl.fragments;
      passed += d.gl.samples_passed;
    }
    const std::string line = "frame " + std::to_string(f.begin.frame) + " (" + std::string(to_string(f.begin.mode)) +
                             "): " + std::to_string(f.draws.size()) + " draws, " + std::to_string(frags) +
                             " GL fragments, " + std::to_string(passed) + " samples passed";
    EXPECT_TRUE(has(r.out, line)) << "expected '" << line << "' in:\n" << r.out;
  }
  EXPECT_TRUE(has(r.out, "3 objects visible")) << "frame 0's ground truth shows objects 0, 2, 4:\n" << r.out;
}

// info --json prints one JSON object with the properties in order and per-frame numbers.
TEST(TraceCliTest, InfoJson) {
  const CliResult r = nbsim("trace info --json " + sample().string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::ordered_json::parse(r.out);
  EXPECT_EQ(j["format_version"], kFormatVersion);
  EXPECT_EQ(j["bytes"], fs::file_size(sample()));
  const Properties props = sample_properties();
  ASSERT_EQ(j["properties"].size(), props.size());
  std::size_t i = 0;
  for (const auto& [k, v] : j["properties"].items()) {
    EXPECT_EQ(k, props[i].first) << "properties keep their order";
    EXPECT_EQ(v, props[i].second);
    ++i;
  }
  EXPECT_EQ(j["scene"]["objects"], 6);
  const auto want = sample_frames();
  ASSERT_EQ(j["frames"].size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    const auto& f = j["frames"][k];
    std::uint64_t frags = 0, passed = 0;
    for (const DrawRecord& d : want[k].draws) {
      frags += d.gl.fragments;
      passed += d.gl.samples_passed;
    }
    EXPECT_EQ(f["frame"], want[k].begin.frame);
    EXPECT_EQ(f["draws"], want[k].draws.size());
    EXPECT_EQ(f["fragments"], frags);
    EXPECT_EQ(f["samples_passed"], passed);
    if (want[k].truth) {
      const auto visible = std::count_if(want[k].truth->visible_pixels.begin(), want[k].truth->visible_pixels.end(),
                                         [](std::uint32_t n) { return n > 0; });
      EXPECT_EQ(f["objects_visible"], visible) << "frame " << want[k].begin.frame;
    } else {
      EXPECT_TRUE(f["objects_visible"].is_null()) << "frame 5 records no ground truth";
    }
  }
  EXPECT_EQ(j["frames"][1]["depth"], nlohmann::json({"after_occluders", "final"}));
  EXPECT_EQ(j["frames"][1]["levels"][1], nlohmann::ordered_json({{"op", "min"}, {"levels", 5}, {"size", "32x24"}}));
  EXPECT_EQ(j["totals"]["draws"], 9);
}

// dump writes the chosen depth snapshot, every N-buffer level and the ground truth, bit-exact.
TEST(TraceCliTest, DumpWritesDepthLevelsAndTruth) {
  const fs::path depth = scratch("dump_depth.exr"), levels = scratch("dump_levels"), csv = scratch("dump_truth.csv"),
                 png = scratch("dump_ids.png");
  const CliResult r = nbsim("trace dump " + sample().string() + " --frame 2 --which occluders --depth " + depth.string() +
                            " --levels " + levels.string() + " --truth " + csv.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const SampleFrame want = sample_frames()[1];

  const nbsim::DepthImage d = nbsim::io::read_depth(depth);
  ASSERT_EQ(d.width, 32);
  ASSERT_EQ(d.height, 24);
  EXPECT_TRUE(same_words(d.texels, want.depths[0].texels)) << "the after-occluders snapshot, y up, bit-exact";

  for (const NBufferLevels& l : want.levels) {
    const std::string op = l.op == 0 ? "max" : "min";
    for (int i = 0; i < l.levels; ++i) {
      const fs::path f = levels / ("" + op + "_level_0" + std::to_string(i) + ".exr");
      ASSERT_TRUE(fs::exists(f)) << f;
      const nbsim::DepthImage img = nbsim::io::read_depth(f);
      const std::size_t plane = 32 * 24;
      const std::vector<float> expect(l.texels.begin() + static_cast<std::ptrdiff_t>(plane * i),
                                      l.texels.begin() + static_cast<std::ptrdiff_t>(plane * (i + 1)));
      EXPECT_TRUE(same_words(img.texels, expect)) << f;
    }
  }

  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "object,visible_pixels");
  for (std::size_t i = 0; i < want.truth->visible_pixels.size(); ++i) {
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line, std::to_string(i) + "," + std::to_string(want.truth->visible_pixels[i]));
  }
  EXPECT_FALSE(std::getline(in, line)) << "one row per object";

  const CliResult p = nbsim("trace dump " + sample().string() + " --frame 2 --truth " + png.string());
  ASSERT_EQ(p.status, 0) << p.err;
  namespace OIIO = OIIO_NAMESPACE;
  auto img = OIIO::ImageInput::open(png.string());
  ASSERT_TRUE(img);
  ASSERT_EQ(img->spec().width, 32);
  ASSERT_EQ(img->spec().nchannels, 3);
  std::vector<std::uint8_t> px(32 * 24 * 3);
  ASSERT_TRUE(img->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  // File row 23 is y = 0; ids there are -1 for x < 5 (black) and object 0 for 5 <= x < 10.
  const std::size_t bottom = 23 * 32 * 3;
  EXPECT_EQ(px[bottom] + px[bottom + 1] + px[bottom + 2], 0) << "no object: black";
  EXPECT_GT(px[bottom + 5 * 3] + px[bottom + 5 * 3 + 1] + px[bottom + 5 * 3 + 2], 0) << "object 0: a colour";
}

// dump refuses (exit 2, nothing written) what the frame does not hold and bad arguments.
TEST(TraceCliTest, DumpRefusals) {
  const std::string t = "trace dump " + sample().string();
  const fs::path out = scratch("refused.exr");
  const std::string d = " --depth " + out.string();
  struct Row {
    std::string args;
    std::string message;
  };
  const Row rows[] = {
      {t + " --frame 3" + d, "has no frame 3 (the next frame is 5)"},
      {t + " --frame 9" + d, "has no frame 9 (its 3 frames are numbered 0 to 5)"},
      {t + " --frame 0 --which occluders" + d, "no 'after_occluders' depth snapshot (it has: final)"},
      {t + " --frame 0 --levels " + scratch("refused_levels").string() + d, "records no N-buffer levels"},
      {t + " --frame 5 --truth " + scratch("refused.csv").string() + d, "records no ground truth"},
      {t + " --frame 0 --truth " + scratch("refused.png").string() + d, "records no ID-buffer image"},
      {t + " --frame 0 --truth " + scratch("refused.txt").string(), "expected a .csv"},
      {t + " --frame 0", "nothing to dump"},
      {t + " --frame 0 --which middle" + d, "no 'middle' depth snapshot (it has: final)"},
      {t + d, "--frame"},
  };
  for (const Row& row : rows) {
    fs::remove(out);
    const CliResult r = nbsim(row.args);
    EXPECT_EQ(r.status, 2) << row.args << "\n" << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.args << ": expected '" << row.message << "': " << r.err;
    EXPECT_FALSE(fs::exists(out)) << row.args << ": wrote output although refused";
  }
  EXPECT_FALSE(fs::exists(scratch("refused_levels"))) << "no level directory for a refused dump";
}

// `trace format` prints the record tables from the schema (the same text FORMAT.md holds), for
// this version or an older one, and refuses a version this build does not know.
TEST(TraceCliTest, FormatPrintsTheRecordTables) {
  CliResult r = nbsim("trace format");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, record_tables(kFormatVersion));
  EXPECT_TRUE(has(r.out, "### DRWS: DrawBatch") && has(r.out, "| `stencil.back.pass` |")) << r.out;
  r = nbsim("trace format --format-version 1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "| `which` |") && !has(r.out, "DRWS")) << r.out;
  r = nbsim("trace format --format-version " + std::to_string(kFormatVersion + 1));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "knows format versions 1 to")) << r.err;
  // --update leaves a current document as it is.
  const fs::path doc = scratch("FORMAT.md");
  {
    std::ofstream out(doc);
    out << "intro\n<!-- generated: nbsim trace format FEND 2 -->\nstale\n<!-- end generated -->\nend\n";
  }
  r = nbsim("trace format --update " + doc.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "refreshed its 1 record tables")) << r.out;
  std::ifstream in(doc);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "intro\n<!-- generated: nbsim trace format FEND 2 -->\n" + record_table(ChunkType::FrameEnd, 2) +
                      "<!-- end generated -->\nend\n");
  r = nbsim("trace format --update " + doc.string());
  EXPECT_TRUE(has(r.out, "are current")) << r.out;
}

// `trace dump --records` prints every record of the frame through the schema, field by field.
TEST(TraceCliTest, DumpRecords) {
  const CliResult r = nbsim("trace dump " + sample().string() + " --frame 2 --records");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "FRAM FrameBegin\n  frame: 2\n")) << r.out;
  EXPECT_TRUE(has(r.out, "DRAW DrawRecord\n  index: 2\n")) << r.out;
  EXPECT_TRUE(has(r.out, "DPTH DepthSnapshot\n  name: \"after_occluders\"\n")) << r.out;
  EXPECT_TRUE(has(r.out, "NBLV NBufferLevels\n  source: \"after_occluders\"\n  op: 1 (min)")) << r.out;
  EXPECT_TRUE(has(r.out, "FEND FrameEnd\n  frame: 2\n  draws: 3\n")) << r.out;
}

// info --json lists a frame's stencil images, light camera and technique records when it has them
// (nbsim itself registers no technique chunk, so it reads them raw) and omits the keys otherwise.
TEST(TraceCliTest, InfoShowsVersion2Records) {
  const fs::path f = scratch("v2_info.nbtrace");
  write_sample_trace_v2(f);
  const CliResult r = nbsim("trace info --json " + f.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& frames = j["frames"];
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0]["draws"], 1029);
  EXPECT_FALSE(frames[0].contains("stencil") || frames[0].contains("light") || frames[0].contains("technique_records"));
  EXPECT_EQ(frames[1]["depth"], nlohmann::json({"after_occluders", "final", "litmap_min", "litmap_max"}));
  EXPECT_EQ(frames[1]["stencil"], nlohmann::json({"shadow_mask", "volumes"}));
  EXPECT_EQ(frames[1]["light"], true);
  EXPECT_EQ(frames[1]["technique_records"], nlohmann::json({"TSTX", "RAWX", "TSTX"}));
  EXPECT_EQ(frames[2]["technique_records"], nlohmann::json({"RAWX"}));
  const CliResult d = nbsim("trace dump " + f.string() + " --frame 2 --records");
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_TRUE(has(d.out, "STNC StencilSnapshot\n  name: \"shadow_mask\"\n")) << d.out;
  EXPECT_TRUE(has(d.out, "LGHT Camera\n  view: [")) << d.out;
  EXPECT_TRUE(has(d.out, "TSTX (unregistered technique chunk)\n  payload: ")) << d.out;
}

// A header value that is not UTF-8 is refused by verify and by info --json with exit 2, naming the
// key and chunk 0, and nothing goes to stdout (info --json must not fail in the JSON library).
TEST(TraceCliTest, RefusesNonUtf8Header) {
  const fs::path f = scratch("latin1.nbtrace");
  Bytes b;
  const auto pre = encode_preamble(kFormatVersion);
  b.assign(pre.begin(), pre.end());
  for (const Bytes& c : {encode_chunk(ChunkType::Header, encode(Properties{{"viewport", "8x8"}, {"command_line", "nbsim -o caf\xe9.nbt"}})),
                         encode_chunk(ChunkType::End, encode(EndMarker{1, 0}))})
    b.insert(b.end(), c.begin(), c.end());
  write_file(f, b);
  for (const char* cmd : {"trace verify ", "trace info --json ", "trace info "}) {
    const CliResult r = nbsim(cmd + f.string());
    EXPECT_EQ(r.status, 2) << cmd << r.out << r.err;
    EXPECT_TRUE(has(r.err, "chunk 0 (HEAD)") && has(r.err, "property 'command_line' has a value that is not UTF-8"))
        << cmd << r.err;
    EXPECT_TRUE(r.out.empty()) << cmd << r.out;
  }
}

}  // namespace
