// TraceSchemaTest: the records' one description (traces/format/schema.h) and what it drives
// besides the codec: FORMAT.md's record tables (which must equal the generated ones, so the
// document cannot drift), the table sizes against the encoder, and the generic dump.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <regex>

#include "model/common/error.h"
#include "tests/traces/format/sample_trace.h"
#include "traces/format/describe.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string format_doc() {
  std::ifstream in(NBSIM_FORMAT_DOC, std::ios::binary);
  EXPECT_TRUE(in) << NBSIM_FORMAT_DOC;
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// FORMAT.md's generated regions hold exactly what `nbsim trace format` prints today (refresh with
// `nbsim trace format --update traces/FORMAT.md` after changing schema.h).
TEST(TraceSchemaTest, FormatDocTablesMatchTheSchema) {
  const std::string doc = format_doc();
  const std::string fresh = refresh_format_doc(doc);
  if (fresh != doc) {
    std::size_t i = 0;
    while (i < doc.size() && i < fresh.size() && doc[i] == fresh[i]) ++i;
    FAIL() << "traces/FORMAT.md's record tables differ from the schema from byte " << i << ":\n  doc:    "
           << doc.substr(i, 160) << "\n  schema: " << fresh.substr(i, 160)
           << "\nrun: nbsim trace format --update traces/FORMAT.md";
  }
}

// Every record of the newest version has its table in FORMAT.md.
TEST(TraceSchemaTest, FormatDocShowsEveryRecordOfTheNewestVersion) {
  const std::vector<std::string> regions = format_doc_regions(format_doc());
  for (const RecordKind& k : record_kinds()) {
    std::string type = chunk_type_name(k.type);
    if (type == "END ") type = "END";
    const std::string want = type + " " + std::to_string(kFormatVersion);
    EXPECT_NE(std::find(regions.begin(), regions.end(), want), regions.end()) << "FORMAT.md lacks the table of " << want;
  }
}

// A table's stated size is the encoder's: fixed records exactly, variable ones at their symbols' values.
TEST(TraceSchemaTest, TableSizesAreTheEncodersSizes) {
  auto size_in = [](ChunkType t) {
    const std::string table = record_table(t, kFormatVersion);
    std::smatch m;
    EXPECT_TRUE(std::regex_search(table, m, std::regex(R"(\((.*) bytes\))"))) << table;
    return m[1].str();
  };
  EXPECT_EQ(size_in(ChunkType::FrameBegin), std::to_string(encode(sample_frame_begin(3)).size()));
  EXPECT_EQ(size_in(ChunkType::FrameEnd), std::to_string(encode(FrameEnd{}).size()));
  EXPECT_EQ(size_in(ChunkType::End), std::to_string(encode(EndMarker{}).size()));
  // DRAW: constant + 16·V + 4·S (S point sizes).
  const std::string draw = size_in(ChunkType::Draw);
  std::smatch m;
  ASSERT_TRUE(std::regex_match(draw, m, std::regex(R"((\d+) \+ 16·V \+ 4·S)"))) << draw;
  const std::size_t base = std::stoul(m[1].str());
  for (std::size_t v : {0u, 3u, 9u}) EXPECT_EQ(encode(sample_draw(1, v)).size(), base + 16 * v) << "DRAW with " << v;
  const DrawRecord points = sample_draw_v2(1, 5);
  EXPECT_EQ(encode(points).size(), base + 16 * 5 + 4 * points.point_sizes.size()) << "DRAW of points";
  // DPTH, NBLV, STNC: constant + the name's length + the texels.
  const std::string depth = size_in(ChunkType::Depth);
  ASSERT_TRUE(std::regex_match(depth, m, std::regex(R"((\d+) \+ len\(name\) \+ 4·W·H)"))) << depth;
  EXPECT_EQ(encode(sample_depth(DepthWhich::Final, 5, 3)).size(), std::stoul(m[1].str()) + 5 + 4 * 15);
  const std::string levels = size_in(ChunkType::Levels);
  ASSERT_TRUE(std::regex_match(levels, m, std::regex(R"((\d+) \+ len\(source\) \+ 4·L·W·H)"))) << levels;
  EXPECT_EQ(encode(sample_levels(nbsim::FarOp::Max, 5, 3, 4)).size(), std::stoul(m[1].str()) + 15 + 4 * 60);
  const std::string stencil = size_in(ChunkType::Stencil);
  ASSERT_TRUE(std::regex_match(stencil, m, std::regex(R"((\d+) \+ len\(name\) \+ W·H)"))) << stencil;
  EXPECT_EQ(encode(sample_stencil("mask", 5, 3)).size(), std::stoul(m[1].str()) + 4 + 15);
  EXPECT_EQ(size_in(ChunkType::Light), std::to_string(encode(sample_light(0)).size()));
}

