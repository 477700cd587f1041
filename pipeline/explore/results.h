// The tidy outputs of `nbsim explore`: OUT/results.csv (one row per point and trace, one column
// per parameter and per metric, read from each point's run.json or error.txt) and OUT/sweep.json.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "pipeline/explore/runner.h"
#include "pipeline/explore/sweep.h"

namespace nbsim::explore {

// The metric columns of results.csv, in order, after the parameter columns and "status". Cull
// metrics are empty in the "trace" culling mode; memory bytes are the shared channel's.
const std::vector<std::string>& metric_columns();

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
