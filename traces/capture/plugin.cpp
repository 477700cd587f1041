// Plug-in options and rows; see plugin.h.
#include "traces/capture/plugin.h"

#include <fmt/format.h>

#include <sstream>

#include <algorithm>
#include <charconv>

#include "model/common/error.h"

namespace nbsim::capture {

namespace {

bool parse_integer(const std::string& s, std::int64_t& out) {
  const char* end = s.data() + s.size();
  const auto [p, ec] = std::from_chars(s.data(), end, out);
  return !s.empty() && ec == std::errc() && p == end;
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

}  // namespace

OptionSpec integer_option(std::string name, std::string help, std::int64_t default_value, std::int64_t min, std::int64_t max) {
  return OptionSpec{std::move(name), std::move(help), std::to_string(default_value), OptionSpec::Kind::Integer, min, max, {}};
}

OptionSpec choice_option(std::string name, std::string help, std::string default_value, std::vector<std::string> choices) {
  return OptionSpec{std::move(name), std::move(help), std::move(default_value), OptionSpec::Kind::Choice, 0, 0, std::move(choices)};
}

OptionSpec text_option(std::string name, std::string help, std::string default_value) {
  return OptionSpec{std::move(name), std::move(help), std::move(default_value), OptionSpec::Kind::Text, 0, 0, {}};
}

OptionSpec levels_every_spec(const std::string& what) {
  return integer_option("levels-every", "Record " + what + " every K-th frame (0: never)", 10, 0, 1000000);
}

std::string option_problem(const OptionSpec& spec, const std::string& value) {
  switch (spec.kind) {
    case OptionSpec::Kind::Integer: {
      std::int64_t v = 0;
      if (!parse_integer(value, v)) return fmt::format("--{} '{}' is not an integer", spec.name, value);
      if (v < spec.min || v > spec.max)
        return fmt::format("--{} {} is out of range ({} to {})", spec.name, value, spec.min, spec.max);
      return {};
    }
    case OptionSpec::Kind::Text:
      if (value.empty() || value.size() > 4096 ||
          std::any_of(value.begin(), value.end(), [](char c) { return static_cast<unsigned char>(c) <= ' '; }))
        return fmt::format("--{} '{}' is not one word of at most 4096 characters", spec.name, value.substr(0, 120));
      return {};
    case OptionSpec::Kind::Choice:
      if (std::find(spec.choices.begin(), spec.choices.end(), value) == spec.choices.end())
        return fmt::format("--{} '{}' is not one of {}", spec.name, value, joined(spec.choices));
      return {};
  }
  return fmt::format("--{} has an unknown kind", spec.name);
}

std::string OptionValues::text(const OptionSpec& spec) const {
  const auto it = values_.find(spec.name);
  const std::string& v = it == values_.end() ? spec.default_value : it->second;
  if (const std::string problem = option_problem(spec, v); !problem.empty()) throw InputError(problem);
  return v;
}

std::int64_t OptionValues::integer(const OptionSpec& spec) const {
  NBSIM_CHECK(spec.kind == OptionSpec::Kind::Integer, "integer() of a non-integer option " + spec.name);
  std::int64_t v = 0;
  parse_integer(text(spec), v);
  return v;
}

OptionSpec covering_option(std::vector<std::string> kinds) {
  return choice_option("covering",
                       "How an N-buffer query covers a rectangle: paper (the paper's five cases, Fig. 3), corners (squares of side "
                       "2^floor(log2 max(w,h)) at its corners, nbsim's before the paper's), one (a single square)",
                       "paper", std::move(kinds));
}

const OptionSpec& align_option() {
  static const OptionSpec spec = choice_option(
      "align", "Where a square taller than the rectangle sits: top (flush with its top edge, the paper's) or bottom", "top",
      {"top", "bottom"});
  return spec;
}

CoveringSpec read_covering(const OptionValues& values, const OptionSpec& covering) {
  return {*parse_covering_kind(values.text(covering)), *parse_covering_align(values.text(align_option()))};
}

std::pair<std::string, std::string> covering_property(const CoveringSpec& spec) {
  return {std::string(kCoveringProperty), covering_name(spec)};
}

double parse_real(const std::string& text, const std::string& what, double lo, double hi) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(v >= lo && v <= hi)) throw InputError(fmt::format("{} '{}' is not a number in [{}, {}]", what, text, lo, hi));
  return v;
}

std::vector<std::string> split_list(const std::string& text, char separator) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, separator);) out.push_back(item);
  return out;
}

const OptionSpec& seed_option() {
  static const OptionSpec seed{"seed", "Seed of the scene and the camera path", "1", OptionSpec::Kind::Integer, 0, 4294967295LL, {}};
  return seed;
}

void check_options_declared(const OptionValues& values, const std::vector<const PluginInfo*>& chosen) {
  for (const auto& [name, value] : values.values()) {
    bool declared = false;
    std::vector<std::string> accepted, owners;
    for (const PluginInfo* p : chosen) {
      owners.push_back(p->name);
      for (const OptionSpec& s : p->options) {
        declared = declared || s.name == name;
        if (std::find(accepted.begin(), accepted.end(), "--" + s.name) == accepted.end()) accepted.push_back("--" + s.name);
      }
    }
    if (!declared)
      throw InputError(fmt::format("option --{} is not an option of {}; they accept: {}", name, joined(owners),
                                   accepted.empty() ? std::string("no options") : joined(accepted)));
  }
}

void unknown_row(std::string_view kind, std::string_view name, const std::string& known) {
  throw InputError(fmt::format("unknown {} '{}': known {}s are {}", kind, name, kind, known));
}

}  // namespace nbsim::capture
