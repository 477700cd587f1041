// The relief table; see relief_table.h.
#include "pipeline/techniques/relief/relief_table.h"

#include <algorithm>
#include <cstdlib>
#include <array>
#include <map>
#include <sstream>
#include <stdexcept>

#include "model/common/error.h"

namespace nbsim::techniques {

namespace {

std::vector<double> parse_angles(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  for (std::string a; std::getline(in, a, ',');) out.push_back(std::stod(a));
  return out;
}

std::uint64_t u(const nlohmann::json& j, const char* k) { return j.contains(k) && j[k].is_number() ? j[k].get<std::uint64_t>() : 0; }

nlohmann::ordered_json ratio(double a, double b) { return b > 0 ? nlohmann::ordered_json(a / b) : nlohmann::ordered_json(nullptr); }

}  // namespace

nlohmann::ordered_json relief_rows(const std::vector<nlohmann::json>& runs, const std::vector<std::string>& traces) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const nlohmann::json& run = runs[i];
    const nlohmann::json props = run.value("trace_properties", nlohmann::json::object());
    if (props.value("technique", "") != "relief" || !run.contains("frames"))
      throw InputError("'" + traces[i] + "' was not replayed as a relief trace (no relief frames in its run.json)");
    std::vector<double> angles;
    try {
      angles = parse_angles(props.value("relief_angles", ""));
    } catch (const std::exception&) {
      angles.clear();
    }
    // The trace's safety radius (relief_radius and its settings; strict before the header had them)
    // and the replay's statistics of it.
    const std::string radius = props.value("relief_radius", "strict");
    const double epsilon = std::strtod(props.value("relief_radius_epsilon", "0").c_str(), nullptr);
    const std::string combine = props.value("relief_radius_combine", "max");
    const std::string box_depth = props.value("relief_box_depth", "none");
    nlohmann::ordered_json radius_mean = nullptr, radius_zero = nullptr;
    if (run.contains("summary") && run["summary"].contains("relief")) {
      const auto& sr = run["summary"]["relief"];
      if (sr.contains("radius_mean")) radius_mean = sr["radius_mean"];
      if (sr.contains("radius_zero_fraction")) radius_zero = sr["radius_zero_fraction"];
    }
    for (const nlohmann::json& f : run["frames"]) {
      if (!f.contains("relief")) continue;
      const std::uint64_t frame = u(f, "frame");
      for (const auto& [method, v] : f["relief"].items()) {
        if (v.contains("errors") && v["errors"].is_null())
          throw InputError("'" + traces[i] + "' was replayed with relief.score=false: the table needs the walks' hit errors");
        nlohmann::ordered_json r;
        r["trace"] = traces[i];
        r["field"] = props.value("relief_field", "");
        r["field_size"] = std::stoi(props.value("relief_field_size", "0"));
        r["frame"] = frame;
        r["angle"] = angles.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(angles[frame % angles.size()]);
        r["method"] = method;
        r["radius"] = radius;
        r["radius_epsilon"] = epsilon;
        r["radius_combine"] = radius == "paper" ? nlohmann::ordered_json(combine) : nlohmann::ordered_json(nullptr);
        r["radius_mean"] = radius_mean;
        r["radius_zero_fraction"] = radius_zero;
        for (const char* k : {"fragments", "gl_fragments", "lookups", "steps", "errors", "reference_hits", "cycles", "pixel_mismatches",
                              "walk_mismatches"})
          r[k] = u(v, k);
        // What the box left in the depth buffer (relief_box_depth; none before the header had it):
        // the fragments rasterized (those not walked were culled by the early test), the depth
        // written, box draws whose depth differs from GL's, and later scene fragments it hid.
        r["box_depth"] = box_depth;
        for (const char* k : {"rasterized", "depth_written", "depth_mismatches", "scene_hidden"}) r[k] = v.contains(k) ? u(v, k) : 0;
        const double n = static_cast<double>(u(v, "fragments"));
        r["lookups_per_fragment"] = ratio(static_cast<double>(u(v, "lookups")), n);
        r["steps_per_fragment"] = ratio(static_cast<double>(u(v, "steps")), n);
        r["error_rate"] = ratio(static_cast<double>(u(v, "errors")), n);
        const double texels = static_cast<double>(r["field_size"].get<int>()) * static_cast<double>(r["field_size"].get<int>());
        r["storage_bytes"] = v.contains("storage_bytes") ? u(v, "storage_bytes") : 0;
        r["storage_bytes_per_texel"] = ratio(static_cast<double>(r["storage_bytes"].get<std::uint64_t>()), texels);
        rows.push_back(std::move(r));
      }
    }
  }
  return rows;
}

