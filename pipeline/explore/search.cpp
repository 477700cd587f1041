// The front search; see search.h.
#include "pipeline/explore/search.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <random>

#include "model/common/error.h"
#include "pipeline/techniques/results.h"

namespace nbsim::explore {

FrontSearch::FrontSearch(const std::vector<Point>& points, std::size_t axis_count, SearchOptions options)
    : points_(points), axes_(axis_count), options_(options) {
  if (axis_count == 0) throw InputError("--search front steps along a sweep's axes: this sweep lists its points (no axes)");
  if (options.start < 1) throw InputError("--search-start must be at least 1");
  if (options.rounds < 1) throw InputError("--search-rounds must be at least 1");
}

void FrontSearch::choose(std::size_t i, std::vector<std::size_t>& out) {
  if (!chosen_.insert(i).second) return;
  out.push_back(i);
  // Its references run with it.
  const Point& p = points_[i];
  for (const std::string* id : {&p.technique_reference, &p.timing_reference}) {
    if (id->empty()) continue;
    for (std::size_t j = 0; j < points_.size(); ++j)
      if (points_[j].id == *id && chosen_.insert(j).second) out.push_back(j);
  }
}

std::vector<std::size_t> FrontSearch::next(const ResultsTable& done) {
  std::vector<std::size_t> out;
  if (round_ >= options_.rounds) return out;
  std::map<std::string, std::vector<std::size_t>> by_trace;  // the grid points of each trace
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (points_[i].role == "sweep" && points_[i].grid.size() == axes_) by_trace[points_[i].trace].push_back(i);
  if (round_ == 0) {
    std::mt19937_64 rng(options_.seed);
    for (auto& [trace, list] : by_trace) {
      std::vector<std::size_t> order = list;
      std::shuffle(order.begin(), order.end(), rng);
      for (std::size_t k = 0; k < std::min(options_.start, order.size()); ++k) choose(order[k], out);
    }
  } else {
    // Each trace's front among the points run and ok; their grid neighbours not run yet.
    std::map<std::vector<int>, std::size_t> at;  // (trace index, grid) -> point
    std::map<std::string, int> trace_no;
    for (const auto& [trace, list] : by_trace) {
      const int t = static_cast<int>(trace_no.size());
      trace_no[trace] = t;
      for (std::size_t i : list) {
        std::vector<int> key = points_[i].grid;
        key.insert(key.begin(), t);
        at[key] = i;
      }
    }
    for (const auto& [trace, list] : by_trace) {
      struct Value {
        std::size_t i;
        double cost, error;
      };
      std::vector<Value> values;
      for (std::size_t i : list) {
        if (!chosen_.count(i) || i >= done.rows.size() || done.cell(i, "status") != "ok") continue;
        const techniques::TechniqueResults* t = techniques::find_technique_results(points_[i].technique);
        const std::string cost_col =
            !options_.cost.empty() ? options_.cost : t && !t->headline_cost.empty() ? t->headline_cost : "cycles_per_frame";
        const std::string error_col = !options_.error.empty() ? options_.error : t ? t->headline_error : "";
        const std::string& c = done.cell(i, cost_col);
        const std::string& e = error_col.empty() ? std::string() : done.cell(i, error_col);
        if (c.empty()) continue;
        values.push_back({i, std::stod(c), e.empty() ? 0.0 : std::stod(e)});
      }
      for (const Value& v : values) {
        const bool dominated = std::any_of(values.begin(), values.end(), [&](const Value& o) {
          return o.cost <= v.cost && o.error <= v.error && (o.cost < v.cost || o.error < v.error);
        });
        if (dominated) continue;
        for (std::size_t a = 0; a < axes_; ++a)
          for (int step : {-1, 1}) {
            std::vector<int> key = points_[v.i].grid;
            key[a] += step;
            key.insert(key.begin(), trace_no[trace]);
            if (const auto it = at.find(key); it != at.end()) choose(it->second, out);
          }
      }
    }
  }
  ++round_;
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace nbsim::explore
