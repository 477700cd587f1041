// FORMAT.md's record tables and the generic record dump, both from schema.h's field visitor; see
// describe.h.
#include "traces/format/describe.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <type_traits>
#include <utility>

#include "model/common/error.h"
#include "traces/format/codec.h"
#include "traces/format/header.h"
#include "traces/format/schema.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

namespace {

template <class T>
constexpr const char* int_type() {
  if constexpr (std::is_same_v<T, std::uint8_t>) return "u8";
  else if constexpr (std::is_same_v<T, std::uint32_t>) return "u32";
  else if constexpr (std::is_same_v<T, std::int32_t>) return "i32";
  else return "u64";
}

template <class E>
std::string enum_values() {
  std::string s = fmt::format("{}:", EnumInfo<E>::name);
  for (unsigned v = 0; v <= EnumInfo<E>::max; ++v)
    s += fmt::format("{} {} {}", v ? "," : "", v, enum_value_name(static_cast<E>(v)));
  return s;
}

std::string join_meaning(std::string a, const char* b) {
  if (!b || !*b) return a;
  if (a.empty()) return b;
  return a + "; " + b;
}

// Builds a record's table: one row per field, with offsets that stay exact after variable-size
// fields (as a constant plus multiples of the counts' symbols, "25+16·V", and string lengths,
// "4+len(name)").
class DocIo {
 public:
  explicit DocIo(std::uint32_t version) : version_(version) {}
  std::uint32_t version() const { return version_; }
  template <class F> void since(std::uint32_t v, F&& f) { if (version_ >= v) f(); }
  template <class F> void until(std::uint32_t v, F&& f) { if (version_ <= v) f(); }
  void u8(const char* n, std::uint8_t&, const char* m) { row(n, "u8", m, 1); }
  void u32(const char* n, std::uint32_t&, const char* m) { row(n, "u32", m, 4); }
  void u64(const char* n, std::uint64_t&, const char* m) { row(n, "u64", m, 8); }
  void i32(const char* n, std::int32_t&, const char* m) { row(n, "i32", m, 4); }
  void f32(const char* n, float&, const char* m) { row(n, "f32", m, 4); }
  void f64(const char* n, double&, const char* m) { row(n, "f64", m, 8); }
  void boolean(const char* n, bool&, const char* m) { row(n, "bool", m, 1); }
  template <class T> void ranged(const char* n, T&, T lo, T hi, const char* symbol, const char* m) {
    std::string range = hi == std::numeric_limits<T>::max() ? fmt::format("at least {}", +lo) : fmt::format("{} .. {}", +lo, +hi);
    if (*symbol) range = fmt::format("{}, {}", symbol, range);
    row(n, int_type<T>(), join_meaning(range, m), sizeof(T));
  }
  template <class E> void enumeration(const char* n, E&, const char* m) { row(n, "u8", join_meaning(enum_values<E>(), m), 1); }
  template <std::size_t N> void floats(const char* n, std::array<float, N>&, const char* m) {
    row(n, fmt::format("f32[{}]", N), m, 4 * N);
  }
  void string(const char* n, std::string&, std::size_t, const char* m) {
    row(n, "string", m, 4);
    add_term(fmt::format("len({})", n), 1);
  }
  template <class T> void words(const char* n, std::vector<T>&, const char* symbol, const char* m) {
    row(n, fmt::format("vec<{}>", word_type<T>()), join_meaning(fmt::format("{} elements", symbol), m), 4);
    add_term(symbol, 4);
  }
  template <class T> void image(const char* n, std::vector<T>&, std::uint64_t, const char* count_text, const char* m) {
    row(n, fmt::format("{}[{}]", word_type<T>(), count_text), m, 0);
    add_term(count_text, sizeof(T));
  }
  template <class E, class F> void items(const char* n, std::vector<E>&, const char* symbol, Element el, F&&, const char* m) {
    row(n, fmt::format("vec<{}>", el.type), join_meaning(fmt::format("{} elements", symbol), m), 4);
    if (el.fixed)
      add_term(symbol, el.bytes);
    else
      variable_ = true;
  }

