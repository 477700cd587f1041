// Sweep files of `nbsim explore`; see sweep.h.
#include "pipeline/explore/sweep.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "pipeline/techniques/results.h"

namespace nbsim::explore {

namespace {

// {"unit": {"field": v}} and {"unit.field": v} -> {"unit.field": v}; `skip` keys stay as they are.
nlohmann::ordered_json flatten(const nlohmann::ordered_json& j, const std::string& where, const std::set<std::string>& skip = {}) {
  if (!j.is_object()) throw InputError(fmt::format("{}: expected an object of config keys, got {}", where, j.type_name()));
  nlohmann::ordered_json flat = nlohmann::ordered_json::object();
  const auto put = [&](const std::string& key, const nlohmann::ordered_json& v) {
    if (v.is_object() || v.is_array() || v.is_null())
      throw InputError(fmt::format("{}: {} must be a single value, got {}", where, key, config::excerpt(v)));
    if (flat.contains(key)) throw InputError(fmt::format("{}: {} is given twice", where, key));
    flat[key] = v;
  };
  for (const auto& [name, value] : j.items()) {
    if (skip.count(name)) {
      flat[name] = value;
    } else if (name.find('.') == std::string::npos && value.is_object()) {
      for (const auto& [field, v] : value.items()) put(name + "." + field, v);
    } else {
      put(name, value);
    }
  }
  return flat;
}

// False when the point's `skip_key` is absent or one of `skip_values`: it runs nothing the
// technique's errors measure.
bool has_reference(const techniques::ReferenceSetting& r, const nlohmann::json& effective) {
  if (r.skip_key.empty()) return true;
  if (!effective.contains(r.skip_key)) return false;
  const nlohmann::json& v = effective[r.skip_key];
  const std::string value = v.is_string() ? v.get<std::string>() : v.dump();
  return std::find(r.skip_values.begin(), r.skip_values.end(), value) == r.skip_values.end();
}

std::string describe_settings(const std::string& trace, const nlohmann::json& settings) {
  std::string s = "trace " + trace;
  for (const auto& [k, v] : settings.items()) s += fmt::format(", {}={}", k, v.is_string() ? v.get<std::string>() : v.dump());
  return s;
}

// A single JSON value from the ordered (file) form to the sorted form used for settings.
nlohmann::json sorted(const nlohmann::ordered_json& v) { return nlohmann::json::parse(v.dump()); }

}  // namespace

SweepSpec parse_sweep(const nlohmann::ordered_json& j, const std::string& origin, std::uint64_t max_points) {
  if (!j.is_object()) throw InputError(fmt::format("{}: a sweep is a JSON object, got {}", origin, j.type_name()));
  static const std::set<std::string> known = {"name", "description", "traces", "set", "axes", "points"};
  for (const auto& [k, v] : j.items())
    if (!known.count(k))
      throw InputError(fmt::format("{}: unknown sweep entry '{}' (expected name, description, traces, set, axes or points)", origin, k));
  SweepSpec s;
  for (const char* k : {"name", "description"}) {
    if (!j.contains(k)) continue;
    if (!j[k].is_string()) throw InputError(fmt::format("{}: {} must be a string", origin, k));
    (std::string(k) == "name" ? s.name : s.description) = j[k].get<std::string>();
  }
  if (!j.contains("traces") || !j["traces"].is_array() || j["traces"].empty())
    throw InputError(fmt::format("{}: traces must be a non-empty list of trace files", origin));
  std::set<std::string> trace_names;
  for (const auto& t : j["traces"]) {
    if (!t.is_string() || t.get<std::string>().empty())
      throw InputError(fmt::format("{}: traces: every entry must be a file name, got {}", origin, config::excerpt(t)));
    if (!trace_names.insert(t.get<std::string>()).second)
      throw InputError(fmt::format("{}: traces: '{}' is listed twice", origin, config::excerpt_text(t.get<std::string>(), 1024)));
    if (trace_names.size() > max_points)  // bounded like the points, which are mostly one or more per trace
      throw InputError(fmt::format("{}: traces: more than {} traces, the limit of points (--max-points N raises it)", origin, max_points));
    s.traces.push_back(t.get<std::string>());
  }
  if (j.contains("set")) s.set = flatten(j["set"], origin + ": set");
  if (j.contains("axes") == j.contains("points"))
    throw InputError(fmt::format("{}: give exactly one of axes (a cartesian product) and points (a listed set)", origin));
  if (j.contains("axes")) {
    const auto& axes = j["axes"];
    if (!axes.is_object() || axes.empty()) throw InputError(fmt::format("{}: axes must be a non-empty object of key: [values]", origin));
    // Count the points before building any: traces x the product of the axis sizes, saturating.
    std::uint64_t count = s.traces.size();
    std::string product = fmt::format("{} trace{}", s.traces.size(), s.traces.size() == 1 ? "" : "s");
    for (const auto& [key, values] : axes.items()) {
      const std::uint64_t n = values.is_array() ? values.size() : 1;
      count = n != 0 && count > UINT64_MAX / n ? UINT64_MAX : count * n;
      product += fmt::format(" x {}", n);
    }
    if (count > max_points)
      throw InputError(fmt::format("{}: the sweep has {} = {}{} points, more than the limit of {} (--max-points N raises it)",
                                   origin, product, count == UINT64_MAX ? "more than " : "", count, max_points));
    for (const auto& [key, values] : axes.items()) {
      if (!values.is_array() || values.empty())
        throw InputError(fmt::format("{}: axes.{} must be a non-empty list of values", origin, key));
      if (s.set.contains(key)) throw InputError(fmt::format("{}: {} is both in set and in axes", origin, key));
      std::vector<nlohmann::json> list;
      std::set<std::string> seen;  // each value as JSON text
      for (const auto& v : values) {
        if (v.is_object() || v.is_array() || v.is_null())
          throw InputError(fmt::format("{}: axes.{}: {} is not a single value", origin, key, config::excerpt(v)));
        if (!seen.insert(v.dump()).second)
          throw InputError(fmt::format("{}: axes.{}: {} is listed twice (at [{}] again)", origin, key, config::excerpt(v), list.size()));
        list.push_back(sorted(v));
      }
      s.axes.emplace_back(key, std::move(list));
    }
  } else {
    const auto& points = j["points"];
    if (!points.is_array() || points.empty()) throw InputError(fmt::format("{}: points must be a non-empty list of objects", origin));
    std::uint64_t count = 0;  // points run: one per listed point that names its trace, one per trace otherwise
    std::map<std::string, std::size_t> seen;  // each point as sorted JSON text -> its index
    for (std::size_t i = 0; i < points.size(); ++i) {
      const std::string where = fmt::format("{}: points[{}]", origin, i);
      nlohmann::ordered_json p = flatten(points[i], where, {"trace"});
      if (p.contains("trace")) {
        if (!p["trace"].is_string()) throw InputError(fmt::format("{}: trace must be a file name", where));
        if (!trace_names.count(p["trace"].get<std::string>()))
          throw InputError(fmt::format("{}: trace '{}' is not one of traces", where, p["trace"].get<std::string>()));
      }
      count += p.contains("trace") ? 1 : s.traces.size();
      if (count > max_points)
        throw InputError(fmt::format("{}: the sweep has more than {} points by points[{}], more than the limit (--max-points N "
                                     "raises it)",
                                     origin, max_points, i));
      if (const auto [at, added] = seen.emplace(sorted(p).dump(), i); !added)
        throw InputError(fmt::format("{}: this point is listed twice (the same as points[{}])", where, at->second));
      s.points.push_back(std::move(p));
    }
  }
  return s;
}

std::vector<Point> expand(const SweepSpec& spec) {
  std::vector<nlohmann::json> combos;  // flat settings, with "trace" when a listed point names one
  std::vector<std::vector<int>> grids;  // each combo's axis indices (axes sweeps)
  if (!spec.axes.empty()) {
    std::vector<std::size_t> index(spec.axes.size(), 0);
    for (;;) {
      nlohmann::json c = sorted(spec.set);
      for (std::size_t a = 0; a < spec.axes.size(); ++a) c[spec.axes[a].first] = spec.axes[a].second[index[a]];
      combos.push_back(std::move(c));
      grids.emplace_back(index.begin(), index.end());
      std::size_t a = spec.axes.size();
      while (a > 0 && ++index[a - 1] == spec.axes[a - 1].second.size()) index[--a] = 0;
      if (a == 0) break;
    }
  } else {
    for (const auto& p : spec.points) {
      nlohmann::json c = sorted(spec.set);
      for (const auto& [k, v] : p.items()) c[k] = sorted(v);
      combos.push_back(std::move(c));
    }
  }
  std::vector<Point> points;
  for (const auto& trace : spec.traces) {
    for (std::size_t ci = 0; ci < combos.size(); ++ci) {
      const nlohmann::json& c = combos[ci];
      if (c.contains("trace") && c["trace"].get<std::string>() != trace) continue;
      Point p;
      p.trace = trace;
      if (ci < grids.size()) p.grid = grids[ci];
      p.settings = c;
      p.settings.erase("trace");
      p.id = point_id(p.trace, p.settings);
      points.push_back(std::move(p));
    }
  }
  return points;
}

std::string point_id(const std::string& trace, const nlohmann::json& settings) {
  // nlohmann::json (not ordered_json) keeps object keys sorted, so the dump is canonical.
  const std::string canonical = trace + '\n' + settings.dump();
  std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a 64: fixed by the id format, never change
  for (const unsigned char ch : canonical) {
    h ^= ch;
    h *= 0x100000001b3ULL;
  }
  return fmt::format("{:016x}", h);
}

std::vector<std::string> parameter_keys(const SweepSpec& spec) {
  std::vector<std::string> keys;
  const auto add = [&keys](const std::string& k) {
    if (k != "trace" && std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
  };
  for (const auto& [k, v] : spec.set.items()) add(k);
  for (const auto& [k, v] : spec.axes) add(k);
  for (const auto& p : spec.points)
    for (const auto& [k, v] : p.items()) add(k);
  return keys;
}

void check_points(const SweepSpec& spec, std::vector<Point>& points, const ConfigCheck& check, const std::string& origin) {
  // Each value on its own: against its key's type and limits (a key this build lacks, a value out
  // of its limits: the whole sweep is refused at once), then beside the other keys' defaults. A
  // value that breaks a rule there (a tracking tile beside the default eager policy, say) is only
  // doubtful: its points are refused one by one below, and the sweep only when all of them are (the
  // value then cannot be built in this sweep at all, and the message names it).
  struct Doubt {
    nlohmann::json settings;  // the value (or the set's values), typed
    std::string message;
  };
  std::vector<Doubt> doubts;
  const auto check_value = [&](const nlohmann::json& one, const std::string& where) {
    const nlohmann::json typed = check(one, where, CheckScope::Values);
    try {
      check(one, where, CheckScope::Whole);
    } catch (const InputError& e) {
      Doubt d{nlohmann::json::object(), e.what()};
      for (const auto& [k, v] : one.items()) d.settings[k] = typed.contains(k) ? typed[k] : v;
      doubts.push_back(std::move(d));
    }
  };
  check_value(sorted(spec.set), origin + ": set");
  for (const auto& [key, values] : spec.axes)
    for (std::size_t i = 0; i < values.size(); ++i) {
      nlohmann::json one = nlohmann::json::object();
      one[key] = values[i];
      check_value(one, fmt::format("{}: axes.{}[{}]", origin, key, i));
    }
  for (std::size_t i = 0; i < spec.points.size(); ++i)
    for (const auto& [k, v] : spec.points[i].items()) {
      if (k == "trace") continue;
      nlohmann::json one = nlohmann::json::object();
      one[k] = sorted(v);
      check(one, fmt::format("{}: points[{}].{}", origin, i, k), CheckScope::Values);
    }
  const std::vector<std::string> keys = parameter_keys(spec);
  std::set<std::string> seen;
  for (Point& p : points) {
    nlohmann::json effective;
    try {
      effective = check(p.settings, fmt::format("{}: point ({})", origin, describe_settings(p.trace, p.settings)), CheckScope::Whole);
    } catch (const InputError& e) {
      // Every value passed on its own above: the combination cannot be built. Recorded, not run.
      p.refused = e.what();
      for (const auto& k : keys) p.parameters[k] = p.settings.contains(k) ? p.settings[k] : nlohmann::json();
      p.effective = p.settings;
      p.id = point_id(p.trace, p.settings);
      if (!seen.insert(p.id).second)
        throw InputError(fmt::format("{}: the point ({}) is listed twice", origin, describe_settings(p.trace, p.settings)));
      continue;
    }
    for (auto& [k, v] : p.settings.items()) {
      NBSIM_CHECK(effective.contains(k), "the config check returned no value for '" + k + "'");
      v = effective[k];
    }
    for (const auto& k : keys) {
      NBSIM_CHECK(effective.contains(k), "the config check returned no value for '" + k + "'");
      p.parameters[k] = effective[k];
    }
    p.effective = effective;
    p.id = point_id(p.trace, p.settings);
    if (!seen.insert(p.id).second)
      throw InputError(fmt::format("{}: the point ({}) is listed twice", origin, describe_settings(p.trace, p.settings)));
  }
  for (const Doubt& d : doubts) {
    const auto holds = [&d](const Point& p) {
      for (const auto& [k, v] : d.settings.items())
        if (!p.settings.contains(k) || p.settings[k] != v) return false;
      return true;
    };
    if (std::none_of(points.begin(), points.end(), [&](const Point& p) { return p.refused.empty() && holds(p); }))
      throw InputError(d.message);
  }
}

const nlohmann::json& timing_reference_settings() {
  static const nlohmann::json s = {{"gpu.quantum_cycles", 0},
                                   {"geometry.batch_triangles", 85},
                                   {"geometry.fused_viewport", true},
                                   {"depth.fused_interpolation", true}};
  return s;
}

void add_reference_points(std::vector<Point>& points, const std::vector<std::string>& parameters, const ConfigCheck& check,
                          const std::string& origin) {
  const auto config_key = [](const Point& p) { return p.trace + '\n' + p.effective.dump(); };
  std::map<std::string, std::size_t> by_config;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].refused.empty()) by_config.emplace(config_key(points[i]), i);

