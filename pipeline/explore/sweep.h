// Sweep files of `nbsim explore`: parsing, expansion into points (the cartesian product of the
// axes, or a listed set) and their stable ids. Plain C++: the config check is handed in.
//
// Format (JSON object; keys are config keys "unit.field" as `nbsim config --defaults` lists them):
//   "name", "description"  optional strings
//   "traces"   non-empty list of trace files (relative paths: from the current directory)
//   "set"      optional {key: value}: settings shared by every point
//   "axes"     {key: [value, ...]}: every combination, the last axis varying fastest
//   "points"   [{key: value, ..., "trace": optional one trace instead of all}, ...]: a listed set
// Exactly one of "axes" and "points". "set" and points may also nest keys: {"unit": {"field": v}}.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace nbsim::explore {

struct SweepSpec {
  std::string name, description;
  std::vector<std::string> traces;
  nlohmann::ordered_json set = nlohmann::ordered_json::object();              // flat {key: value}, file order
  std::vector<std::pair<std::string, std::vector<nlohmann::json>>> axes;      // in file order
  std::vector<nlohmann::ordered_json> points;                                 // flat, may hold "trace"
};

// One run: a trace with its settings. `settings` is flat and sorted by key ("set" merged with the
// axis or listed values); `parameters` holds the effective value of every key any point of the
// sweep sets (defaults filled in), which results.csv prints one column each.
struct Point {
  std::string id;
  std::string trace;  // as written in the sweep file
  nlohmann::json settings = nlohmann::json::object();
  nlohmann::json parameters = nlohmann::json::object();
  nlohmann::json effective = nlohmann::json::object();  // every config key's value (check_points fills it)
  std::string role = "sweep";  // "reference": added by add_reference_points, not in the sweep file
  // The technique of the trace as its header names it ("" when it names none or cannot be read):
  // its declared results (pipeline/techniques/results.h) give the technique's columns.
  std::string technique;
  // Ids of the points this one's errors are measured against (itself when it is its own
  // reference; empty when there is none): see add_reference_points. technique_reference is the
  // technique's reference setting (results.csv names its column after the declaration's
  // ReferenceSetting::column), timing_reference the generic timing one.
  std::string technique_reference, timing_reference;
  // A design point that cannot be built (its values are each valid, the combination is not: e.g.
  // nbuffer.level0=depth with a resolution divisor): the config check's message. It is recorded as
  // a failed point (its error.txt) and never run; the sweep goes on.
  std::string refused;
  // An axes sweep's point: its value's index on each axis, in the file's axis order (empty for a
  // listed point or a reference point). The front search (search.h) steps along them.
  std::vector<int> grid;
};

// Tunable. Most points a sweep may expand to (traces x the product of the axis sizes, or the
// listed points run on each trace), reference points not counted; `nbsim explore --max-points N`
// raises it. Each point is one replay, and expanding and checking 10,000 takes about a second.
inline constexpr std::uint64_t kDefaultMaxSweepPoints = 10000;

// Checks the structure of a sweep file (parsed keeping its key order); throws InputError naming
// `origin` and the bad entry. A sweep of more than `max_points` points is refused before any
// point is built (counted with no overflow), and an axis value or a listed point given twice is
// refused where it is met.
SweepSpec parse_sweep(const nlohmann::ordered_json& sweep, const std::string& origin,
                      std::uint64_t max_points = kDefaultMaxSweepPoints);

// Every point, trace-major, in file order (ids set from the raw values; check_points normalizes).
std::vector<Point> expand(const SweepSpec& spec);

// A stable id: 16 hex digits of the FNV-1a 64-bit hash of the trace and the sorted settings.
std::string point_id(const std::string& trace, const nlohmann::json& settings);

// What a config check looks at: each value against its key's type and limits only, or also the
// config whole (the units' consistency rules, e.g. a key that needs another's value).
enum class CheckScope { Values, Whole };

// Applies flat settings to a default config and returns every key's effective value, flat
// ({"unit.field": value}); throws InputError naming the key when one is unknown or bad (and, for
// CheckScope::Whole, when the combination breaks a unit's rule). `origin` prefixes the message.
using ConfigCheck = std::function<nlohmann::json(const nlohmann::json& settings, const std::string& origin, CheckScope scope)>;

// Validates every point before anything runs: each axis value on its own (so the message names
// it), then each point whole. Replaces each setting by its typed value (2 -> 2.0 for a float key),
// recomputes the ids, fills `parameters`, and refuses two points with the same id.
void check_points(const SweepSpec& spec, std::vector<Point>& points, const ConfigCheck& check, const std::string& origin);

// The keys of `parameters`, in the order of first appearance in the sweep file.
std::vector<std::string> parameter_keys(const SweepSpec& spec);

// The settings each point's errors are measured against (results.csv):
//  - the technique's: its declared reference setting (pipeline/techniques/results.h
//    ReferenceSetting; `nbsim explore --help` lists each technique's). A point whose technique
//    declares no reference, or whose value of the reference's skip_key is one of its skip_values,
//    has none. Its derived errors (efficiency_lost) compare the two points.
//  - timing, for every technique: the model's most detailed fidelity (timing_reference_settings():
//    no temporal decoupling, llvmpipe's batch size, fused multiply-adds as llvmpipe on FMA hosts).
//    cycle_error = (cycles - reference cycles) / reference cycles.
// Keys the config does not have are left out.
const nlohmann::json& timing_reference_settings();

// Sets each point's technique_reference and timing_reference, appending a point with role
// "reference" for every reference configuration the sweep does not already hold (compared on the
// effective config, so {} and an explicit default are the same point). Call after check_points,
// with each point's technique set.
void add_reference_points(std::vector<Point>& points, const std::vector<std::string>& parameters, const ConfigCheck& check,
                          const std::string& origin);

}  // namespace nbsim::explore
