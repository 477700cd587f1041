// Chunk types a technique adds to a trace (format version 2): a small registry of fourcc, record
// name and field description. Each technique's types come from its <name>_format() (below) and are
// registered before any trace is read (tests may register more); the writer encodes a TechniqueRecord from its fields, the reader
// decodes a registered type's payload into fields and keeps an unregistered one raw, and `nbsim
// trace format` / `dump --records` show them. Technique chunks carry the chunk flag
// kFlagTechnique (FORMAT.md "Chunks"), which is what lets a reader keep an unknown one instead of
// refusing it as damage.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "nbsim/technique_list.h"
#include "traces/format/records.h"

namespace nbsim::trace {

// The field types a technique record may use (little-endian, as the core records).
enum class FieldKind : std::uint8_t { U32, I32, U64, F32, F64, String, VecF32, VecU32, VecI32 };

struct FieldSpec {
  std::string name;
  FieldKind kind;
  std::string meaning;
};

struct ChunkSpec {
  std::uint32_t type = 0;    // fourcc("PRTC"): four printable ASCII characters, not a core type
  std::string technique;     // the trace header's "technique" of the traces that hold it
  std::string record;        // the record's name in FORMAT.md and messages
  std::vector<FieldSpec> fields;
  // A rule the decoded fields keep beyond their types (e.g. vectors of one length), or null: why a
  // record breaks it, empty when it keeps it. The reader refuses a record that breaks it
  // (InputError naming the chunk), the writer aborts on one.
  std::string (*rule)(const TechniqueRecord& record) = nullptr;
};

// For a spec's rule: the field `name` of `record`, or nullptr.
const TechniqueField* find_field(const TechniqueRecord& record, std::string_view name);

// For a spec's rule: why a vector field of `record` (other than the fields named in `scalars`) does
// not have `count` elements ("field 'x' has 2 elements, but count is 3 (one a sprite)", with
// `one_a` = "sprite"), or empty when every one has.
std::string vector_lengths_problem(const TechniqueRecord& record, std::uint64_t count, std::initializer_list<std::string_view> scalars,
                                   std::string_view one_a);

// Registers a chunk type. A bad spec (a core or already registered type, an unprintable fourcc,
// no fields, duplicate field names) is a bug of the technique: it aborts.
void register_technique_chunk(ChunkSpec spec);
// The spec of a registered type, or nullptr.
const ChunkSpec* find_technique_chunk(std::uint32_t type);
// Every registered spec, in registration order. Techniques register at start-up, before traces are
// read or written on other threads (registration locks; this listing does not).
const std::vector<ChunkSpec>& technique_chunks();

// The payload of a record of a registered type, from its fields (which must match the spec's
// names and kinds, in order: a mismatch is a bug and aborts); the stored payload when the record
// was not decoded (an unregistered type read from a file is written back as it was).
std::vector<std::uint8_t> encode(const TechniqueRecord& record);
// A chunk's payload -> record: fields decoded when the type is registered (InputError when the
// payload does not match the description; the payload itself is not kept), raw otherwise.
TechniqueRecord decode_technique(std::uint32_t type, std::span<const std::uint8_t> payload);
// The Markdown table of a registered type's fields (as FORMAT.md's core tables).
std::string technique_table(const ChunkSpec& spec);
// "  name: value" lines (raw: the payload's size).
std::string dump_technique(const TechniqueRecord& record);

// A header key a technique declares beside its chunk types. parse_header checks it when the
// header's "technique" is `technique` (an InputError names the key, its value and `values`), the
// replay reads it typed (Header::whole, real, text), and FORMAT.md lists it under HEAD's keys. A
// property a technique writes without declaring it stays free text.
struct HeaderKeySpec {
  enum class Kind : std::uint8_t { Text, Whole, Real, OneOf, Custom };
  std::string technique;  // the header's "technique" value
  std::string name;       // the property's key
  Kind kind = Kind::Text;
  std::uint64_t min = 0, max = 0;                     // Whole: the closed range
  double lo = 0.0, hi = 0.0;                          // Real: the range, closed unless above_lo
  bool above_lo = false;                              // Real: lo itself excluded
  std::vector<std::string> choices;                   // OneOf: the values, exactly as written
  bool (*custom)(std::string_view value) = nullptr;   // Custom: whether a value is valid
  std::string values;                                 // in words, for FORMAT.md and refusals
  std::string example;
  std::string meaning;
};

// Declarations of each kind; `values` is written from the range or the choices.
HeaderKeySpec text_key(std::string technique, std::string name, std::string example, std::string meaning);
HeaderKeySpec whole_key(std::string technique, std::string name, std::uint64_t lo, std::uint64_t hi, std::string example,
                        std::string meaning);
HeaderKeySpec real_key(std::string technique, std::string name, double lo, double hi, bool above_lo, std::string example,
                       std::string meaning);
HeaderKeySpec choice_key(std::string technique, std::string name, std::vector<std::string> choices, std::string example,
                         std::string meaning);
HeaderKeySpec custom_key(std::string technique, std::string name, bool (*valid)(std::string_view), std::string values,
                         std::string example, std::string meaning);

// The header keys of the techniques this build knows, in registration order (the same list as
// their chunk types).
const std::vector<HeaderKeySpec>& technique_header_keys();

// What a technique adds to the format: its chunk types and its header keys. Each technique of the
// registration list (cmake/NbsimTechniques.cmake) defines TechniqueFormat <name>_format() in its
// folder, traces/format/<name>/.
struct TechniqueFormat {
  std::vector<ChunkSpec> chunks;
  std::vector<HeaderKeySpec> header_keys;
};
#define NBSIM_DECLARE_TECHNIQUE_FORMAT(name) TechniqueFormat name##_format();
NBSIM_EACH_TECHNIQUE(NBSIM_DECLARE_TECHNIQUE_FORMAT)
#undef NBSIM_DECLARE_TECHNIQUE_FORMAT

}  // namespace nbsim::trace
