// Runs the points of a sweep (`nbsim explore`): one `nbsim replay` child per point, N at a time,
// into OUT/points/<id>/, skipping points whose run.json is already there, and recording failures
// in OUT/points/<id>/error.txt. Then writes OUT/results.csv and OUT/sweep.json (results.h).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "pipeline/explore/sweep.h"

namespace nbsim::explore {

// A trace of the sweep: where it is, its checksum (zlib crc32 of the whole file, 8 hex digits)
// and the technique its header names.
struct TraceFile {
  std::filesystem::path path;  // absolute
  std::string crc32;
  std::string technique;  // the header's `technique` property; "" when absent
  // Why the trace's results have the generic columns only ("" when its technique declares its
  // results): no technique property, or a technique without a row in pipeline/techniques/results.cpp.
  std::string note;
};

// Resolves a trace named in a sweep (relative: from the current directory), checksums it and
// reads its technique; throws InputError naming the file when it does not exist, cannot be read,
// or cannot be opened as a trace (TraceReader: preamble, header and scene), so that a sweep over
// a file that is not a trace is refused before any point runs. Damage after the header is found
// by the replay: its points fail one by one in results.csv. Without `checksum` (one point run by
// itself: each Slurm task), crc32 stays "" and the file is not read whole.
TraceFile inspect_trace(const std::string& as_written, bool checksum = true);

struct RunOptions {
  std::filesystem::path out;   // the sweep's folder
  std::filesystem::path exe;   // the nbsim executable that runs `replay`
  int jobs = 1;                // children at a time
  std::function<void(std::size_t done, std::size_t total)> progress;  // after each child ends
};

struct RunReport {
  std::size_t ran = 0;      // children started this time (including failures)
  std::size_t resumed = 0;  // points done before, not run again
  std::size_t failed = 0;   // points that failed this time (refused design points included)
};

// Records a refused design point (Point::refused) as failed: its folder, config.json and an
// error.txt naming why; returns false when the point is not refused.
bool record_refused(const std::filesystem::path& out, const Point& p);

// The folder of one point.
std::filesystem::path point_dir(const std::filesystem::path& out, const Point& p);
// True when the point's run.json exists and holds a summary: such a point is not run again.
bool point_done(const std::filesystem::path& out, const Point& p);

// Runs every point that is not done. `traces` maps each trace as written to its file.
RunReport run_points(const std::vector<Point>& points, const std::map<std::string, TraceFile>& traces, const RunOptions& o);

}  // namespace nbsim::explore
