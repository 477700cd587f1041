// Timelines of unit activity, for debugging a design visually: every sim::Unit reports the spans it
// is busy (the waits of Unit::work) to a Timeline when a run asks for one; otherwise nothing is kept.
//
// Two outputs, both optional:
// - A Chrome / Perfetto trace-event JSON ({"traceEvents": [...]}), streamed to the file as spans
//   end (memory stays bounded). One "X" (complete) event per span; pid 1 is the GPU, one tid and a
//   thread_name track per unit. ts and dur are CYCLES written where the format expects
//   microseconds: a viewer's "1 us" is one cycle (1 ns of model time). A unit whose spans overlap
//   (two threads calling work(), as the N-buffer unit's query port and update engine do) gets extra
//   tracks "<unit> #2", ... so that no track holds overlapping spans.
// - A VCD of one busy bit per unit, written by SystemC's own sc_trace (time unit 1 ns = 1 cycle);
//   the bit is 1 while at least one span of the unit is open.
#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "model/sim/kernel.h"

namespace nbsim::sim {

struct TimelineOptions {
  std::optional<std::filesystem::path> json;  // trace-event JSON (ui.perfetto.dev, chrome://tracing)
  std::optional<std::filesystem::path> vcd;   // busy bits (GTKWave)
  // Spans written to the JSON at most (about 100 bytes each); later spans are counted, not written,
  // and the file says so. Tunable: a cap on file size, not a memory bound (nothing is held).
  std::uint64_t max_events = 5'000'000;
};

// What a timeline recorded, for the run's report.
struct TimelineSummary {
  std::uint64_t events = 0;               // spans written to the JSON
  std::uint64_t dropped = 0;              // spans past max_events, not written
  std::uint64_t first_dropped_cycle = 0;  // begin cycle of the first dropped span
};

class Timeline {
 public:
  // Opens the files. Throws InputError when one cannot be written. Create it before sc_start.
  explicit Timeline(TimelineOptions options);
  ~Timeline();
  Timeline(const Timeline&) = delete;
  Timeline& operator=(const Timeline&) = delete;

  // Declares a unit's track; returns its number. Before sc_start (the VCD's variables are fixed then).
  int add_track(const std::string& unit_name);
  // Declares a track for every sim::Unit in the module hierarchy (depth first, in construction
  // order) and attaches the unit to it. Call after elaboration, before sc_start.
  void attach_units();

  // One span of a track: begin() when the wait starts, end() when it is over.
  struct Span {
    int track = 0;
    int lane = 0;
    std::uint64_t begin = 0;
    std::uint64_t cycles = 0;
  };
  Span begin(int track, std::uint64_t cycles);
  void end(const Span& span, std::string_view label);

  // Finishes the JSON and closes the VCD (after sc_start returns). Safe to call twice.
  TimelineSummary close();
  const TimelineSummary& summary() const noexcept { return summary_; }

 private:
  struct Lane {
    int tid = 0;
    std::uint64_t end = 0;  // the cycle its last span ends
  };
  struct Track {
    std::string name;
    std::vector<Lane> lanes;
    int open = 0;       // spans in progress
    bool busy = false;  // traced into the VCD: open > 0
  };
  void name_lane(const Track& t, int track, int lane);
  void write_event(const std::string& text);

  TimelineOptions options_;
  std::ofstream json_;
  sc_core::sc_trace_file* vcd_ = nullptr;
  std::deque<Track> tracks_;  // deque: the traced `busy` bits keep their addresses
  int next_tid_ = 1;
  bool first_event_ = true;
  bool closed_ = false;
  TimelineSummary summary_;
};

}  // namespace nbsim::sim
