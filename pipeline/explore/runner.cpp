// Runs the points of a sweep as child processes; see runner.h.
#include "pipeline/explore/runner.h"

#include <fmt/format.h>
#include <zlib.h>

#include <fstream>

#include "model/common/error.h"
#include "pipeline/explore/child.h"
#include "pipeline/techniques/results.h"
#include "traces/format/reader.h"

namespace nbsim::explore {

namespace fs = std::filesystem;

TraceFile inspect_trace(const std::string& as_written, bool checksum) {
  std::error_code ec;
  const fs::path p = fs::absolute(as_written, ec);
  if (ec || !fs::is_regular_file(p, ec)) throw InputError(fmt::format("trace '{}' does not exist or is not a file", as_written));
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError(fmt::format("trace '{}' cannot be read", as_written));
  uLong crc = crc32(0L, Z_NULL, 0);
  std::vector<char> buf(1 << 20);
  while (checksum && in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    const auto n = in.gcount();
    if (n > 0) crc = crc32(crc, reinterpret_cast<const Bytef*>(buf.data()), static_cast<uInt>(n));
  }
  TraceFile t{p, checksum ? fmt::format("{:08x}", static_cast<std::uint32_t>(crc)) : std::string(), "", ""};
  try {
    const trace::TraceReader reader(p);
    if (const std::string* technique = reader.property("technique")) t.technique = *technique;
  } catch (const std::exception& e) {  // InputError, or a read error: every point would fail
    throw InputError(fmt::format("trace '{}' cannot be opened as a trace: {}", as_written, e.what()));
  }
  if (t.technique.empty())
    t.note = fmt::format("trace '{}' names no technique in its header: results.csv has the generic columns only for it", as_written);
  else if (!techniques::find_technique_results(t.technique))
    t.note = fmt::format(
        "trace '{}': technique '{}' declares no results (pipeline/techniques/results.cpp): results.csv has the generic "
        "columns only for it",
        as_written, t.technique);
  return t;
}

fs::path point_dir(const fs::path& out, const Point& p) { return out / "points" / p.id; }

bool point_done(const fs::path& out, const Point& p) {
  std::ifstream in(point_dir(out, p) / "run.json");
  if (!in) return false;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  return !j.is_discarded() && j.contains("summary");
}

bool record_refused(const fs::path& out, const Point& p) {
  if (p.refused.empty()) return false;
  const fs::path dir = point_dir(out, p);
  fs::create_directories(dir);
  fs::remove(dir / "run.json");
  std::ofstream cfg(dir / "config.json");
  cfg << p.settings.dump(2) << '\n';
  std::ofstream e(dir / "error.txt");
  e << "refused before any replay, the design cannot be built: " << p.refused << '\n';
  if (!cfg || !e) throw std::runtime_error(fmt::format("cannot write the refused point's files in {}", dir.string()));
  return true;
}

RunReport run_points(const std::vector<Point>& points, const std::map<std::string, TraceFile>& traces, const RunOptions& o) {
  RunReport report;
  std::vector<const Point*> pending;
  std::vector<ChildJob> jobs;
  for (const Point& p : points) {
    if (record_refused(o.out, p)) {
      ++report.failed;
      continue;
    }
    if (point_done(o.out, p)) {
      ++report.resumed;
      continue;
    }
    const fs::path dir = point_dir(o.out, p);
    fs::create_directories(dir);
    for (const char* stale : {"run.json", "error.txt"}) fs::remove(dir / stale);
    {
      std::ofstream cfg(dir / "config.json");
      cfg << p.settings.dump(2) << '\n';
      if (!cfg) throw std::runtime_error(fmt::format("cannot write {}", (dir / "config.json").string()));
    }
    const auto t = traces.find(p.trace);
    NBSIM_CHECK(t != traces.end(), "no trace file for '" + p.trace + "'");
    jobs.push_back({{"replay", t->second.path.string(), "--out", dir.string(), "--config", (dir / "config.json").string()}, dir});
    pending.push_back(&p);
  }
  std::size_t done = 0;
  if (o.progress) o.progress(0, jobs.size());
  run_children(o.exe, jobs, o.jobs, [&](std::size_t i, const ChildOutcome& outcome) {
    ++report.ran;
    const Point& p = *pending[i];
    std::string error = outcome.error;
    if (outcome.ok && !point_done(o.out, p)) error = "the replay ended without writing a run.json with a summary";
    if (!error.empty()) {
      ++report.failed;
      fs::remove(jobs[i].dir / "run.json");  // never resumed as done
      std::ofstream e(jobs[i].dir / "error.txt");
      e << error << '\n';
    }
    if (o.progress) o.progress(++done, jobs.size());
  });
  return report;
}

}  // namespace nbsim::explore