  // The table and the record's size ("80 + 16·V bytes").
  std::string table() const {
    std::string t = "| Offset | Type | Field | Meaning |\n|--------|------|-------|---------|\n";
    for (const auto& r : rows_) t += fmt::format("| {} | {} | `{}` | {} |\n", r[0], r[1], r[2], r[3]);
    return t;
  }
  std::string size() const { return variable_ ? "variable size" : offset(" + ") + " bytes"; }

 private:
  template <class T> static const char* word_type() {
    if constexpr (std::is_same_v<T, float>) return "f32";
    else if constexpr (std::is_same_v<T, std::int32_t>) return "i32";
    else if constexpr (std::is_same_v<T, std::uint8_t>) return "u8";
    else return "u32";
  }
  std::string offset(const char* plus = "+") const {
    if (variable_) return "…";
    std::string s = fmt::format("{}", constant_);
    for (const auto& [sym, k] : terms_) s += k == 1 ? fmt::format("{}{}", plus, sym) : fmt::format("{}{}·{}", plus, k, sym);
    return s;
  }
  void row(const char* n, std::string type, std::string meaning, std::size_t bytes) {
    rows_.push_back({offset(), std::move(type), n, std::move(meaning)});
    constant_ += bytes;
  }
  void add_term(const std::string& symbol, std::uint64_t k) {
    for (auto& [sym, c] : terms_)
      if (sym == symbol) {
        c += k;
        return;
      }
    terms_.emplace_back(symbol, k);
  }

  std::uint32_t version_;
  std::vector<std::array<std::string, 4>> rows_;
  std::uint64_t constant_ = 0;
  std::vector<std::pair<std::string, std::uint64_t>> terms_;
  bool variable_ = false;
};

// Writes "  name: value" lines; vectors show their count and first elements.
class DumpIo {
 public:
  explicit DumpIo(std::string indent = "  ") : indent_(std::move(indent)) {}
  std::string text;
  std::uint32_t version() const { return kFormatVersion; }
  template <class F> void since(std::uint32_t v, F&& f) { if (kFormatVersion >= v) f(); }
  template <class F> void until(std::uint32_t v, F&& f) { if (kFormatVersion <= v) f(); }
  void u8(const char* n, std::uint8_t& v, const char*) { line(n, fmt::format("{}", v)); }
  void u32(const char* n, std::uint32_t& v, const char*) { line(n, fmt::format("{}", v)); }
  void u64(const char* n, std::uint64_t& v, const char*) { line(n, fmt::format("{}", v)); }
  void i32(const char* n, std::int32_t& v, const char*) { line(n, fmt::format("{}", v)); }
  void f32(const char* n, float& v, const char*) { line(n, fmt::format("{}", v)); }
  void f64(const char* n, double& v, const char*) { line(n, fmt::format("{}", v)); }
  void boolean(const char* n, bool& v, const char*) { line(n, v ? "true" : "false"); }
  template <class T> void ranged(const char* n, T& v, T, T, const char*, const char*) { line(n, fmt::format("{}", +v)); }
  template <class E> void enumeration(const char* n, E& v, const char*) {
    line(n, fmt::format("{} ({})", static_cast<unsigned>(v), enum_value_name(v)));
  }
  template <std::size_t N> void floats(const char* n, std::array<float, N>& v, const char*) {
    line(n, fmt::format("[{}]", fmt::join(v, ", ")));
  }
  void string(const char* n, std::string& v, std::size_t, const char*) { line(n, fmt::format("\"{}\"", v)); }
  template <class T> void words(const char* n, std::vector<T>& v, const char*, const char*) { list(n, v); }
  template <class T> void image(const char* n, std::vector<T>& v, std::uint64_t, const char*, const char*) { list(n, v); }
  template <class E, class F> void items(const char* n, std::vector<E>& v, const char*, Element, F&& f, const char*) {
    line(n, fmt::format("{} elements", v.size()));
    for (std::size_t i = 0; i < v.size() && i < kShown; ++i) {
      DumpIo sub(indent_ + "    ");
      f(sub, v[i]);
      text += fmt::format("{}  [{}]\n{}", indent_, i, sub.text);
    }
    if (v.size() > kShown) text += fmt::format("{}  ... {} more\n", indent_, v.size() - kShown);
  }

