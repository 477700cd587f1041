// The registry of technique chunk types and their generic codec; see technique_chunks.h.
#include "traces/format/technique_chunks.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <mutex>
#include <set>
#include <type_traits>
#include <variant>

#include "model/common/error.h"
#include "traces/format/bytes.h"
#include "traces/format/codec.h"

namespace nbsim::trace {

namespace {

constexpr std::array<const char*, 9> kKindNames = {"u32", "i32", "u64", "f32", "f64", "string", "vec<f32>", "vec<u32>", "vec<i32>"};
constexpr std::size_t kMaxStringBytes = 64 * 1024;

const char* kind_name(FieldKind k) { return kKindNames[static_cast<std::size_t>(k)]; }

struct Registry {
  std::mutex mutex;
  std::vector<ChunkSpec> specs;
};

// What the techniques of the registration list add to the format, in the list's order.
std::vector<TechniqueFormat> built_in_formats() {
#define NBSIM_TECHNIQUE_FORMAT(name) name##_format(),
  return {NBSIM_EACH_TECHNIQUE(NBSIM_TECHNIQUE_FORMAT)};
#undef NBSIM_TECHNIQUE_FORMAT
}

// Their chunk types, registered before anything else so that every reader decodes them (a
// technique's own test types register later, at run time).
std::vector<ChunkSpec> built_in_chunks() {
  std::vector<ChunkSpec> chunks;
  for (TechniqueFormat& f : built_in_formats())
    for (ChunkSpec& c : f.chunks) chunks.push_back(std::move(c));
  return chunks;
}

// Their header keys, in the same order.
std::vector<HeaderKeySpec> built_in_header_keys() {
  std::vector<HeaderKeySpec> keys;
  for (TechniqueFormat& f : built_in_formats())
    for (HeaderKeySpec& k : f.header_keys) keys.push_back(std::move(k));
  return keys;
}

Registry& registry() {
  static Registry r{{}, built_in_chunks()};
  return r;
}

// The variant alternative each kind holds.
bool holds(FieldKind k, const TechniqueField& f) {
  switch (k) {
    case FieldKind::U32:
    case FieldKind::U64: return std::holds_alternative<std::uint64_t>(f.value);
    case FieldKind::I32: return std::holds_alternative<std::int64_t>(f.value);
    case FieldKind::F32:
    case FieldKind::F64: return std::holds_alternative<double>(f.value);
    case FieldKind::String: return std::holds_alternative<std::string>(f.value);
    case FieldKind::VecF32: return std::holds_alternative<std::vector<float>>(f.value);
    case FieldKind::VecU32: return std::holds_alternative<std::vector<std::uint32_t>>(f.value);
    case FieldKind::VecI32: return std::holds_alternative<std::vector<std::int32_t>>(f.value);
  }
  return false;
}

}  // namespace

void register_technique_chunk(ChunkSpec spec) {
  NBSIM_CHECK(!is_known_chunk_type(spec.type), fmt::format("technique chunk {} reuses a core chunk type", chunk_type_name(spec.type)));
  NBSIM_CHECK(chunk_type_name(spec.type).size() == 4, fmt::format("technique chunk type {} is not four printable characters",
                                                                  chunk_type_name(spec.type)));
  NBSIM_CHECK(!spec.fields.empty(), fmt::format("technique chunk {} describes no fields", chunk_type_name(spec.type)));
  std::set<std::string> names;
  for (const FieldSpec& f : spec.fields)
    NBSIM_CHECK(names.insert(f.name).second && !f.name.empty(),
                fmt::format("technique chunk {}: field name '{}' empty or repeated", chunk_type_name(spec.type), f.name));
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  for (const ChunkSpec& s : r.specs)
    NBSIM_CHECK(s.type != spec.type, fmt::format("technique chunk {} registered twice", chunk_type_name(spec.type)));
  r.specs.push_back(std::move(spec));
}

const ChunkSpec* find_technique_chunk(std::uint32_t type) {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  for (const ChunkSpec& s : r.specs)
    if (s.type == type) return &s;
  return nullptr;
}

const std::vector<ChunkSpec>& technique_chunks() { return registry().specs; }

std::vector<std::uint8_t> encode(const TechniqueRecord& record) {
  if (!record.decoded) return record.payload;
  const ChunkSpec* spec = find_technique_chunk(record.type);
  NBSIM_CHECK(spec != nullptr, fmt::format("encoding technique chunk {}, which is not registered", chunk_type_name(record.type)));
  NBSIM_CHECK(record.fields.size() == spec->fields.size(),
              fmt::format("technique chunk {}: {} fields, its description has {}", spec->record, record.fields.size(),
                          spec->fields.size()));
  NBSIM_CHECK(!spec->rule || spec->rule(record).empty(),
              fmt::format("technique chunk {} breaks its rule: {}", spec->record, spec->rule ? spec->rule(record) : ""));
  bytes::Out o;
  for (std::size_t i = 0; i < spec->fields.size(); ++i) {
    const FieldSpec& fs = spec->fields[i];
    const TechniqueField& f = record.fields[i];
    NBSIM_CHECK(f.name == fs.name && holds(fs.kind, f),
                fmt::format("technique chunk {}: field {} is '{}', its description says '{}' of type {}", spec->record, i,
                            f.name, fs.name, kind_name(fs.kind)));
    switch (fs.kind) {
      case FieldKind::U32: o.u32(static_cast<std::uint32_t>(std::get<std::uint64_t>(f.value))); break;
      case FieldKind::U64: o.u64(std::get<std::uint64_t>(f.value)); break;
      case FieldKind::I32: o.i32(static_cast<std::int32_t>(std::get<std::int64_t>(f.value))); break;
      case FieldKind::F32: o.f32(static_cast<float>(std::get<double>(f.value))); break;
      case FieldKind::F64: o.f64(std::get<double>(f.value)); break;
      case FieldKind::String: o.str(std::get<std::string>(f.value)); break;
      case FieldKind::VecF32: o.counted_words(std::get<std::vector<float>>(f.value)); break;
      case FieldKind::VecU32: o.counted_words(std::get<std::vector<std::uint32_t>>(f.value)); break;
      case FieldKind::VecI32: o.counted_words(std::get<std::vector<std::int32_t>>(f.value)); break;
    }
  }
  return o.take();
}

TechniqueRecord decode_technique(std::uint32_t type, std::span<const std::uint8_t> payload) {
  TechniqueRecord r;
  r.type = type;
  const ChunkSpec* spec = find_technique_chunk(type);
  if (!spec) {  // kept raw
    r.payload.assign(payload.begin(), payload.end());
    return r;
  }
  // A payload of another layout (a trace captured by a build whose description of this type had
  // other fields) is refused naming the type and where to see the fields this build reads.
  try {
    bytes::In in(payload);
    for (const FieldSpec& fs : spec->fields) {
      TechniqueField f;
      f.name = fs.name;
      const char* n = fs.name.c_str();
      switch (fs.kind) {
        case FieldKind::U32: f.value = std::uint64_t{in.u32(n)}; break;
        case FieldKind::U64: f.value = in.u64(n); break;
        case FieldKind::I32: f.value = std::int64_t{in.i32(n)}; break;
        case FieldKind::F32: f.value = static_cast<double>(in.f32(n)); break;
        case FieldKind::F64: f.value = in.f64(n); break;
        case FieldKind::String: f.value = in.str(kMaxStringBytes, n); break;
        case FieldKind::VecF32: in.counted_words(f.value.emplace<std::vector<float>>(), n); break;
        case FieldKind::VecU32: in.counted_words(f.value.emplace<std::vector<std::uint32_t>>(), n); break;
        case FieldKind::VecI32: in.counted_words(f.value.emplace<std::vector<std::int32_t>>(), n); break;
      }
      r.fields.push_back(std::move(f));
    }
    in.finish();
  } catch (const InputError& e) {
    throw InputError(fmt::format("technique chunk {} ({}, technique {}) does not have this nbsim's layout: {} ({} fields of {} read; "
                                 "`nbsim trace format {}` lists the fields this nbsim reads)",
                                 chunk_type_name(type), spec->record, spec->technique, e.what(), r.fields.size(), spec->fields.size(),
                                 chunk_type_name(type)));
  }
  r.decoded = true;
  if (spec->rule)
    if (const std::string broken = spec->rule(r); !broken.empty()) throw InputError(fmt::format("{}: {}", spec->record, broken));
  return r;
}

std::string technique_table(const ChunkSpec& spec) {
  std::string t = fmt::format("### {}: {} (technique {})\n\n| # | Type | Field | Meaning |\n|---|------|-------|---------|\n",
                              chunk_type_name(spec.type), spec.record, spec.technique);
  for (std::size_t i = 0; i < spec.fields.size(); ++i)
    t += fmt::format("| {} | {} | `{}` | {} |\n", i + 1, kind_name(spec.fields[i].kind), spec.fields[i].name,
                     spec.fields[i].meaning);
  return t;
}

const TechniqueField* find_field(const TechniqueRecord& record, std::string_view name) {
  for (const TechniqueField& f : record.fields)
    if (f.name == name) return &f;
  return nullptr;
}

std::string vector_lengths_problem(const TechniqueRecord& record, std::uint64_t count, std::initializer_list<std::string_view> scalars,
                                   std::string_view one_a) {
  for (const TechniqueField& f : record.fields) {
    if (std::find(scalars.begin(), scalars.end(), f.name) != scalars.end()) continue;
    const std::size_t n = std::visit(
        [](const auto& v) -> std::size_t {
          if constexpr (requires { v.size(); } && !std::is_same_v<std::decay_t<decltype(v)>, std::string>) return v.size();
          return 0;
        },
        f.value);
    if (n != count) return fmt::format("field '{}' has {} elements, but count is {} (one a {})", f.name, n, count, one_a);
  }
  return {};
}

std::string dump_technique(const TechniqueRecord& record) {
  const ChunkSpec* spec = find_technique_chunk(record.type);
  std::string s = fmt::format("{} {}\n", chunk_type_name(record.type), spec ? spec->record : "(unregistered technique chunk)");
  if (!record.decoded) return s + fmt::format("  payload: {} bytes (raw)\n", record.payload.size());
  for (const TechniqueField& f : record.fields) {
    std::string v = std::visit(
        [](const auto& x) -> std::string {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, std::string>) return fmt::format("\"{}\"", x);
          else if constexpr (std::is_arithmetic_v<T>) return fmt::format("{}", x);
          else {
            const std::size_t k = std::min(x.size(), std::size_t{8});
            return fmt::format("{} elements [{}{}]", x.size(), fmt::join(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(k), ", "),
                               x.size() > k ? ", ..." : "");
          }
        },
        f.value);
    s += fmt::format("  {}: {}\n", f.name, v);
  }
  return s;
}

