// The tidy outputs of `nbsim explore`: OUT/results.csv (one row per point and trace, one column
// per parameter and per metric, read from each point's run.json or error.txt), OUT/sweep.json and
// OUT/technique_results.json (the declared results of the sweep's techniques, for the report).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "pipeline/explore/runner.h"
#include "pipeline/explore/sweep.h"
#include "pipeline/techniques/results.h"

namespace nbsim::explore {

// The metric columns of results.csv, in order, after the parameter columns and "status": the
// generic run columns (frames ... depth_tests_per_frame), the techniques' work metrics, the generic
// memory columns (memory bytes are the shared channel's), the techniques' memory metrics, the
// generic fidelity columns (counter_error ... cycles_per_host_second), each technique's reference
// block (its reference column, then each derived error's reference value and the error), and the
// generic timing reference (timing_reference, reference_cycles, cycle_error). `techniques` are the
// declared techniques of the sweep's traces, in trace order (a name shared by two is one column).
// A technique's cells are empty in rows of other techniques and where run.json lacks the value
// (cull metrics in the "trace" culling mode).
std::vector<std::string> metric_columns(const std::vector<const techniques::TechniqueResults*>& techniques);

// The declared techniques of the points' traces, in order of first appearance, without repeats;
// points whose trace names no technique, or one without a declaration, add nothing.
std::vector<const techniques::TechniqueResults*> sweep_techniques(const std::vector<Point>& points);

// Writes technique_results.json: every trace's technique, the declarations of the sweep's
// techniques (to_json), the generic columns and the notes on traces whose technique has no row.
void write_technique_results_json(const std::filesystem::path& file, const std::vector<Point>& points,
                                  const std::map<std::string, TraceFile>& traces);

// results.csv as a table: the header, then one row of cells a point (what write_results_csv writes).
struct ResultsTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  // The cell of `row` in `column`, "" when the header has no such column.
  const std::string& cell(std::size_t row, const std::string& column) const;
};
ResultsTable results_table(const std::filesystem::path& out, const std::vector<Point>& points, const std::vector<std::string>& parameters,
                           const std::map<std::string, TraceFile>& traces, const std::string& version);
// Writes results.csv. `version` fills nbsim_version for failed points (which have no run.json).
void write_results_csv(const std::filesystem::path& file, const std::filesystem::path& out, const std::vector<Point>& points,
                       const std::vector<std::string>& parameters, const std::map<std::string, TraceFile>& traces,
                       const std::string& version);

// Writes sweep.json: the sweep file's name, the parameters and every expanded point.
void write_sweep_json(const std::filesystem::path& file, const std::string& sweep_file, const SweepSpec& spec,
                      const std::vector<Point>& points, const std::vector<std::string>& parameters,
                      const std::map<std::string, TraceFile>& traces, const std::string& version);

// One CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv_field(const std::string& text);

}  // namespace nbsim::explore
