// What schema.h's one description of each record also drives besides the codec: FORMAT.md's
// record tables (`nbsim trace format`, and the test that keeps the document equal to them) and a
// generic dump of any record (`nbsim trace dump --records`).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "traces/format/records.h"

namespace nbsim::trace {

// The chunk types whose records schema.h describes, in FORMAT.md's order, with the first format
// version that has them.
struct RecordKind {
  ChunkType type;
  const char* record;  // the struct's name ("DrawRecord")
  std::uint32_t since;
};
const std::vector<RecordKind>& record_kinds();
// The record struct a chunk type holds ("DrawRecord"), "?" for none.
std::string record_name(ChunkType type);

// "### DRAW: DrawRecord (80 + 16·V bytes)", a blank line and the Markdown table of the record's
// fields (offset, type, field, meaning) in the layout of `version`; "" when `type` has no record
// in that version.
std::string record_table(ChunkType type, std::uint32_t version);

// Every record's table of `version`, one after the other, then the header's known keys and the
// registered technique chunks' tables (what `nbsim trace format` prints).
std::string record_tables(std::uint32_t version);

// FORMAT.md's text with every generated region refreshed. A region is
//   <!-- generated: nbsim trace format DRAW 2 -->  ...  <!-- end generated -->
// and holds record_table(DRAW, 2); the region "HEAD-KEYS 2" holds header_keys_table(). Throws
// InputError for a malformed or unknown region.
std::string refresh_format_doc(std::string_view doc);

// The records of `version` that FORMAT.md must show: "TYPE version" for each region found.
std::vector<std::string> format_doc_regions(std::string_view doc);

// One record, field by field ("  role: 4 (nbuffer_query)"), long vectors abbreviated.
std::string dump_record(const Properties& r);
std::string dump_record(const SceneObjects& r);
std::string dump_record(const FrameBegin& r);
std::string dump_record(const DrawRecord& r);
std::string dump_record(const DepthSnapshot& r);
std::string dump_record(const NBufferLevels& r);
std::string dump_record(const GroundTruth& r);
std::string dump_record(const FrameEnd& r);
std::string dump_record(const StencilSnapshot& r);
std::string dump_record(const Camera& r);
// A whole frame: FRAM, its records in the order the reader keeps them, FEND.
std::string dump_frame(const scene::Frame& f);

}  // namespace nbsim::trace
