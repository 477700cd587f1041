// The results each technique declares (docs/architecture.md, "Adding a technique: the results
// side"): its cost, error and outcome metrics (read by JSON pointer from a replay's run.json), its
// reference setting (the exact point its relative errors are measured against), its paper-style
// table if it has one, and its headline cost and error for Pareto plots. `nbsim explore`
// (results.csv, technique_results.json), `nbsim table2` and analysis/report.py read this one table;
// each technique of the registration list defines its row. Plain C++ (no SystemC).
//
// The technique-independent results stay with their readers: the timing reference (cycle_error
// against gpu.quantum_cycles=0 ...) in pipeline/explore/sweep.h, counter_error against GL's
// counters and the run columns (frames, cycles, memory bytes, host seconds) in results.cpp.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nbsim/technique_list.h"

namespace nbsim::techniques {

// What a metric says about a point.
enum class MetricKind {
  Cost,     // work or memory the technique spends (lower is cheaper)
  Error,    // how wrong or how weak its answer is
  Outcome,  // a count that explains an error (culled objects, hidden candidates)
};

// Where a metric's column sits in results.csv: after the generic work columns (frames ...
// depth_tests_per_frame) or after the generic memory columns (memory_bytes_per_frame ...).
// Derived errors always sit in the reference block, after the generic fidelity columns.
enum class Section { Work, Memory };

// How a derived error is computed from the point's value p and its reference point's value r.
enum class Derivation {
  None,                 // read as it is from `source`
  ReferenceMinusPoint,  // r - p (a quality the reference maximises: efficiency lost)
  PointMinusReference,  // p - r
  RelativeToReference,  // (p - r) / r, empty when r is 0
  LossRelativeToReference,  // (r - p) / r, empty when r is 0 (a count the reference maximises, lost as a fraction of it)
};

struct Metric {
  std::string name;         // the results.csv column (and table2.json key)
  std::string unit;         // "depth tests", "fraction", "objects", "bytes", ...
  std::string description;  // one line
  MetricKind kind = MetricKind::Cost;
  // JSON pointer into run.json: the value itself, or for a derived error the value compared
  // between the point and its reference.
  std::string source;
  Section section = Section::Work;
  Derivation derivation = Derivation::None;
  // For a derived error: the column that shows the reference point's value of `source`.
  std::string reference_column;
  // A correctness count that must be 0 for a conservative technique (false culls, popping, mask
  // pixels unlike GL's): table2 exits 1 and the report flags the point otherwise.
  bool must_be_zero = false;
};

// The exact (most accurate) point of a technique: a point's settings with `settings` applied,
// every key starting with one of `reset_prefixes` back at its default, and keys this build's
// config lacks left out. A point whose `skip_key` has one of `skip_values` (or that lacks the key)
// has no reference: it runs nothing the errors measure.
struct ReferenceSetting {
  std::string column;  // results.csv: the id of the reference point ("culling_reference")
  std::string description;
  nlohmann::json settings = nlohmann::json::object();  // flat config keys -> values
  std::vector<std::string> reset_prefixes;
  std::string skip_key;
  std::vector<std::string> skip_values;
};

// One row of a paper-style table (`nbsim table2`): the row's replay runs with the table's row key
// set to `value`. `paper` is the paper's number for the table's paper column, when it has one.
struct TableRow {
  std::string value;
  std::string paper_label;
  std::optional<double> paper;
  // Settings changed for this row only when the user's config has a given value (e.g. a row
  // whose test cannot run per primitive sets cull.granularity back to object).
  struct Override {
    std::string key, when, set;
  };
  std::vector<Override> overrides;
};

// How a printed table column shows its value.
enum class CellFormat {
  Text,     // left-aligned text (the row's value)
  Paper,    // the paper's number without decimals, "-" when it has none
  Fixed0,   // a number with 0 decimals
  Fixed1,   // a number with 1 decimal
  Count,    // an unsigned integer
  Percent,  // a fraction printed as a percentage with 1 decimal
};

struct PrintedColumn {
  std::string header;  // the text table's header
  std::string column;  // the table2.json key
  int width = 0;
  CellFormat format = CellFormat::Fixed1;
};

struct TableSpec {
  std::string command;      // "table2"
  std::string title;        // the first line of the text output (trace and frames follow)
  std::string row_key;      // the config key each row sets ("cull.mode")
  std::string row_column;   // the key of a row's value in table2.json ("mode")
  std::string paper_label_column, paper_value_column;  // "paper", "paper_depth_tests_per_frame"
  std::string section;      // JSON pointer into run.json that every row's replay must have
  // table2.json columns after the paper's: each a name and its JSON pointer into run.json.
  std::vector<std::pair<std::string, std::string>> columns;
  std::vector<TableRow> rows;
  std::vector<PrintedColumn> printed;
  // The ratio line: `column` of row `numerator` over that of row `denominator`, and the paper's.
  struct Ratio {
    std::string label, numerator, denominator, column, paper;
  };
  std::optional<Ratio> ratio;
  // Printed when row `row` has `column` equal to `value`.
  struct Note {
    std::string row, column, value, text;
  };
  std::vector<Note> notes;
  std::string must_be_zero;  // the column whose sum makes the command exit 1 ("false_culls")
  std::string footer;        // the command's --help footer
};

// How analysis/report.py shows the headlines (axis labels, table headers, Pareto column names,
// plot file suffixes): the technique's words, written into technique_results.json.
struct ReportLabels {
  std::string error_axis, error_text, error_column;           // the headline error (in points of %)
  std::string fallback_axis, fallback_text, fallback_column;  // 1 - fallback_error (in %)
  std::string cost_axis, cost_column, cost_pareto, cost_short;  // the headline cost
  std::string memory_axis, memory_pareto, memory_short;       // memory_cost, plotted in KiB
  std::string quality_column;  // the fallback error metric's own column (a fraction)
  std::string must_be_zero;    // the correctness count's name in plots ("false culls")
  std::string alike;           // what a sweep without a trade-off has in common ("culls alike")
};

struct TechniqueResults {
  std::string technique;  // as the trace header's `technique` property carries it
  std::string description;
  std::vector<Metric> metrics;  // in results.csv column order within each section
  std::optional<ReferenceSetting> reference;
  std::optional<TableSpec> table;
  std::string headline_cost;   // a metric name (Cost) for Pareto plots
  std::string headline_error;  // a metric name (Error) for Pareto plots
  // The error to plot when a results.csv lacks the headline error (no reference ran): this
  // Error metric, a fraction, plotted as 1 - value.
  std::string fallback_error;
  std::string memory_cost;  // a Cost metric in bytes plotted as a third Pareto front, or ""
  ReportLabels report;
};

// Helpers for a technique's declaration (pipeline/techniques/<name>/results.cpp): a metric read from
// run.json at `source` (a JSON pointer); an Error derived from `source` in the point and in its
// reference point (the reference's value shown in `reference_column`); the labels of a technique
// whose headline cost is total depth tests per frame and whose memory cost is the N-buffer's.
Metric metric(const char* name, const char* unit, const char* description, MetricKind kind, std::string source);
Metric derived_error(const char* name, const char* unit, const char* description, std::string source, Derivation derivation,
                     const char* reference_column);
void depth_test_and_nbuffer_labels(ReportLabels& l);

// Each technique of the registration list (cmake/NbsimTechniques.cmake) defines its row,
// TechniqueResults <name>_results(), in its folder pipeline/techniques/<name>/.
#define NBSIM_DECLARE_TECHNIQUE_RESULTS(name) TechniqueResults name##_results();
NBSIM_EACH_TECHNIQUE(NBSIM_DECLARE_TECHNIQUE_RESULTS)
#undef NBSIM_DECLARE_TECHNIQUE_RESULTS

// Every technique's results, one row each, in the registration list's order.
const std::vector<TechniqueResults>& technique_results();

// The row of `technique`, or nullptr when it declares none.
const TechniqueResults* find_technique_results(std::string_view technique);

// The metric `name` of `t`, or nullptr.
const Metric* find_metric(const TechniqueResults& t, std::string_view name);

// The JSON form (technique_results.json, `nbsim explore`'s out folder): analysis/report.py reads
// the metric names, units and headlines from it.
nlohmann::ordered_json to_json(const TechniqueResults& t);

// The enum names used in that JSON.
std::string_view name_of(MetricKind k);
std::string_view name_of(Section s);
std::string_view name_of(Derivation d);

// The value of a JSON pointer in `j`, or nullptr when it is absent (or the pointer is malformed).
const nlohmann::json* at_pointer(const nlohmann::json& j, const std::string& pointer);

}  // namespace nbsim::techniques