const std::vector<HeaderKeySpec>& technique_header_keys() {
  static const std::vector<HeaderKeySpec> keys = built_in_header_keys();
  return keys;
}

namespace {

std::string number_text(double v) { return fmt::format("{}", v); }

}  // namespace

HeaderKeySpec text_key(std::string technique, std::string name, std::string example, std::string meaning) {
  HeaderKeySpec k;
  k.technique = std::move(technique), k.name = std::move(name), k.values = "text";
  k.example = std::move(example), k.meaning = std::move(meaning);
  return k;
}

HeaderKeySpec whole_key(std::string technique, std::string name, std::uint64_t lo, std::uint64_t hi, std::string example,
                        std::string meaning) {
  HeaderKeySpec k = text_key(std::move(technique), std::move(name), std::move(example), std::move(meaning));
  k.kind = HeaderKeySpec::Kind::Whole;
  k.min = lo, k.max = hi;
  k.values = fmt::format("a whole number, {} .. {}", lo, hi);
  return k;
}

HeaderKeySpec real_key(std::string technique, std::string name, double lo, double hi, bool above_lo, std::string example,
                       std::string meaning) {
  HeaderKeySpec k = text_key(std::move(technique), std::move(name), std::move(example), std::move(meaning));
  k.kind = HeaderKeySpec::Kind::Real;
  k.lo = lo, k.hi = hi, k.above_lo = above_lo;
  k.values = above_lo ? fmt::format("a number above {}, at most {}", number_text(lo), number_text(hi))
                      : fmt::format("a number, {} .. {}", number_text(lo), number_text(hi));
  return k;
}

HeaderKeySpec choice_key(std::string technique, std::string name, std::vector<std::string> choices, std::string example,
                         std::string meaning) {
  HeaderKeySpec k = text_key(std::move(technique), std::move(name), std::move(example), std::move(meaning));
  k.kind = HeaderKeySpec::Kind::OneOf;
  k.values = "one of " + fmt::format("{}", fmt::join(choices, ", "));
  k.choices = std::move(choices);
  return k;
}

HeaderKeySpec custom_key(std::string technique, std::string name, bool (*valid)(std::string_view), std::string values,
                         std::string example, std::string meaning) {
  HeaderKeySpec k = text_key(std::move(technique), std::move(name), std::move(example), std::move(meaning));
  k.kind = HeaderKeySpec::Kind::Custom;
  k.custom = valid;
  k.values = std::move(values);
  return k;
}

}  // namespace nbsim::trace
