// Configuration keys of the model: every tunable field of every unit's config struct is declared
// here once with its key ("unit.field"), unit, limits and meaning (gem5 Params, VCML properties).
// A run's configuration is applied from JSON and from `--set unit.field=value`; a key that is set
// but not declared is an error, so that a typo never silently runs the default experiment.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace nbsim::config {

class Schema {
 public:
  // Fields are bound by reference: the schema writes into the config structs it describes, which
  // must outlive it. Keys are "unit.field", lowercase with underscores; fields carry their unit in
  // their name where it helps (`lookup_latency_cycles`).
  void add(const std::string& key, int& field, const std::string& unit, const std::string& description, int min, int max);
  void add(const std::string& key, double& field, const std::string& unit, const std::string& description, double min, double max);
  void add(const std::string& key, bool& field, const std::string& description);
  // An enumeration stored as its label (the config struct converts it when validated).
  void add(const std::string& key, std::string& field, const std::string& description, std::vector<std::string> labels);

  // Applies {"unit": {"field": value}} or {"unit.field": value} (mixed is fine). Throws InputError
  // naming the key on an unknown key, a wrong type or a value outside the limits.
  void apply(const nlohmann::json& config, const std::string& origin = "config");
  // Applies "unit.field=value"; the value is parsed by the field's type.
  void set(const std::string& assignment);

  // Every key: {"key", "type", "default", "unit", "limits", "description"} (defaults are the values
  // bound when the key was added).
  nlohmann::ordered_json describe() const;
  // Current values as {"unit": {"field": value}}, for run.json.
  nlohmann::ordered_json values() const;
  bool has(const std::string& key) const;
  // A key that a later version moved: setting `old_key` is refused with a message naming `new_key`.
  void renamed(const std::string& old_key, const std::string& new_key);
  std::size_t size() const noexcept { return entries_.size(); }

 private:
  struct Entry {
    std::string key, type, unit, limits, description;
    nlohmann::ordered_json default_value;
    std::function<void(const nlohmann::json&, const std::string& origin)> set;
    std::function<nlohmann::ordered_json()> get;
  };
  void add_entry(Entry e);
  const Entry* find(const std::string& key) const;
  [[noreturn]] void unknown(const std::string& key, const std::string& origin) const;
  std::vector<Entry> entries_;
  std::vector<std::pair<std::string, std::string>> renamed_;  // (old key, new key)
};

}  // namespace nbsim::config
