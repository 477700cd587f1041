// The timeline recorder: streams trace-event JSON and drives SystemC's VCD writer; see timeline.h.
#include "model/sim/timeline.h"

#include <fmt/format.h>

#include <functional>
#include <utility>

#include "model/common/error.h"
#include "model/sim/unit.h"

namespace nbsim::sim {

namespace {

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string json_string(std::string_view s) {
  std::string q = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': q += "\\\""; break;
      case '\\': q += "\\\\"; break;
      case '\n': q += "\\n"; break;
      case '\t': q += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
          q += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        else
          q += c;
    }
  }
  return q + "\"";
}

// SystemC appends ".vcd" to the name it is given.
std::string vcd_base_name(const std::filesystem::path& p) {
  std::string s = p.string();
  if (s.size() > 4 && s.compare(s.size() - 4, 4, ".vcd") == 0) s.resize(s.size() - 4);
  return s;
}

}  // namespace

Timeline::Timeline(TimelineOptions options) : options_(std::move(options)) {
  if (options_.json) {
    json_.open(*options_.json);
    if (!json_) throw InputError(fmt::format("cannot write the timeline '{}'", options_.json->string()));
    json_ << "{\"traceEvents\":[\n";
    write_event(R"({"name":"process_name","ph":"M","pid":1,"tid":0,"args":{"name":"nbsim gpu: 1 us shown = 1 cycle"}})");
  }
  if (options_.vcd) {
    // SystemC reports an unwritable file as an error, which the report handler may not turn into
    // an exception yet: check first, with the user's message.
    if (!std::ofstream(*options_.vcd))
      throw InputError(fmt::format("cannot write the VCD '{}'", options_.vcd->string()));
    vcd_ = sc_core::sc_create_vcd_trace_file(vcd_base_name(*options_.vcd).c_str());
    vcd_->set_time_unit(1.0, sc_core::SC_NS);  // one VCD time step per cycle
  }
}

Timeline::~Timeline() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() explicitly to see failures
  }
}

int Timeline::add_track(const std::string& unit_name) {
  NBSIM_CHECK(!vcd_ || !sc_core::sc_is_running(), "timeline tracks are declared before sc_start");
  const int track = static_cast<int>(tracks_.size());
  Track& t = tracks_.emplace_back();
  t.name = unit_name;
  t.lanes.push_back({next_tid_++, 0});
  name_lane(t, track, 0);
  if (vcd_) sc_core::sc_trace(vcd_, t.busy, unit_name + "_busy");
  return track;
}

void Timeline::attach_units() {
  const std::function<void(sc_core::sc_object&)> visit = [&](sc_core::sc_object& o) {
    if (auto* u = dynamic_cast<Unit*>(&o)) u->attach_timeline(this, add_track(u->name()));
    for (sc_core::sc_object* child : o.get_child_objects()) visit(*child);
  };
  for (sc_core::sc_object* top : sc_core::sc_get_top_level_objects()) visit(*top);
}

Timeline::Span Timeline::begin(int track, std::uint64_t cycles) {
  Track& t = tracks_[static_cast<std::size_t>(track)];
  const std::uint64_t now = local_cycles();  // the unit's thread's time, ahead of SystemC's when decoupled
  std::size_t lane = 0;
  while (lane < t.lanes.size() && t.lanes[lane].end > now) ++lane;
  if (lane == t.lanes.size()) {
    t.lanes.push_back({next_tid_++, 0});
    name_lane(t, track, static_cast<int>(lane));
  }
  t.lanes[lane].end = now + cycles;
  ++t.open;
  t.busy = true;
  return {track, static_cast<int>(lane), now, cycles};
}

void Timeline::end(const Span& s, std::string_view label) {
  Track& t = tracks_[static_cast<std::size_t>(s.track)];
  t.busy = --t.open > 0;
  if (!json_.is_open()) return;
  if (summary_.events >= options_.max_events) {
    if (summary_.dropped++ == 0) summary_.first_dropped_cycle = s.begin;
    return;
  }
  ++summary_.events;
  write_event(fmt::format(R"({{"name":{},"cat":"busy","ph":"X","ts":{},"dur":{},"pid":1,"tid":{},"args":{{"cycles":{}}}}})",
                          json_string(label.empty() ? std::string_view("busy") : label), s.begin, s.cycles,
                          t.lanes[static_cast<std::size_t>(s.lane)].tid, s.cycles));
}

TimelineSummary Timeline::close() {
  if (closed_) return summary_;
  closed_ = true;
  if (json_.is_open()) {
    json_ << fmt::format(
        "\n],\"otherData\":{{\"time_unit\":\"cycle (ts and dur are cycles; 1 cycle = 1 ns of model time)\","
        "\"events\":{},\"dropped_events\":{},\"max_events\":{},\"first_dropped_cycle\":{}}}}}\n",
        summary_.events, summary_.dropped, options_.max_events, summary_.first_dropped_cycle);
    json_.close();
    if (!json_) throw InputError(fmt::format("writing the timeline '{}' failed", options_.json->string()));
  }
  if (vcd_) {
    // SystemC writes a time step's traced values when time moves on: the last step's changes (units
    // going idle at the end) reach the file only after one more cycle, which the VCD then ends with.
    // Not after sc_stop, which allows no more sc_start.
    if (sc_core::sc_get_status() == sc_core::SC_PAUSED) sc_core::sc_start(cycles(1));
    sc_core::sc_close_vcd_trace_file(vcd_);
    vcd_ = nullptr;
  }
  return summary_;
}

void Timeline::name_lane(const Track& t, int track, int lane) {
  if (!json_.is_open()) return;
  const int tid = t.lanes[static_cast<std::size_t>(lane)].tid;
  const std::string name = lane == 0 ? t.name : fmt::format("{} #{}", t.name, lane + 1);
  write_event(fmt::format(R"({{"name":"thread_name","ph":"M","pid":1,"tid":{},"args":{{"name":{}}}}})", tid, json_string(name)));
  write_event(fmt::format(R"({{"name":"thread_sort_index","ph":"M","pid":1,"tid":{},"args":{{"sort_index":{}}}}})", tid,
                          track * 64 + lane));
}

void Timeline::write_event(const std::string& text) {
  if (!first_event_) json_ << ",\n";
  first_event_ = false;
  json_ << text;
}

}  // namespace nbsim::sim
