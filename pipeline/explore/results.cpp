// The tidy outputs of `nbsim explore`; see results.h.
#include "pipeline/explore/results.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>

#include "model/common/error.h"
#include "model/config/json_input.h"
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

// The generic columns of results.csv (technique-independent), by block; see metric_columns().
const std::vector<std::string> kRunColumns = {"frames", "draws", "cycles", "cycles_per_frame", "depth_tests", "depth_tests_per_frame"};
const std::vector<std::string> kMemoryColumns = {"memory_bytes_per_frame", "depth_bytes_per_frame", "nbuffer_bytes_per_frame"};
const std::vector<std::string> kFidelityColumns = {"fragment_error",  "passed_error", "counter_error", "within_thresholds",
                                                   "host_seconds", "cycles_per_host_second"};
const std::vector<std::string> kTimingColumns = {"timing_reference", "reference_cycles", "cycle_error"};

// The generic metric cells of a finished point.
std::map<std::string, std::string> generic_metrics_of(const nlohmann::json& run) {
  std::map<std::string, std::string> m;
  const nlohmann::json& s = run["summary"];
  const double frames = s.value("frames", 0.0);
  const auto per_frame = [frames](double v) { return frames > 0 ? number(v / frames) : std::string(); };
  for (const char* k : {"frames", "draws", "cycles", "depth_tests", "fragment_error", "passed_error", "within_thresholds",
                        "host_seconds", "cycles_per_host_second"})
    if (s.contains(k)) m[k] = cell(s[k]);
  if (s.contains("cycles")) m["cycles_per_frame"] = per_frame(s["cycles"].get<double>());
  if (s.contains("depth_tests")) m["depth_tests_per_frame"] = per_frame(s["depth_tests"].get<double>());
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

// The declared metric cells of a finished point of technique `t` that are read as they are.
void technique_metrics_of(const nlohmann::json& run, const techniques::TechniqueResults& t, std::map<std::string, std::string>& m) {
  for (const auto& metric : t.metrics)
    if (metric.derivation == techniques::Derivation::None)
      if (const nlohmann::json* v = techniques::at_pointer(run, metric.source)) m[metric.name] = cell(*v);
}

// A derived error from the point's value p and its reference's r; nullopt when it has no value.
std::optional<double> derive(techniques::Derivation d, double p, double r) {
  switch (d) {
    case techniques::Derivation::ReferenceMinusPoint: return r - p;
    case techniques::Derivation::PointMinusReference: return p - r;
    case techniques::Derivation::RelativeToReference:
      if (r > 0) return (p - r) / r;
      return std::nullopt;
    case techniques::Derivation::LossRelativeToReference:
      if (r > 0) return (r - p) / r;
      return std::nullopt;
    case techniques::Derivation::None: break;
  }
  return std::nullopt;
}

void append_unique(std::vector<std::string>& columns, const std::string& c) {
  if (std::find(columns.begin(), columns.end(), c) == columns.end()) columns.push_back(c);
}

std::optional<nlohmann::json> read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return std::nullopt;
  return j;
}

}  // namespace

std::vector<std::string> metric_columns(const std::vector<const techniques::TechniqueResults*>& ts) {
  using techniques::Derivation;
  using techniques::Section;
  std::vector<std::string> columns = kRunColumns;
  const auto section = [&](Section which) {
    for (const auto* t : ts)
      for (const auto& m : t->metrics)
        if (m.derivation == Derivation::None && m.section == which) append_unique(columns, m.name);
  };
  section(Section::Work);
  for (const auto& c : kMemoryColumns) append_unique(columns, c);
  section(Section::Memory);
  for (const auto& c : kFidelityColumns) append_unique(columns, c);
  for (const auto* t : ts) {
    if (!t->reference) continue;
    append_unique(columns, t->reference->column);
    for (const auto& m : t->metrics)
      if (m.derivation != Derivation::None) {
        append_unique(columns, m.reference_column);
        append_unique(columns, m.name);
      }
  }
  for (const auto& c : kTimingColumns) append_unique(columns, c);
  return columns;
}

std::vector<const techniques::TechniqueResults*> sweep_techniques(const std::vector<Point>& points) {
  std::vector<const techniques::TechniqueResults*> ts;
  for (const Point& p : points)
    if (const auto* t = techniques::find_technique_results(p.technique); t && std::find(ts.begin(), ts.end(), t) == ts.end())
      ts.push_back(t);
  return ts;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string q = "\"";
  for (const char ch : text) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + '"';
}

const std::string& ResultsTable::cell(std::size_t row, const std::string& column) const {
  static const std::string none;
  const auto it = std::find(header.begin(), header.end(), column);
  if (it == header.end() || row >= rows.size()) return none;
  return rows[row][static_cast<std::size_t>(it - header.begin())];
}