  // The id of the point whose config is `p`'s with `overrides`, added when the sweep lacks it.
  const auto reference = [&](std::size_t i, const nlohmann::json& overrides) -> std::string {
    Point r;
    r.trace = points[i].trace;
    r.technique = points[i].technique;
    r.settings = points[i].settings;
    bool changed = false;
    for (const auto& [k, v] : overrides.items()) {
      if (!points[i].effective.contains(k)) continue;  // a key this build does not have
      if (points[i].effective[k] == v) continue;
      r.settings[k] = v;
      changed = true;
    }
    if (!changed) return points[i].id;
    r.effective =
        check(r.settings, fmt::format("{}: reference point ({})", origin, describe_settings(r.trace, r.settings)), CheckScope::Whole);
    for (auto& [k, v] : r.settings.items()) v = r.effective[k];
    if (const auto found = by_config.find(config_key(r)); found != by_config.end()) return points[found->second].id;
    for (const auto& k : parameters) r.parameters[k] = r.effective[k];
    r.id = point_id(r.trace, r.settings);
    r.role = "reference";
    by_config.emplace(config_key(r), points.size());
    points.push_back(std::move(r));
    const std::size_t added = points.size() - 1;
    points[added].technique_reference = points[added].timing_reference = points[added].id;  // errors of a reference: none
    return points[added].id;
  };

  const nlohmann::json defaults = check(nlohmann::json::object(), origin + ": defaults", CheckScope::Whole);
  const std::size_t sweep_points = points.size();
  for (std::size_t i = 0; i < sweep_points; ++i) {
    if (!points[i].refused.empty()) continue;  // never run: nothing to measure against
    const techniques::TechniqueResults* t = techniques::find_technique_results(points[i].technique);
    if (t && t->reference && has_reference(*t->reference, points[i].effective)) {
      // One reference for every variant the setting does not name (e.g. every test mode, so a
      // flat query's loss shows too); keys under reset_prefixes mean nothing to it
      // (the Hi-Z keys): they go back to their defaults, one reference for all their variants.
      nlohmann::json overrides = t->reference->settings;
      for (const auto& [k, v] : defaults.items())
        for (const auto& prefix : t->reference->reset_prefixes)
          if (k.rfind(prefix, 0) == 0) overrides[k] = v;
      points[i].technique_reference = reference(i, overrides);
    }
    points[i].timing_reference = reference(i, timing_reference_settings());
  }
}

}  // namespace nbsim::explore
