// Configuration schema; see schema.h.
#include "model/config/schema.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "model/common/error.h"
#include "model/config/json_input.h"

namespace nbsim::config {

namespace {

// Tunable. Longest key an unknown key is compared with for a "did you mean" hint: declared keys
// are under 64 characters, and the edit distance below is quadratic in the lengths.
constexpr std::size_t kMaxHintKeyChars = 256;
// Hints are given only for keys this close (edit distance below it).
constexpr std::size_t kHintDistance = 4;

// Edit distance, for "did you mean" hints on unknown keys.
std::size_t distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

void Schema::add_entry(Entry e) {
  NBSIM_CHECK(e.key.find('.') != std::string::npos, "config key '" + e.key + "' must be unit.field");
  NBSIM_CHECK(!find(e.key), "config key '" + e.key + "' declared twice");
  e.default_value = e.get();
  entries_.push_back(std::move(e));
}

void Schema::add(const std::string& key, int& field, const std::string& unit, const std::string& description, int min, int max) {
  Entry e{key, "int", unit, fmt::format("{} to {}", min, max), description, {}, {}, {}};
  e.set = [&field, key, min, max](const nlohmann::json& v, const std::string& origin) {
    if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) == v.get<double>()))
      throw InputError(fmt::format("{}: {} must be an integer, got {}", origin, key, excerpt(v)));
    const double d = v.get<double>();
    if (d < min || d > max) throw InputError(fmt::format("{}: {} = {} is outside its limits {} to {}", origin, key, excerpt(v), min, max));
    field = static_cast<int>(d);
  };
  e.get = [&field] { return nlohmann::ordered_json(field); };
  add_entry(std::move(e));
}

void Schema::add(const std::string& key, double& field, const std::string& unit, const std::string& description, double min, double max) {
  Entry e{key, "float", unit, fmt::format("{} to {}", min, max), description, {}, {}, {}};
  e.set = [&field, key, min, max](const nlohmann::json& v, const std::string& origin) {
    if (!v.is_number()) throw InputError(fmt::format("{}: {} must be a number, got {}", origin, key, excerpt(v)));
    const double d = v.get<double>();
    if (!std::isfinite(d) || d < min || d > max)
      throw InputError(fmt::format("{}: {} = {} is outside its limits {} to {}", origin, key, excerpt(v), min, max));
    field = d;
  };
  e.get = [&field] { return nlohmann::ordered_json(field); };
  add_entry(std::move(e));
}

void Schema::add(const std::string& key, bool& field, const std::string& description) {
  Entry e{key, "bool", "", "true or false", description, {}, {}, {}};
  e.set = [&field, key](const nlohmann::json& v, const std::string& origin) {
    if (!v.is_boolean()) throw InputError(fmt::format("{}: {} must be true or false, got {}", origin, key, excerpt(v)));
    field = v.get<bool>();
  };
  e.get = [&field] { return nlohmann::ordered_json(field); };
  add_entry(std::move(e));
}

void Schema::add(const std::string& key, std::string& field, const std::string& description, std::vector<std::string> labels) {
  std::string all;
  for (const auto& l : labels) all += (all.empty() ? "" : ", ") + l;
  Entry e{key, "enum", "", all, description, {}, {}, {}};
  e.set = [&field, key, labels, all](const nlohmann::json& v, const std::string& origin) {
    if (!v.is_string() || std::find(labels.begin(), labels.end(), v.get<std::string>()) == labels.end())
      throw InputError(fmt::format("{}: {} must be one of {}, got {}", origin, key, all, excerpt(v)));
    field = v.get<std::string>();
  };
  e.get = [&field] { return nlohmann::ordered_json(field); };
  add_entry(std::move(e));
}

const Schema::Entry* Schema::find(const std::string& key) const {
  for (const auto& e : entries_)
    if (e.key == key) return &e;
  return nullptr;
}

bool Schema::has(const std::string& key) const { return find(key) != nullptr; }

void Schema::renamed(const std::string& old_key, const std::string& new_key) {
  NBSIM_CHECK(find(new_key) != nullptr, "config key '" + old_key + "' renamed to an undeclared key '" + new_key + "'");
  renamed_.emplace_back(old_key, new_key);
}

void Schema::unknown(const std::string& key, const std::string& origin) const {
  for (const auto& [old_key, new_key] : renamed_)
    if (key == old_key)
      throw InputError(fmt::format("{}: config key '{}' is now '{}' (same meaning and limits)", origin, key, new_key));
  const Entry* best = nullptr;
  std::size_t best_d = kHintDistance;  // suggest only close matches
  if (key.size() <= kMaxHintKeyChars)
    for (const auto& e : entries_) {
      // The length difference bounds the distance from below: skip keys that cannot be close.
      const std::size_t gap = key.size() > e.key.size() ? key.size() - e.key.size() : e.key.size() - key.size();
      if (gap >= best_d) continue;
      const std::size_t d = distance(key, e.key);
      if (d < best_d) best_d = d, best = &e;
    }
  throw InputError(fmt::format("{}: unknown config key '{}'{} (nbsim config --defaults lists every key)", origin, excerpt_text(key),
                               best ? fmt::format("; did you mean '{}'?", best->key) : ""));
}

void Schema::apply(const nlohmann::json& config, const std::string& origin) {
  if (!config.is_object()) throw InputError(fmt::format("{}: a config is a JSON object of units, got {}", origin, config.type_name()));
  for (const auto& [name, value] : config.items()) {
    if (name.find('.') == std::string::npos && value.is_object()) {
      for (const auto& [field, v] : value.items()) {
        const std::string key = name + "." + field;
        const Entry* e = find(key);
        if (!e) unknown(key, origin);
        e->set(v, origin);
      }
    } else {
      const Entry* e = find(name);
      if (!e) unknown(name, origin);
      e->set(value, origin);
    }
  }
}

void Schema::set(const std::string& assignment) {
  if (std::size_t bad = 0; !valid_utf8(assignment, &bad))
    throw InputError(fmt::format("--set: the argument is not valid UTF-8 (byte 0x{:02x} at offset {}, after '{}')",
                                 static_cast<unsigned char>(assignment[bad]), bad, excerpt_text(std::string_view(assignment).substr(0, bad))));
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set '{}': expected unit.field=value", excerpt_text(assignment)));
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  const Entry* e = find(key);
  if (!e) unknown(key, "--set");
  nlohmann::json v;
  if (e->type == "enum") {
    v = text;
  } else {
    // accept() checks the syntax without building a value; parse_input then applies the limits
    // (nesting depth, repeated keys) before anything walks the value.
    if (!nlohmann::json::accept(text))
      throw InputError(fmt::format("--set {}: '{}' is not a valid {} value", key, excerpt_text(text), e->type));
    v = parse_input(text, fmt::format("--set {}: the value", key));
  }
  e->set(v, "--set");
}

nlohmann::ordered_json Schema::describe() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::array();
  for (const auto& e : entries_)
    j.push_back({{"key", e.key}, {"type", e.type}, {"default", e.default_value}, {"unit", e.unit}, {"limits", e.limits},
                 {"description", e.description}});
  return j;
}

nlohmann::ordered_json Schema::values() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& e : entries_) {
    const auto dot = e.key.find('.');
    j[e.key.substr(0, dot)][e.key.substr(dot + 1)] = e.get();
  }
  return j;
}

}  // namespace nbsim::config