 private:
  static constexpr std::size_t kShown = 4;
  void line(const char* n, const std::string& v) { text += fmt::format("{}{}: {}\n", indent_, n, v); }
  template <class T> void list(const char* n, const std::vector<T>& v) {
    const std::size_t k = std::min(v.size(), std::size_t{8});
    line(n, fmt::format("{} elements [{}{}]", v.size(), fmt::join(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), ", "),
                        v.size() > k ? ", ..." : ""));
  }
  std::string indent_;
};

template <class R>
std::string table_of(ChunkType type, std::uint32_t version) {
  DocIo io(version);
  R r{};
  fields(io, r);
  std::string name;
  for (const RecordKind& k : record_kinds())
    if (k.type == type) name = k.record;
  std::string fourcc = chunk_type_name(type);
  while (!fourcc.empty() && fourcc.back() == ' ') fourcc.pop_back();  // "END "
  return fmt::format("### {}: {} ({})\n\n{}", fourcc, name, io.size(), io.table());
}

template <class R>
std::string dump_of(const R& r) {
  DumpIo io;
  fields(io, const_cast<R&>(r));  // DumpIo only reads
  return fmt::format("{} {}\n{}", chunk_type_name(RecordChunk<R>::type), record_name(RecordChunk<R>::type), io.text);
}

constexpr std::string_view kRegionOpen = "<!-- generated: nbsim trace format ";
constexpr std::string_view kRegionClose = "<!-- end generated -->";
constexpr std::string_view kHeaderKeys = "HEAD-KEYS";  // the region of the header's known keys

}  // namespace

const std::vector<RecordKind>& record_kinds() {
  static const std::vector<RecordKind> kinds = {
      {ChunkType::Header, "Properties", 1},   {ChunkType::Scene, "SceneObjects", 1},
      {ChunkType::FrameBegin, "FrameBegin", 1}, {ChunkType::Draw, "DrawRecord", 1},
      {ChunkType::Depth, "DepthSnapshot", 1}, {ChunkType::Levels, "NBufferLevels", 1},
      {ChunkType::Truth, "GroundTruth", 1},   {ChunkType::FrameEnd, "FrameEnd", 1},
      {ChunkType::End, "EndMarker", 1},       {ChunkType::DrawBatch, "DrawBatch", 2},
      {ChunkType::Stencil, "StencilSnapshot", 2}, {ChunkType::Light, "Camera", 2},
  };
  return kinds;
}

std::string record_name(ChunkType type) {
  for (const RecordKind& k : record_kinds())
    if (k.type == type) return k.record;
  return "?";
}

std::string record_table(ChunkType type, std::uint32_t version) {
  const auto kind = std::find_if(record_kinds().begin(), record_kinds().end(), [&](const RecordKind& k) { return k.type == type; });
  if (kind == record_kinds().end() || version < kind->since || version < 1 || version > kFormatVersion) return {};
  switch (type) {
    case ChunkType::Header: return table_of<Properties>(type, version);
    case ChunkType::Scene: return table_of<SceneObjects>(type, version);
    case ChunkType::FrameBegin: return table_of<FrameBegin>(type, version);
    case ChunkType::Draw: return table_of<DrawRecord>(type, version);
    case ChunkType::Depth: return table_of<DepthSnapshot>(type, version);
    case ChunkType::Levels: return table_of<NBufferLevels>(type, version);
    case ChunkType::Truth: return table_of<GroundTruth>(type, version);
    case ChunkType::FrameEnd: return table_of<FrameEnd>(type, version);
    case ChunkType::End: return table_of<EndMarker>(type, version);
    case ChunkType::DrawBatch: return table_of<DrawBatch>(type, version);
    case ChunkType::Stencil: return table_of<StencilSnapshot>(type, version);
    case ChunkType::Light: return table_of<Camera>(type, version);
  }
  return {};
}

std::string record_tables(std::uint32_t version) {
  std::string s;
  for (const RecordKind& k : record_kinds()) {
    const std::string t = record_table(k.type, version);
    if (t.empty()) continue;
    if (!s.empty()) s += "\n";
    s += t;
  }
  s += "\n### HEAD keys\n\n";
  s += header_keys_table();
  for (const ChunkSpec& spec : technique_chunks()) {
    s += "\n";
    s += technique_table(spec);
  }
  return s;
}

