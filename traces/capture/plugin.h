// The capture's plug-ins (techniques, scenes, camera paths) are rows of one table each: a name, a
// one-line description and the options the plug-in reads, declared once. The command line offers
// every declared option as --NAME, `nbsim capture --help` lists the rows, and a capture reads the
// chosen plug-ins' options from one OptionValues bag. An option that is set but that none of the
// chosen plug-ins declares is an error, so a typo never runs the default experiment silently.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "model/nbuffer/covering.h"

namespace nbsim::capture {

struct OptionSpec {
  enum class Kind : std::uint8_t { Integer, Choice, Text };  // Text: any word, checked by its reader
  std::string name;  // as on the command line without the dashes: "levels-every" is --levels-every
  std::string help;
  std::string default_value;
  Kind kind = Kind::Integer;
  std::int64_t min = 0, max = 0;     // Integer: the inclusive range
  std::vector<std::string> choices;  // Choice: the allowed values
};

// The three kinds of spec, written the same way by every technique and scene.
OptionSpec integer_option(std::string name, std::string help, std::int64_t default_value, std::int64_t min, std::int64_t max);
OptionSpec choice_option(std::string name, std::string help, std::string default_value, std::vector<std::string> choices);
OptionSpec text_option(std::string name, std::string help, std::string default_value);
// --levels-every: record `what` (e.g. "the GLSL N-buffer levels") every K-th frame, 0 never; default 10.
OptionSpec levels_every_spec(const std::string& what);

// Why `value` is not a valid value of `spec` (a sentence naming the option), or empty when it is.
std::string option_problem(const OptionSpec& spec, const std::string& value);

// The options a capture was given, by name; unset ones take their spec's default.
class OptionValues {
 public:
  OptionValues() = default;
  OptionValues(std::initializer_list<std::pair<const std::string, std::string>> values) : values_(values) {}

  void set(const std::string& name, std::string value) { values_[name] = std::move(value); }
  bool has(const std::string& name) const { return values_.count(name) != 0; }
  const std::map<std::string, std::string>& values() const noexcept { return values_; }

  // The value of `spec` (its default when unset); throws InputError when it is not valid.
  std::string text(const OptionSpec& spec) const;
  std::int64_t integer(const OptionSpec& spec) const;

 private:
  std::map<std::string, std::string> values_;
};

// --covering and --align: how a technique's GL queries cover a rectangle with N-buffer squares
// (model/nbuffer/covering.h); default paper and top, the paper's. `kinds`: the coverings the
// technique's queries offer. The capture records them as the header's nbuffer_covering
// (kCoveringProperty, "paper/top"), which the model's replay takes by default.
OptionSpec covering_option(std::vector<std::string> kinds = {"paper", "corners", "one"});
const OptionSpec& align_option();
// The covering given by the two options (their specs' defaults when unset).
CoveringSpec read_covering(const OptionValues& values, const OptionSpec& covering);
// The header property of a covering: {kCoveringProperty, "paper/top"}.
std::pair<std::string, std::string> covering_property(const CoveringSpec& spec);

// A Text option's number: `text` whole as a double in [lo, hi], or an InputError
// "<what> '<text>' is not a number in [lo, hi]" (`what` names the option, e.g. "--box-at").
double parse_real(const std::string& text, const std::string& what, double lo, double hi);
// A Text option's list: the items between `separator`s (empty items kept, none for "").
std::vector<std::string> split_list(const std::string& text, char separator);

// --seed: one option that the scenes and the camera paths that are random share, so that one seed
// fixes the scene and the path together.
const OptionSpec& seed_option();

// What every registry row starts with.
struct PluginInfo {
  std::string name;
  std::string description;  // one line, for --help
  std::vector<OptionSpec> options;
};

// Throws InputError when `values` holds an option that none of `chosen` declares, naming it, the
// chosen plug-ins and the options they accept.
void check_options_declared(const OptionValues& values, const std::vector<const PluginInfo*>& chosen);

// The row named `name` of `table` (rows with a PluginInfo `info`); throws InputError naming the
// kind of plug-in ("technique", "scene", "camera path") and listing the known names.
template <class Row>
const Row& find_row(const std::vector<Row>& table, std::string_view name, std::string_view kind);

// "a, b, c": the names of a table, for messages and help.
template <class Row>
std::string row_names(const std::vector<Row>& table) {
  std::string out;
  for (const Row& r : table) out += (out.empty() ? "" : ", ") + r.info.name;
  return out;
}

[[noreturn]] void unknown_row(std::string_view kind, std::string_view name, const std::string& known);

template <class Row>
const Row& find_row(const std::vector<Row>& table, std::string_view name, std::string_view kind) {
  for (const Row& r : table)
    if (r.info.name == name) return r;
  unknown_row(kind, name, row_names(table));
}

}  // namespace nbsim::capture