nlohmann::ordered_json relief_ranking(const nlohmann::ordered_json& rows) {
  struct Sum {
    double fragments = 0, lookups = 0, steps = 0, errors = 0, cycles = 0, rows = 0, storage_per_texel = 0;
  };
  std::map<std::string, Sum> sums;
  for (const auto& r : rows) {
    Sum& s = sums[r["method"].get<std::string>()];
    s.fragments += static_cast<double>(u(r, "fragments"));
    s.lookups += static_cast<double>(u(r, "lookups"));
    s.steps += static_cast<double>(u(r, "steps"));
    s.errors += static_cast<double>(u(r, "errors"));
    s.cycles += static_cast<double>(u(r, "cycles"));
    s.rows += 1;
    if (r["storage_bytes_per_texel"].is_number()) s.storage_per_texel = std::max(s.storage_per_texel, r["storage_bytes_per_texel"].get<double>());
  }
  struct Entry {
    std::string method;
    Sum s;
    double cost = 0, error = 0;
  };
  std::vector<Entry> entries;
  for (const auto& [m, s] : sums) entries.push_back({m, s, s.rows > 0 ? s.cycles / s.rows : 0, s.fragments > 0 ? s.errors / s.fragments : 0});
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.cost < b.cost || (a.cost == b.cost && a.method < b.method); });
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const Entry& e : entries) {
    bool dominated = false;
    for (const Entry& o : entries)
      if (&o != &e && o.cost <= e.cost && o.error <= e.error && (o.cost < e.cost || o.error < e.error)) dominated = true;
    nlohmann::ordered_json j;
    j["method"] = e.method;
    j["fragments"] = static_cast<std::uint64_t>(e.s.fragments);
    j["lookups_per_fragment"] = ratio(e.s.lookups, e.s.fragments);
    j["steps_per_fragment"] = ratio(e.s.steps, e.s.fragments);
    j["cycles_per_frame"] = e.cost;
    j["errors"] = static_cast<std::uint64_t>(e.s.errors);
    j["error_rate"] = e.error;
    j["pareto"] = !dominated;
    j["storage_bytes_per_texel"] = e.s.storage_per_texel;  // the largest over the rows' fields
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::ordered_json relief_nbuffer_vs_exact(const nlohmann::ordered_json& rows) {
  struct Pair {
    double exact_fragments = 0, exact_lookups = 0, exact_errors = 0, nb_fragments = 0, nb_lookups = 0, nb_errors = 0;
  };
  std::map<std::pair<std::string, int>, Pair> pairs;
  for (const auto& r : rows) {
    const std::string m = r["method"].get<std::string>();
    if (m != "exact" && m != "nbuffer") continue;
    Pair& p = pairs[{r["field"].get<std::string>(), r["field_size"].get<int>()}];
    const double f = static_cast<double>(u(r, "fragments")), l = static_cast<double>(u(r, "lookups")), e = static_cast<double>(u(r, "errors"));
    if (m == "exact") p.exact_fragments += f, p.exact_lookups += l, p.exact_errors += e;
    else p.nb_fragments += f, p.nb_lookups += l, p.nb_errors += e;
  }
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const auto& [key, p] : pairs) {
    if (p.exact_fragments == 0 || p.nb_fragments == 0) continue;
    nlohmann::ordered_json j;
    j["field"] = key.first;
    j["field_size"] = key.second;
    j["exact_lookups_per_fragment"] = p.exact_lookups / p.exact_fragments;
    j["nbuffer_lookups_per_fragment"] = p.nb_lookups / p.nb_fragments;
    j["lookup_ratio"] = ratio(p.nb_lookups / p.nb_fragments, p.exact_lookups / p.exact_fragments);
    j["exact_errors"] = static_cast<std::uint64_t>(p.exact_errors);
    j["nbuffer_errors"] = static_cast<std::uint64_t>(p.nb_errors);
    j["extra_errors"] = static_cast<std::int64_t>(p.nb_errors) - static_cast<std::int64_t>(p.exact_errors);
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::ordered_json relief_paper_table(const nlohmann::ordered_json& rows) {
  // Baboud & Decoret, Table 1, terrain (GeForce 6800 GT), frames per second at 32^2 .. 256^2.
  const std::vector<std::pair<std::string, std::array<double, 4>>> paper = {
      {"binary", {109, 109, 110, 108}}, {"exact", {115, 87, 58, 36}}, {"robust", {116, 105, 97, 96}}};
  const std::array<int, 4> sizes = {32, 64, 128, 256};
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const auto& [method, hz] : paper)
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      double cycles = 0, n = 0, fragments = 0, lookups = 0;
      for (const auto& r : rows)
        if (r["method"] == method && r["field_size"] == sizes[k] && r["field"].get<std::string>().rfind("fbm", 0) == 0) {
          cycles += static_cast<double>(u(r, "cycles"));
          fragments += static_cast<double>(u(r, "fragments"));
          lookups += static_cast<double>(u(r, "lookups"));
          n += 1;
        }
      nlohmann::ordered_json j;
      j["method"] = method;
      j["field_size"] = sizes[k];
      j["paper_hz"] = hz[k];
      j["cycles_per_frame"] = n > 0 ? nlohmann::ordered_json(cycles / n) : nlohmann::ordered_json(nullptr);
      j["lookups_per_fragment"] = ratio(lookups, fragments);
      out.push_back(std::move(j));
    }
  return out;
}

}  // namespace nbsim::techniques