void write_results_csv(const fs::path& file, const fs::path& out, const std::vector<Point>& points,
                       const std::vector<std::string>& parameters, const std::map<std::string, TraceFile>& traces,
                       const std::string& version) {
  // The file is written only when whole: a run.json that cannot be read leaves no partial results.csv.
  const ResultsTable t = results_table(out, points, parameters, traces, version);
  std::ostringstream csv;
  for (const auto* row : {&t.header}) {
    for (std::size_t i = 0; i < row->size(); ++i) csv << (i ? "," : "") << csv_field((*row)[i]);
    csv << '\n';
  }
  for (const auto& row : t.rows) {
    for (std::size_t i = 0; i < row.size(); ++i) csv << (i ? "," : "") << csv_field(row[i]);
    csv << '\n';
  }
  std::ofstream f(file);
  f << csv.str();
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

ResultsTable results_table(const fs::path& out, const std::vector<Point>& points, const std::vector<std::string>& parameters,
                           const std::map<std::string, TraceFile>& traces, const std::string& version) {
  ResultsTable table;
  // Every finished run first: the error columns compare a point with its reference points.
  std::map<std::string, nlohmann::json> runs;
  for (const Point& p : points)
    if (point_done(out, p))
      if (auto run = read_json(point_dir(out, p) / "run.json")) runs[p.id] = std::move(*run);
  const auto value_of = [&runs](const std::string& id, const std::string& pointer) -> std::optional<double> {
    const auto it = runs.find(id);
    if (id.empty() || it == runs.end()) return std::nullopt;
    const nlohmann::json* v = techniques::at_pointer(it->second, pointer);
    if (!v || !v->is_number()) return std::nullopt;
    return v->get<double>();
  };
  const auto errors = [&](const Point& p, const techniques::TechniqueResults* t, std::map<std::string, std::string>& m) {
    if (t && t->reference) {
      m[t->reference->column] = p.technique_reference;
      for (const auto& metric : t->metrics) {
        if (metric.derivation == techniques::Derivation::None) continue;
        const auto mine = value_of(p.id, metric.source);
        const auto ref = value_of(p.technique_reference, metric.source);
        if (ref) m[metric.reference_column] = number(*ref);
        if (mine && ref)
          if (const auto e = derive(metric.derivation, *mine, *ref)) m[metric.name] = number(*e);
      }
    }
    // The generic timing reference: cycle_error = (cycles - reference cycles) / reference cycles.
    m["timing_reference"] = p.timing_reference;
    const auto cycles = value_of(p.id, "/summary/cycles");
    const auto ref_cycles = value_of(p.timing_reference, "/summary/cycles");
    if (ref_cycles) m["reference_cycles"] = number(*ref_cycles);
    if (cycles && ref_cycles)
      if (const auto e = derive(techniques::Derivation::RelativeToReference, *cycles, *ref_cycles)) m["cycle_error"] = number(*e);
  };
  const std::vector<std::string> columns = metric_columns(sweep_techniques(points));

  std::vector<std::string>& header = table.header;
  header = {"point_id", "role", "trace", "trace_crc32", "nbsim_version"};
  header.insert(header.end(), parameters.begin(), parameters.end());
  header.push_back("status");
  header.insert(header.end(), columns.begin(), columns.end());
  header.push_back("error");
  for (const Point& p : points) {
    const fs::path dir = point_dir(out, p);
    const auto run = point_done(out, p) ? read_json(dir / "run.json") : std::nullopt;
    std::vector<std::string> row = {p.id, p.role, p.trace, traces.at(p.trace).crc32,
                                    run && run->contains("nbsim_version") ? cell((*run)["nbsim_version"]) : version};
    for (const auto& k : parameters) row.push_back(cell(p.parameters.value(k, nlohmann::json())));
    if (run) {
      row.push_back("ok");
      const techniques::TechniqueResults* t = techniques::find_technique_results(p.technique);
      std::map<std::string, std::string> m;
      try {
        m = generic_metrics_of(*run);
        if (t) technique_metrics_of(*run, *t, m);
        errors(p, t, m);
      } catch (const nlohmann::json::exception& e) {  // a run.json edited or damaged since its run
        throw InputError(fmt::format("{}: {}", (dir / "run.json").string(), config::excerpt_text(e.what())));
      }
      for (const auto& c : columns) row.push_back(m.count(c) ? m.at(c) : "");
      row.emplace_back();
    } else {
      std::string error = tail_lines(dir / "error.txt", 5);
      row.push_back(error.empty() ? "not_run" : "failed");
      row.insert(row.end(), columns.size(), "");
      row.push_back(error);
    }
    table.rows.push_back(std::move(row));
  }
  return table;
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
  for (const Point& p : points) {
    nlohmann::ordered_json e = {{"id", p.id}, {"role", p.role}, {"trace", p.trace}, {"trace_file", traces.at(p.trace).path.string()},
                                {"trace_crc32", traces.at(p.trace).crc32}, {"technique", p.technique}, {"settings", p.settings},
                                {"parameters", p.parameters}};
    if (const auto* t = techniques::find_technique_results(p.technique); t && t->reference) e[t->reference->column] = p.technique_reference;
    e["timing_reference"] = p.timing_reference;
    j["points"].push_back(std::move(e));
  }
  for (const auto* t : sweep_techniques(points))
    if (t->reference) j[t->reference->column + "_settings"] = t->reference->settings;
  j["timing_reference_settings"] = timing_reference_settings();
  std::ofstream f(file);
  f << j.dump(2) << '\n';
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

void write_technique_results_json(const fs::path& file, const std::vector<Point>& points, const std::map<std::string, TraceFile>& traces) {
  nlohmann::ordered_json j;
  j["traces"] = nlohmann::ordered_json::object();
  std::vector<std::string> notes;
  for (const Point& p : points) {
    if (j["traces"].contains(p.trace)) continue;
    const TraceFile& tf = traces.at(p.trace);
    j["traces"][p.trace] = tf.technique.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(tf.technique);
    if (!tf.note.empty()) notes.push_back(tf.note);
  }
  j["techniques"] = nlohmann::ordered_json::array();
  for (const auto* t : sweep_techniques(points)) j["techniques"].push_back(techniques::to_json(*t));
  j["generic_columns"] = {{"run", kRunColumns},
                          {"memory", kMemoryColumns},
                          {"fidelity", kFidelityColumns},
                          {"timing_reference", kTimingColumns}};
  j["timing_reference_settings"] = timing_reference_settings();
  j["notes"] = notes;
  std::ofstream f(file);
  f << j.dump(2) << '\n';
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

}  // namespace nbsim::explore
