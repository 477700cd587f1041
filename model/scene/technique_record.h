// Reading a technique's own record (scene::TechniqueRecord, decoded by the trace reader) in a frame
// program: the frame's one record of a type and its fields by name, each miss an InputError naming
// the frame, the record and the field (a damaged trace). Used by the particles and shadows programs.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <string_view>
#include <vector>

#include "model/common/error.h"
#include "model/scene/frame.h"

namespace nbsim::scene {

// A technique record's type from its four characters, as the trace format spells them
// (traces/format/records.h fourcc): the first character in the lowest byte.
constexpr std::uint32_t record_type(const char (&s)[5]) noexcept {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(s[0])) | static_cast<std::uint32_t>(static_cast<unsigned char>(s[1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[2])) << 16 | static_cast<std::uint32_t>(static_cast<unsigned char>(s[3])) << 24;
}

// The frame's one decoded record of `type`; `label` names it ("ParticleCulling (PRTC)") and
// `why_needed` ends the message when it is missing.
inline const TechniqueRecord& single_record(const Frame& f, std::uint32_t type, std::string_view label,
                                            std::string_view why_needed) {
  const std::uint64_t frame = f.begin.frame;
  const TechniqueRecord* rec = nullptr;
  for (const TechniqueRecord& r : f.technique_records)
    if (r.type == type) {
      if (rec) throw InputError(fmt::format("frame {}: more than one {} record", frame, label));
      rec = &r;
    }
  if (!rec) throw InputError(fmt::format("frame {}: no {} record: {}", frame, label, why_needed));
  if (!rec->decoded) throw InputError(fmt::format("frame {}: the {} record was not decoded", frame, label));
  return *rec;
}

// The vector field `name` of a record (`label`: its name in messages, "ParticleCulling").
template <class T>
const std::vector<T>& record_field(const TechniqueRecord& rec, std::string_view name, std::string_view label, std::uint64_t frame) {
  for (const TechniqueField& f : rec.fields)
    if (f.name == name) {
      if (const auto* v = std::get_if<std::vector<T>>(&f.value)) return *v;
      throw InputError(fmt::format("frame {}: the {} record's field '{}' has the wrong type", frame, label, name));
    }
  throw InputError(fmt::format("frame {}: the {} record has no field '{}'", frame, label, name));
}

// A scalar field (u32 fields decode as uint64_t, i32 as int64_t, f64 as double, strings as std::string).
template <class T>
T record_scalar(const TechniqueRecord& rec, std::string_view name, std::string_view label, std::uint64_t frame) {
  for (const TechniqueField& f : rec.fields)
    if (f.name == name) {
      if (const T* v = std::get_if<T>(&f.value)) return *v;
      throw InputError(fmt::format("frame {}: the {} record's field '{}' has the wrong type", frame, label, name));
    }
  throw InputError(fmt::format("frame {}: the {} record has no field '{}'", frame, label, name));
}

}  // namespace nbsim::scene
