// JSON the user gives (config files, sweep files, --set values): read and parsed within stated
// limits, and echoed into messages only as bounded excerpts. Used by the config schema
// (schema.h), `nbsim explore`'s sweep files and the --config option. docs/limits.md lists
// every limit here with the message given when it is exceeded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace nbsim::config {

// Tunable. Deepest nesting of objects and arrays in a JSON input (the top-level value is depth 1).
// Configs nest 2 deep and sweep files 4; 64 leaves room while keeping every recursive walk of a
// parsed value (dump, copy, comparison) far from the end of the stack.
inline constexpr int kMaxJsonDepth = 64;
// Tunable. Largest config or sweep file read, in bytes (the sample sweeps are under 2 KB).
inline constexpr std::uintmax_t kMaxJsonFileBytes = std::uintmax_t{64} << 20;
// Tunable. Characters of a user's value, key or text echoed into a message before it is cut.
inline constexpr std::size_t kMaxEchoChars = 120;

// Parses `text` as one JSON value (`comments`: allow // and /* */ comments). Throws InputError
// starting with `origin` when the text is not valid JSON (which includes text that is not UTF-8),
// holds a NUL byte, nests deeper than kMaxJsonDepth, or gives one key twice in an object.
nlohmann::json parse_input(std::string_view text, const std::string& origin, bool comments = false);
nlohmann::ordered_json parse_input_ordered(std::string_view text, const std::string& origin, bool comments = false);

// The whole file as text. Throws InputError naming `what` and the file when it cannot be read, is
// a directory, or is larger than kMaxJsonFileBytes.
std::string read_input_file(const std::string& path, const std::string& what);

// A value as compact JSON of at most about kMaxEchoChars characters ("..." marks a cut), safe at
// any depth and for strings that are not UTF-8 (such bytes become U+FFFD).
std::string excerpt(const nlohmann::json& v);
std::string excerpt(const nlohmann::ordered_json& v);
// Text cut to `limit` bytes; a cut says how long the text was.
std::string excerpt_text(std::string_view text, std::size_t limit = kMaxEchoChars);

// True when `text` is valid UTF-8; otherwise `bad_at` (when given) is the offset of the first bad byte.
bool valid_utf8(std::string_view text, std::size_t* bad_at = nullptr);

}  // namespace nbsim::config
