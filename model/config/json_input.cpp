// User-given JSON within limits; see json_input.h.
#include "model/config/json_input.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <system_error>
#include <vector>

#include "model/common/error.h"

namespace nbsim::config {

namespace {

constexpr auto kReplace = nlohmann::json::error_handler_t::replace;

// Values nested deeper than this are shown as {...} or [...] in an excerpt.
constexpr int kExcerptDepth = 8;

template <class J>
void excerpt_into(const J& v, std::string& out, int depth) {
  if (out.size() > kMaxEchoChars) return;
  if (v.is_object() || v.is_array()) {
    const bool object = v.is_object();
    if (depth >= kExcerptDepth && !v.empty()) {
      out += object ? "{...}" : "[...]";
      return;
    }
    out += object ? '{' : '[';
    bool first = true;
    for (auto it = v.begin(); it != v.end() && out.size() <= kMaxEchoChars; ++it) {
      if (!first) out += ',';
      first = false;
      if (object) out += J(it.key().substr(0, kMaxEchoChars + 1)).dump(-1, ' ', false, kReplace) + ':';
      excerpt_into(it.value(), out, depth + 1);
    }
    out += object ? '}' : ']';
  } else if (v.is_string()) {
    out += J(v.template get_ref<const std::string&>().substr(0, kMaxEchoChars + 1)).dump(-1, ' ', false, kReplace);
  } else {
    out += v.dump();
  }
}

template <class J>
std::string excerpt_of(const J& v) {
  std::string out;
  excerpt_into(v, out, 0);
  if (out.size() > kMaxEchoChars) out = out.substr(0, kMaxEchoChars) + "...";
  return out;
}

template <class J>
J parse_limited(std::string_view text, const std::string& origin, bool comments) {
  if (const auto nul = text.find('\0'); nul != std::string_view::npos)
    throw InputError(fmt::format("{} holds a NUL byte at offset {}: JSON text has none", origin, nul));
  std::vector<std::set<std::string>> keys;  // the keys met so far in each open object
  const typename J::parser_callback_t check = [&](int depth, nlohmann::json::parse_event_t event, J& parsed) {
    using E = nlohmann::json::parse_event_t;
    switch (event) {
      case E::object_start:
      case E::array_start:
        // `depth` counts the containers already open around this one.
        if (depth + 1 > kMaxJsonDepth)
          throw InputError(fmt::format("{} nests objects and arrays deeper than {} levels (the limit)", origin, kMaxJsonDepth));
        if (event == E::object_start) keys.emplace_back();
        break;
      case E::object_end: keys.pop_back(); break;
      case E::key:
        if (!keys.back().insert(parsed.template get<std::string>()).second)
          throw InputError(fmt::format("{} gives the key {} twice in one object", origin, excerpt_of(parsed)));
        break;
      default: break;
    }
    return true;
  };
  try {
    return J::parse(text.begin(), text.end(), check, true, comments);
  } catch (const nlohmann::json::exception& e) {
    // A syntax error (its message names line and column; its "last read" part can be long), or a
    // number out of range such as 1E999 (out_of_range.406).
    throw InputError(fmt::format("{} is not valid JSON: {}", origin, excerpt_text(e.what(), 2 * kMaxEchoChars)));
  }
}

}  // namespace

nlohmann::json parse_input(std::string_view text, const std::string& origin, bool comments) {
  return parse_limited<nlohmann::json>(text, origin, comments);
}

nlohmann::ordered_json parse_input_ordered(std::string_view text, const std::string& origin, bool comments) {
  return parse_limited<nlohmann::ordered_json>(text, origin, comments);
}

std::string read_input_file(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(fmt::format("{} '{}' is a directory, not a file", what, excerpt_text(path, 1024)));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{} '{}' cannot be read", what, excerpt_text(path, 1024)));
  // Read in pieces up to one byte past the limit: works for pipes and devices, which have no size.
  std::string text;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    text.append(buf.data(), static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxJsonFileBytes)
      throw InputError(fmt::format("{} '{}' is larger than {} MiB (the limit)", what, excerpt_text(path, 1024), kMaxJsonFileBytes >> 20));
  }
  if (in.bad()) throw InputError(fmt::format("{} '{}' cannot be read", what, excerpt_text(path, 1024)));
  return text;
}

std::string excerpt(const nlohmann::json& v) { return excerpt_of(v); }
std::string excerpt(const nlohmann::ordered_json& v) { return excerpt_of(v); }

std::string excerpt_text(std::string_view text, std::size_t limit) {
  if (text.size() <= limit) return std::string(text);
  return fmt::format("{}... ({} bytes)", text.substr(0, limit), text.size());
}

bool valid_utf8(std::string_view text, std::size_t* bad_at) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned c = s[i];
    std::size_t len = 0;
    unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte (no overlongs, no surrogates)
    if (c < 0x80) len = 1;
    else if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c >= 0xE0 && c <= 0xEF) len = 3, lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
    else if (c >= 0xF0 && c <= 0xF4) len = 4, lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
    bool ok = len > 0 && i + len <= n;
    for (std::size_t k = 1; ok && k < len; ++k) ok = k == 1 ? (s[i + 1] >= lo && s[i + 1] <= hi) : (s[i + k] >= 0x80 && s[i + k] <= 0xBF);
    if (!ok) {
      if (bad_at) *bad_at = i;
      return false;
    }
    i += len;
  }
  return true;
}

}  // namespace nbsim::config
