// The front search of `nbsim explore --search front`: a sweep's grid explored without running all
// of it. Round 0 runs `start` points of each trace chosen at random (seeded, so a search repeats);
// every later round runs the grid neighbours (one step along one axis) of the points on each trace's
// Pareto front of cost against error, not run yet; the search ends when a round adds nothing or
// after `rounds` rounds. Cost and error are the technique's headline metrics (its declared results:
// pipeline/techniques/results.h), cycles_per_frame and no error for a trace without a declaration.
// A point's reference points run with it (its errors are measured against them).
// Plain C++ over the expanded points; the rounds run through the same runners as a whole sweep
// (local or Slurm), so the search is usable with either engine.
#pragma once

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "pipeline/explore/results.h"
#include "pipeline/explore/sweep.h"

namespace nbsim::explore {

struct SearchOptions {
  std::size_t start = 8;    // random grid points of each trace in round 0
  int rounds = 8;           // rounds at most, round 0 included
  std::uint64_t seed = 1;   // of round 0's choice
  // The columns of results.csv the front is taken on; "" takes the technique's headline metric.
  std::string cost, error;
};

class FrontSearch {
 public:
  // `points`: the expanded sweep (axes: every grid point has its Point::grid), references included.
  // Throws InputError for a sweep without axes (a listed sweep has no grid to step on).
  FrontSearch(const std::vector<Point>& points, std::size_t axis_count, SearchOptions options);

  // The indices of the points to run next (their references included), given the results of those
  // run so far (rows in `points` order, as results_table writes them); empty: the search is over.
  std::vector<std::size_t> next(const ResultsTable& done);
  // Every point chosen so far, in `points` order.
  std::vector<std::size_t> chosen() const { return {chosen_.begin(), chosen_.end()}; }
  int round() const noexcept { return round_; }

 private:
  void choose(std::size_t i, std::vector<std::size_t>& out);
  const std::vector<Point>& points_;
  std::size_t axes_;
  SearchOptions options_;
  std::set<std::size_t> chosen_;
  int round_ = 0;
};

}  // namespace nbsim::explore