// The tables of version 1 that differ from version 2's are in FORMAT.md too (readers still read
// them), and the others are the same in both versions.
TEST(TraceSchemaTest, FormatDocShowsTheVersion1LayoutsThatChanged) {
  const std::vector<std::string> regions = format_doc_regions(format_doc());
  int changed = 0;
  for (const RecordKind& k : record_kinds()) {
    if (k.since > 1) continue;
    std::string type = chunk_type_name(k.type);
    if (type == "END ") type = "END";
    if (record_table(k.type, 1) == record_table(k.type, 2)) continue;
    ++changed;
    EXPECT_NE(std::find(regions.begin(), regions.end(), type + " 1"), regions.end()) << "FORMAT.md lacks " << type << "'s version 1 table";
  }
  EXPECT_EQ(changed, 3) << "DRAW, DPTH and NBLV changed in version 2";
}

// Every field of the table appears in the dump of a record, in the table's order.
TEST(TraceSchemaTest, DumpShowsEveryField) {
  const std::string table = record_table(ChunkType::Draw, kFormatVersion);
  const std::string dump = dump_record(sample_draw_v2(5, 2));
  std::size_t at = 0;
  const std::regex field(R"(\| `([^`]+)` \|)");
  int fields = 0;
  for (auto it = std::sregex_iterator(table.begin(), table.end(), field); it != std::sregex_iterator(); ++it) {
    const std::size_t p = dump.find("  " + (*it)[1].str() + ":", at);
    ASSERT_NE(p, std::string::npos) << "field " << (*it)[1] << " missing (or out of order) in:\n" << dump;
    at = p;
    ++fields;
  }
  EXPECT_GT(fields, 40);
  EXPECT_TRUE(has(dump, "role: 5 (visible)")) << dump;
  EXPECT_TRUE(has(dump, "stencil.front.fail: 4 (incr_wrap)")) << dump;
}

// The tables of every version exist for every record of that version, and a document naming an
// unknown record is refused.
TEST(TraceSchemaTest, TablesPerVersion) {
  for (std::uint32_t v = 1; v <= kFormatVersion; ++v)
    for (const RecordKind& k : record_kinds())
      EXPECT_EQ(record_table(k.type, v).empty(), v < k.since) << chunk_type_name(k.type) << " v" << v;
  EXPECT_TRUE(record_table(ChunkType::Draw, kFormatVersion + 1).empty());
  EXPECT_THROW(refresh_format_doc("<!-- generated: nbsim trace format ZZZZ 1 -->\n<!-- end generated -->\n"),
               nbsim::InputError);
  EXPECT_THROW(refresh_format_doc("<!-- generated: nbsim trace format DRAW 1 -->\nno end"), nbsim::InputError);
}

// A registered technique chunk's table lists its fields; `nbsim trace format` appends it.
TEST(TraceSchemaTest, TechniqueChunkTables) {
  register_test_chunk();
  const ChunkSpec* spec = find_technique_chunk(kTestChunk);
  ASSERT_NE(spec, nullptr);
  const std::string t = technique_table(*spec);
  EXPECT_TRUE(has(t, "### TSTX: TestRecord (technique test_technique)")) << t;
  EXPECT_TRUE(has(t, "| 9 | vec<i32> | `deltas` | i32s |")) << t;
  EXPECT_TRUE(has(record_tables(kFormatVersion), t));
  const std::string d = dump_technique(sample_technique_record(4));
  EXPECT_TRUE(has(d, "count: 4000000004") && has(d, "label: \"litmap \"max\"\"") && has(d, "deltas: 0 elements")) << d;
  EXPECT_TRUE(has(dump_technique(sample_raw_record()), "payload: 7 bytes (raw)"));
}

}  // namespace
