// The table of the results each technique declares, and their helpers; see results.h.
#include "pipeline/techniques/results.h"

#include <algorithm>


namespace nbsim::techniques {

Metric metric(const char* name, const char* unit, const char* description, MetricKind kind, std::string source) {
  Metric m;
  m.name = name;
  m.unit = unit;
  m.description = description;
  m.kind = kind;
  m.source = std::move(source);
  return m;
}

// An Error derived from `source` in the point and in its reference point (the reference's value
// shown in `reference_column`).
Metric derived_error(const char* name, const char* unit, const char* description, std::string source, Derivation derivation,
                     const char* reference_column) {
  Metric m = metric(name, unit, description, MetricKind::Error, std::move(source));
  m.derivation = derivation;
  m.reference_column = reference_column;
  return m;
}

// The labels of a technique whose headline cost is total depth tests per frame and whose memory
// cost is the N-buffer's (e.g. the techniques that cull primitives with an N-buffer).
void depth_test_and_nbuffer_labels(ReportLabels& l) {
  l.cost_axis = "total depth tests per frame";
  l.cost_column = "total depth tests/frame";
  l.cost_pareto = "pareto_depth_tests";
  l.cost_short = "tests";
  l.memory_axis = "N-buffer memory (KiB)";
  l.memory_pareto = "pareto_memory";
  l.memory_short = "memory";
}

const std::vector<TechniqueResults>& technique_results() {
  // One row per technique of the registration list, declared in its folder (pipeline/techniques/<name>/).
#define NBSIM_TECHNIQUE_RESULTS(name) name##_results(),
  static const std::vector<TechniqueResults> table = {NBSIM_EACH_TECHNIQUE(NBSIM_TECHNIQUE_RESULTS)};
#undef NBSIM_TECHNIQUE_RESULTS
  return table;
}

const TechniqueResults* find_technique_results(std::string_view technique) {
  for (const auto& t : technique_results())
    if (t.technique == technique) return &t;
  return nullptr;
}

const Metric* find_metric(const TechniqueResults& t, std::string_view name) {
  const auto it = std::find_if(t.metrics.begin(), t.metrics.end(), [name](const Metric& m) { return m.name == name; });
  return it == t.metrics.end() ? nullptr : &*it;
}

std::string_view name_of(MetricKind k) {
  switch (k) {
    case MetricKind::Cost: return "cost";
    case MetricKind::Error: return "error";
    case MetricKind::Outcome: return "outcome";
  }
  return "?";
}

std::string_view name_of(Section s) { return s == Section::Work ? "work" : "memory"; }

std::string_view name_of(Derivation d) {
  switch (d) {
    case Derivation::None: return "none";
    case Derivation::ReferenceMinusPoint: return "reference_minus_point";
    case Derivation::PointMinusReference: return "point_minus_reference";
    case Derivation::RelativeToReference: return "relative_to_reference";
    case Derivation::LossRelativeToReference: return "loss_relative_to_reference";
  }
  return "?";
}

nlohmann::ordered_json to_json(const TechniqueResults& t) {
  nlohmann::ordered_json j;
  j["technique"] = t.technique;
  j["description"] = t.description;
  j["metrics"] = nlohmann::ordered_json::array();
  for (const Metric& m : t.metrics) {
    nlohmann::ordered_json e = {{"name", m.name},     {"unit", m.unit},    {"description", m.description},
                                {"kind", name_of(m.kind)}, {"source", m.source}, {"section", name_of(m.section)},
                                {"derivation", name_of(m.derivation)}};
    if (!m.reference_column.empty()) e["reference_column"] = m.reference_column;
    e["must_be_zero"] = m.must_be_zero;
    j["metrics"].push_back(std::move(e));
  }
  if (t.reference) {
    j["reference"] = {{"column", t.reference->column},
                      {"description", t.reference->description},
                      {"settings", t.reference->settings},
                      {"reset_prefixes", t.reference->reset_prefixes},
                      {"skip_key", t.reference->skip_key},
                      {"skip_values", t.reference->skip_values}};
  } else {
    j["reference"] = nullptr;
  }
  j["table"] = t.table ? nlohmann::ordered_json(t.table->command) : nlohmann::ordered_json(nullptr);
  j["headline_cost"] = t.headline_cost;
  j["headline_error"] = t.headline_error;
  j["fallback_error"] = t.fallback_error;
  j["memory_cost"] = t.memory_cost;
  const ReportLabels& l = t.report;
  j["report"] = {{"error_axis", l.error_axis},         {"error_text", l.error_text},       {"error_column", l.error_column},
                 {"fallback_axis", l.fallback_axis},   {"fallback_text", l.fallback_text}, {"fallback_column", l.fallback_column},
                 {"cost_axis", l.cost_axis},           {"cost_column", l.cost_column},     {"cost_pareto", l.cost_pareto},
                 {"cost_short", l.cost_short},         {"memory_axis", l.memory_axis},     {"memory_pareto", l.memory_pareto},
                 {"memory_short", l.memory_short},     {"quality_column", l.quality_column}, {"must_be_zero", l.must_be_zero},
                 {"alike", l.alike}};
  return j;
}

const nlohmann::json* at_pointer(const nlohmann::json& j, const std::string& pointer) {
  try {
    const nlohmann::json::json_pointer p(pointer);
    if (!j.contains(p)) return nullptr;
    return &j.at(p);
  } catch (const nlohmann::json::exception&) {
    return nullptr;  // malformed pointer, or an array index that is not a number
  }
}

}  // namespace nbsim::techniques