namespace {

// The region starting at `at` (its opening marker): type name and version, and where its content
// and closing marker are.
struct Region {
  std::string type;
  std::uint32_t version = 0;
  std::size_t content = 0, close = 0, end = 0;
};

Region parse_region(std::string_view doc, std::size_t at) {
  Region r;
  const std::size_t eol = doc.find("-->", at);
  if (eol == std::string_view::npos) throw InputError(fmt::format("FORMAT.md: unterminated marker at byte {}", at));
  const std::string_view spec = doc.substr(at + kRegionOpen.size(), eol - at - kRegionOpen.size());
  const std::size_t space = spec.find(' ');
  if (space == std::string_view::npos) throw InputError(fmt::format("FORMAT.md: marker at byte {} lacks 'TYPE VERSION'", at));
  r.type = std::string(spec.substr(0, space));
  const std::string v(spec.substr(space + 1));
  r.version = static_cast<std::uint32_t>(std::strtoul(v.c_str(), nullptr, 10));
  r.content = eol + 3;
  if (r.content < doc.size() && doc[r.content] == '\n') ++r.content;
  r.close = doc.find(kRegionClose, r.content);
  if (r.close == std::string_view::npos) throw InputError(fmt::format("FORMAT.md: region at byte {} is not closed", at));
  r.end = r.close + kRegionClose.size();
  return r;
}

std::string table_for(const Region& r) {
  if (r.type == kHeaderKeys) return header_keys_table();
  for (const RecordKind& k : record_kinds())
    if (chunk_type_name(k.type) == r.type || (r.type == "END" && k.type == ChunkType::End)) {
      std::string t = record_table(k.type, r.version);
      if (!t.empty()) return t;
    }
  for (const ChunkSpec& spec : technique_chunks())  // a technique's chunk type, by its fourcc
    if (chunk_type_name(spec.type) == r.type && r.version >= 2) return technique_table(spec);
  throw InputError(fmt::format("FORMAT.md: no record {} in format version {}", r.type, r.version));
}

}  // namespace

std::string refresh_format_doc(std::string_view doc) {
  std::string out;
  std::size_t pos = 0;
  for (std::size_t at; (at = doc.find(kRegionOpen, pos)) != std::string_view::npos;) {
    const Region r = parse_region(doc, at);
    out += doc.substr(pos, r.content - pos);
    out += table_for(r);
    out += doc.substr(r.close, r.end - r.close);
    pos = r.end;
  }
  out += doc.substr(pos);
  return out;
}

std::vector<std::string> format_doc_regions(std::string_view doc) {
  std::vector<std::string> found;
  std::size_t pos = 0;
  for (std::size_t at; (at = doc.find(kRegionOpen, pos)) != std::string_view::npos;) {
    const Region r = parse_region(doc, at);
    found.push_back(fmt::format("{} {}", r.type, r.version));
    pos = r.end;
  }
  return found;
}

std::string dump_record(const Properties& r) { return dump_of(r); }
std::string dump_record(const SceneObjects& r) { return dump_of(r); }
std::string dump_record(const FrameBegin& r) { return dump_of(r); }
std::string dump_record(const DrawRecord& r) { return dump_of(r); }
std::string dump_record(const DepthSnapshot& r) { return dump_of(r); }
std::string dump_record(const NBufferLevels& r) { return dump_of(r); }
std::string dump_record(const GroundTruth& r) { return dump_of(r); }
std::string dump_record(const FrameEnd& r) { return dump_of(r); }
std::string dump_record(const StencilSnapshot& r) { return dump_of(r); }
std::string dump_record(const Camera& r) { return dump_of(r); }

std::string dump_frame(const scene::Frame& f) {
  std::string s = dump_record(f.begin);
  for (const DrawRecord& d : f.draws) s += dump_record(d);
  for (const DepthSnapshot& d : f.depths) s += dump_record(d);
  for (const NBufferLevels& l : f.levels) s += dump_record(l);
  for (const StencilSnapshot& st : f.stencils) s += dump_record(st);
  if (f.light) s += dump_record(*f.light);
  for (const TechniqueRecord& t : f.technique_records) s += dump_technique(t);
  if (f.truth) s += dump_record(*f.truth);
  s += dump_record(f.end);
  return s;
}

}  // namespace nbsim::trace
