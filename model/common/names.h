// Names of small enums whose values are 0..N-1, kept in one table per enum: to_string and parse
// from the same table, so that the two never disagree (run outputs and config keys use the names).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace nbsim {

// The name of `e`, or "?" for a value outside the table.
template <class Enum, std::size_t N>
constexpr std::string_view enum_name(const std::array<std::string_view, N>& names, Enum e) noexcept {
  const auto i = static_cast<std::size_t>(e);
  return i < N ? names[i] : "?";
}

// The value named `s`, or nothing when the table has no such name.
template <class Enum, std::size_t N>
constexpr std::optional<Enum> parse_enum_name(const std::array<std::string_view, N>& names, std::string_view s) noexcept {
  for (std::size_t i = 0; i < N; ++i)
    if (names[i] == s) return static_cast<Enum>(i);
  return std::nullopt;
}

// Every name of the table, for a config key's allowed labels or a command-line option's choices.
template <std::size_t N>
std::vector<std::string> name_list(const std::array<std::string_view, N>& names) {
  return {names.begin(), names.end()};
}

}  // namespace nbsim
