// TraceSchemaTest: the records' one description (traces/format/schema.h) and what it drives
// besides the codec: FORMAT.md's record tables (which must equal the generated ones, so the
// document cannot drift), the table sizes against the encoder, and the generic dump.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <regex>

#include "model/common/error.h"
#include "tests/trace/sample_trace.h"
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
    EXPECT_TRUE(std::regex_search(table, m, std::regex(R"(\(([^)]*) bytes\))"))) << table;
    return m[1].str();
  };
  EXPECT_EQ(size_in(ChunkType::FrameBegin), std::to_string(encode(sample_frame_begin(3)).size()));
  EXPECT_EQ(size_in(ChunkType::FrameEnd), std::to_string(encode(FrameEnd{}).size()));
  EXPECT_EQ(size_in(ChunkType::End), std::to_string(encode(EndMarker{}).size()));
  // DRAW: constant + 16·V.
  const std::string draw = size_in(ChunkType::Draw);
  std::smatch m;
  ASSERT_TRUE(std::regex_match(draw, m, std::regex(R"((\d+) \+ 16·V)"))) << draw;
  const std::size_t base = std::stoul(m[1].str());
  for (std::size_t v : {0u, 3u, 9u}) EXPECT_EQ(encode(sample_draw(1, v)).size(), base + 16 * v) << "DRAW with " << v;
  // DPTH, NBLV: constant + 4·W·H (times L).
  const std::string depth = size_in(ChunkType::Depth);
  ASSERT_TRUE(std::regex_match(depth, m, std::regex(R"((\d+) \+ 4·W·H)"))) << depth;
  EXPECT_EQ(encode(sample_depth(DepthWhich::Final, 5, 3)).size(), std::stoul(m[1].str()) + 4 * 15);
  const std::string levels = size_in(ChunkType::Levels);
  ASSERT_TRUE(std::regex_match(levels, m, std::regex(R"((\d+) \+ 4·L·W·H)"))) << levels;
  EXPECT_EQ(encode(sample_levels(nbsim::FarOp::Max, 5, 3, 4)).size(), std::stoul(m[1].str()) + 4 * 60);
}

// Every field of the table appears in the dump of a record, in the table's order.
TEST(TraceSchemaTest, DumpShowsEveryField) {
  const std::string table = record_table(ChunkType::Draw, kFormatVersion);
  const std::string dump = dump_record(sample_draw(5, 2));
  std::size_t at = 0;
  const std::regex field(R"(\| `([^`]+)` \|)");
  int fields = 0;
  for (auto it = std::sregex_iterator(table.begin(), table.end(), field); it != std::sregex_iterator(); ++it) {
    const std::size_t p = dump.find("  " + (*it)[1].str() + ":", at);
    ASSERT_NE(p, std::string::npos) << "field " << (*it)[1] << " missing (or out of order) in:\n" << dump;
    at = p;
    ++fields;
  }
  EXPECT_GT(fields, 20);
  EXPECT_TRUE(has(dump, "role: 5 (visible)")) << dump;
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

}  // namespace
