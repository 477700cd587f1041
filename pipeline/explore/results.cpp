// The tidy outputs of `nbsim explore`; see results.h.
#include "pipeline/explore/results.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>

#include "pipeline/explore/child.h"

namespace nbsim::explore {

namespace fs = std::filesystem;

namespace {

std::string cell(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

std::string number(double v) { return fmt::format("{}", v); }

const nlohmann::json* find(const nlohmann::json& j, std::initializer_list<const char*> path) {
  const nlohmann::json* at = &j;
  for (const char* k : path) {
    if (!at->is_object() || !at->contains(k)) return nullptr;
    at = &(*at)[k];
  }
  return at;
}

// The metric cells of a finished point, in metric_columns() order.
std::map<std::string, std::string> metrics_of(const nlohmann::json& run) {
  std::map<std::string, std::string> m;
  const nlohmann::json& s = run["summary"];
  const double frames = s.value("frames", 0.0);
  const auto per_frame = [frames](double v) { return frames > 0 ? number(v / frames) : std::string(); };
  for (const char* k : {"frames", "draws", "cycles", "depth_tests", "fragment_error", "passed_error", "within_thresholds",
                        "host_seconds", "cycles_per_host_second"})
    if (s.contains(k)) m[k] = cell(s[k]);
  if (s.contains("cycles")) m["cycles_per_frame"] = per_frame(s["cycles"].get<double>());
  if (s.contains("depth_tests")) m["depth_tests_per_frame"] = per_frame(s["depth_tests"].get<double>());
  if (const auto* c = find(s, {"cull"})) {
    for (const char* k : {"query_depth_tests_per_frame", "update_texels_per_frame", "total_depth_tests_per_frame", "false_culls",
                          "culling_efficiency", "culled", "candidates_not_visible", "max_lookups_per_test",
                          "nbuffer_memory_bytes", "structure_memory_bytes"})
      if (c->contains(k)) m[k] = cell((*c)[k]);
  }
  if (s.contains("fragment_error") && s.contains("passed_error"))
    m["counter_error"] = number(std::max(s["fragment_error"].get<double>(), s["passed_error"].get<double>()));
  if (const auto* mem = find(run, {"stats", "gpu.memory"}); mem && mem->is_object()) {
    double total = 0;
    for (const auto& [k, v] : mem->items())
      if (k.rfind("bytes_", 0) == 0 && v.is_number()) total += v.get<double>();
    m["memory_bytes_per_frame"] = per_frame(total);
    if (mem->contains("bytes_depth")) m["depth_bytes_per_frame"] = per_frame((*mem)["bytes_depth"].get<double>());
    if (mem->contains("bytes_nbuffer")) m["nbuffer_bytes_per_frame"] = per_frame((*mem)["bytes_nbuffer"].get<double>());
  }
  return m;
}

std::optional<nlohmann::json> read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return std::nullopt;
  return j;
}

}  // namespace

const std::vector<std::string>& metric_columns() {
  static const std::vector<std::string> columns = {
      "frames", "draws", "cycles", "cycles_per_frame", "depth_tests", "depth_tests_per_frame", "query_depth_tests_per_frame",
      "update_texels_per_frame", "total_depth_tests_per_frame", "false_culls", "culling_efficiency", "culled",
      "candidates_not_visible", "max_lookups_per_test", "memory_bytes_per_frame", "depth_bytes_per_frame",
      "nbuffer_bytes_per_frame", "nbuffer_memory_bytes", "structure_memory_bytes", "fragment_error", "passed_error",
      "counter_error", "within_thresholds", "host_seconds", "cycles_per_host_second", "culling_reference",
      "reference_culling_efficiency", "efficiency_lost", "timing_reference", "reference_cycles", "cycle_error"};
  return columns;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string q = "\"";
  for (const char ch : text) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + '"';
}

void write_results_csv(const fs::path& file, const fs::path& out, const std::vector<Point>& points,
                       const std::vector<std::string>& parameters, const std::map<std::string, TraceFile>& traces,
                       const std::string& version) {
  std::ofstream csv(file);
  if (!csv) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
  // Every finished run first: the error columns compare a point with its reference points.
  std::map<std::string, nlohmann::json> summaries;
  for (const Point& p : points)
    if (point_done(out, p))
      if (const auto run = read_json(point_dir(out, p) / "run.json")) summaries[p.id] = (*run)["summary"];
  const auto reference_value = [&summaries](const std::string& id, std::initializer_list<const char*> path) -> std::optional<double> {
    const auto it = summaries.find(id);
    if (id.empty() || it == summaries.end()) return std::nullopt;
    const nlohmann::json* v = find(it->second, path);
    if (!v || !v->is_number()) return std::nullopt;
    return v->get<double>();
  };
  const auto errors = [&](const Point& p, std::map<std::string, std::string>& m) {
    m["culling_reference"] = p.culling_reference;
    m["timing_reference"] = p.timing_reference;
    const auto eff = reference_value(p.id, {"cull", "culling_efficiency"});
    const auto ref_eff = reference_value(p.culling_reference, {"cull", "culling_efficiency"});
    if (ref_eff) m["reference_culling_efficiency"] = number(*ref_eff);
    if (eff && ref_eff) m["efficiency_lost"] = number(*ref_eff - *eff);
    const auto cycles = reference_value(p.id, {"cycles"});
    const auto ref_cycles = reference_value(p.timing_reference, {"cycles"});
    if (ref_cycles) m["reference_cycles"] = number(*ref_cycles);
    if (cycles && ref_cycles && *ref_cycles > 0) m["cycle_error"] = number((*cycles - *ref_cycles) / *ref_cycles);
  };

  std::vector<std::string> header = {"point_id", "role", "trace", "trace_crc32", "nbsim_version"};
  header.insert(header.end(), parameters.begin(), parameters.end());
  header.push_back("status");
  header.insert(header.end(), metric_columns().begin(), metric_columns().end());
  header.push_back("error");
  for (std::size_t i = 0; i < header.size(); ++i) csv << (i ? "," : "") << csv_field(header[i]);
  csv << '\n';
  for (const Point& p : points) {
    const fs::path dir = point_dir(out, p);
    const auto run = point_done(out, p) ? read_json(dir / "run.json") : std::nullopt;
    std::vector<std::string> row = {p.id, p.role, p.trace, traces.at(p.trace).crc32,
                                    run && run->contains("nbsim_version") ? cell((*run)["nbsim_version"]) : version};
    for (const auto& k : parameters) row.push_back(cell(p.parameters.value(k, nlohmann::json())));
    if (run) {
      row.push_back("ok");
      auto m = metrics_of(*run);
      errors(p, m);
      for (const auto& c : metric_columns()) row.push_back(m.count(c) ? m.at(c) : "");
      row.emplace_back();
    } else {
      std::string error = tail_lines(dir / "error.txt", 5);
      row.push_back(error.empty() ? "not_run" : "failed");
      row.insert(row.end(), metric_columns().size(), "");
      row.push_back(error);
    }
    for (std::size_t i = 0; i < row.size(); ++i) csv << (i ? "," : "") << csv_field(row[i]);
    csv << '\n';
  }
  if (!csv) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

void write_sweep_json(const fs::path& file, const std::string& sweep_file, const SweepSpec& spec, const std::vector<Point>& points,
                      const std::vector<std::string>& parameters, const std::map<std::string, TraceFile>& traces,
                      const std::string& version) {
  nlohmann::ordered_json j;
  j["sweep_file"] = sweep_file;
  j["name"] = spec.name;
  j["description"] = spec.description;
  j["nbsim_version"] = version;
  j["parameters"] = parameters;
  j["points"] = nlohmann::ordered_json::array();
  for (const Point& p : points)
    j["points"].push_back({{"id", p.id}, {"role", p.role}, {"trace", p.trace}, {"trace_file", traces.at(p.trace).path.string()},
                           {"trace_crc32", traces.at(p.trace).crc32}, {"settings", p.settings}, {"parameters", p.parameters},
                           {"culling_reference", p.culling_reference}, {"timing_reference", p.timing_reference}});
  j["culling_reference_settings"] = culling_reference_settings();
  j["timing_reference_settings"] = timing_reference_settings();
  std::ofstream f(file);
  f << j.dump(2) << '\n';
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

}  // namespace nbsim::explore
