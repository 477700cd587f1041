// AppsUnit; see unit.h.
#include "model/apps/unit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "model/common/error.h"

namespace nbsim::apps {

namespace {

constexpr double kMinRate = 0.01, kMaxRate = 4096.0;

std::uint64_t ceil_div(double work, double per_cycle) {
  if (work <= 0.0) return 0;
  return static_cast<std::uint64_t>(std::ceil(work / per_cycle));
}

}  // namespace

void AppsUnitConfig::describe(config::Schema& s, AppsUnitConfig& c) {
  s.add("apps.setup_triangles_per_cycle", c.setup_triangles_per_cycle, "triangles/cycle", "a replayed draw's triangles through setup a cycle",
        kMinRate, kMaxRate);
  s.add("apps.tests_per_cycle", c.tests_per_cycle, "tests/cycle", "depth tests of a replayed draw a cycle", kMinRate, kMaxRate);
  s.add("apps.draw_overhead_cycles", c.draw_overhead_cycles, "cycles", "a draw's state and launch (flagged draws cost this only)", 0, 100000);
  s.add("apps.oq_latency_cycles", c.oq_latency_cycles, "cycles",
        "cull.mode=oq: an occlusion query's round trip, which the draw it tests waits for", 0, 1000000);
}

void AppsUnitConfig::validate() const {
  for (const auto& [key, v] : {std::pair{"apps.setup_triangles_per_cycle", setup_triangles_per_cycle}, std::pair{"apps.tests_per_cycle", tests_per_cycle}})
    if (!(v >= kMinRate && v <= kMaxRate)) throw InputError(fmt::format("{} is {}, not in [{}, {}]", key, v, kMinRate, kMaxRate));
  if (draw_overhead_cycles < 0 || draw_overhead_cycles > 100000)
    throw InputError(fmt::format("apps.draw_overhead_cycles is {}, not in [0, 100000]", draw_overhead_cycles));
  if (oq_latency_cycles < 0 || oq_latency_cycles > 1000000)
    throw InputError(fmt::format("apps.oq_latency_cycles is {}, not in [0, 1000000]", oq_latency_cycles));
}

AppsUnit::AppsUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const AppsUnitConfig& config, const AppsCull& cull,
                   std::ostream* log)
    : sim::Unit(name, registry),
      cull_(cull),
      config_((config.validate(), config)),
      log_(log),
      frames_(stats().counter("frames", "frames", "frames replayed")),
      draws_(stats().counter("draws", "draws", "draw calls recorded")),
      replayed_(stats().counter("replayed", "draws", "draws the model replayed (not flagged)")),
      compared_(stats().counter("compared", "draws", "replayed draws compared with GL's samples passed (their target not stale)")),
      matched_(stats().counter("matched", "draws", "compared draws whose samples passed equal GL's")),
      mismatched_(stats().counter("mismatched", "draws", "compared draws whose samples passed differ from GL's (expected 0)")),
      after_stale_(stats().counter("after_stale", "draws", "replayed draws after a stale change of their target: not compared")),
      depth_changes_(stats().counter("depth_changes", "draws", "flagged draws whose recorded depth change was applied")),
      clears_(stats().counter("clears", "clears", "depth and stencil clears applied")),
      triangles_(stats().counter("triangles", "triangles", "captured triangles of the replayed draws")),
      fragments_(stats().counter("fragments", "fragments", "the model's rasterized fragments of the replayed draws")),
      depth_tests_(stats().counter("depth_tests", "tests", "the model's depth tests of the replayed draws")),
      samples_(stats().counter("samples", "samples", "the model's samples passed of the replayed draws")),
      gl_samples_(stats().counter("gl_samples", "samples", "GL's samples passed of every draw")),
      gl_samples_compared_(stats().counter("gl_samples_compared", "samples", "GL's samples passed of the compared draws")),
      frames_depth_compared_(stats().counter("frames_depth_compared", "frames", "frames whose final depth was compared with GL's")),
      depth_pixels_(stats().counter("depth_pixels", "pixels", "pixels of the final depth compared")),
      depth_mismatches_(stats().counter("depth_mismatches", "pixels", "of those, pixels whose depth differs from GL's (expected 0)")),
      unhandled_frames_(stats().counter("unhandled_frames", "frames", "frames in which the program used a GL feature not captured")),
      may_discard_replayed_(stats().counter("may_discard_replayed", "draws",
                                            "draws whose shader may discard, replayed as if nothing was and checked against GL")),
      may_discard_equal_(stats().counter("may_discard_equal", "draws",
                                         "of those, the draws equal to GL's (samples, and the depth change when it writes depth): "
                                         "counted among the compared and matched")),
      cycles_(stats().counter("cycles", "cycles", "cycles of every draw")),
      gl_hidden_(stats().counter("gl_hidden", "draws", "draws whose GL samples passed are 0 (hidden, or drawing nothing)")),
      tested_(stats().counter("tested", "draws", "draws tested for culling (cull.mode)")),
      tested_hidden_(stats().counter("tested_hidden", "draws", "tested draws whose GL samples passed are 0: what culling can remove")),
      culled_(stats().counter("culled", "draws", "tested draws found hidden and not drawn")),
      false_culls_(stats().counter("false_culls", "draws", "culled draws that GL drew samples of (expected 0)")),
      query_depth_tests_(stats().counter("query_depth_tests", "tests",
                                         "depth tests of the culling queries: texels read, or the occlusion boxes' fragments")),
      queries_(stats().counter("queries", "queries", "culling queries (draws and, per-primitive, triangles)")),
      update_texels_(stats().counter("update_texels", "texels", "texels the query structure recomputed (its upkeep)")),
      clear_texels_(stats().counter("clear_texels", "texels", "texels the query structure filled by clears")),
      primitive_tests_(stats().counter("primitive_tests", "triangles", "triangles of visible tested draws tested (per-primitive)")),
      primitives_culled_(stats().counter("primitives_culled", "triangles", "of those, found hidden and skipped")),
      primitive_lookups_(stats().counter("primitive_lookups", "tests", "texels the triangles' queries read")) {
  for (int u = 1; u < kUntested; ++u)
    untested_[static_cast<std::size_t>(u)] = &stats().counter(fmt::format("untested_{}", to_string(static_cast<Untested>(u))), "draws",
                                                               fmt::format("draws not tested for culling: {}", to_string(static_cast<Untested>(u))));
  if (cull_.on) {
    CullSettings s;
    s.tester = this;
    s.width = cull_.width, s.height = cull_.height, s.op = cull_.op, s.primitives = cull_.primitives;
    s.fused_interpolation = cull_.fused_interpolation;
    replay_.set_culling(s);
  }
  for (int r = 1; r < kReasons; ++r)
    flagged_[static_cast<std::size_t>(r)] = &stats().counter(fmt::format("flagged_{}", to_string(static_cast<Reason>(r))), "draws",
                                                              fmt::format("draws flagged: {}", to_string(static_cast<Reason>(r))));
  if (log_)
    *log_ << "frame,draw,framebuffer,reason,stale,depth_change,may_discard,triangles,fragments,depth_tests,samples,gl_samples,match,"
             "query_depth_tests\n";
}

void AppsUnit::depth_cleared(float) {
  ++cleared_;
  cleared_event_.notify(sc_core::SC_ZERO_TIME);
}

void AppsUnit::rebuild(const DepthImage& depth) {
  if (cull_.structure) update_texels_ += cull_.structure->changed(depth, Rect{0, 0, depth.width, depth.height});
}

void AppsUnit::cleared(const DepthImage&, float value) {
  if (cull_.structure) clear_texels_ += cull_.structure->cleared(value);
}

void AppsUnit::changed(const DepthImage& depth, const Rect& dirty) {
  if (cull_.structure) update_texels_ += cull_.structure->changed(depth, dirty);
}

void AppsUnit::prepare(const DepthImage& depth) {
  if (cull_.structure) update_texels_ += cull_.structure->prepare(depth);
}

void AppsUnit::query(const DepthImage& depth, std::span<const Rect> rects, std::span<const float> nearest,
                     std::vector<query::Answer>& answers) {
  if (cull_.structure) {
    cull_.structure->query_batch(rects, nearest, answers);
  } else {
    answers.clear();
    std::uint64_t pixels = 0;
    for (std::size_t i = 0; i < rects.size(); ++i) {
      answers.push_back(full_depth_query(depth, rects[i], nearest[i], cull_.op));
      pixels += answers.back().lookups;
    }
    label_with([&] { return fmt::format("occlusion query ({} px)", pixels); });
    work(static_cast<std::uint64_t>(config_.oq_latency_cycles) + ceil_div(static_cast<double>(pixels), config_.tests_per_cycle));
  }
  queries_ += rects.size();
  for (const query::Answer& a : answers) update_texels_ += a.update_texels;
}

void AppsUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor&) {
  const AppFrameCounts k = replay_.run_frame(*f);
  ++begun_;
  while (cleared_ < begun_) wait(cleared_event_);  // the frame before is counted as its own
  ++frames_;
  clears_ += k.clears;
  if (!k.unhandled.empty()) ++unhandled_frames_;
  if (k.depth_compared) ++frames_depth_compared_, depth_pixels_ += k.depth_pixels, depth_mismatches_ += k.depth_mismatches;
  for (const AppDrawCounts& d : k.draws) {
    ++draws_;
    gl_samples_ += d.gl_samples;
    gl_hidden_ += d.gl_samples == 0 ? 1 : 0;
    if (cull_.on) {
      if (d.untested == Untested::Tested) {
        ++tested_;
        tested_hidden_ += d.gl_samples == 0 ? 1 : 0;
        query_depth_tests_ += d.query_lookups + d.primitive_lookups;
        primitive_tests_ += d.primitive_tests, primitives_culled_ += d.primitives_culled, primitive_lookups_ += d.primitive_lookups;
      } else {
        ++*untested_[static_cast<std::size_t>(d.untested)];
      }
    }
    if (d.culled) {
      ++culled_;
      false_culls_ += d.false_cull() ? 1 : 0;
      label_with([&] { return fmt::format("app draw {} (culled)", d.draw); });
      work(static_cast<std::uint64_t>(config_.draw_overhead_cycles));
      cycles_ += static_cast<std::uint64_t>(config_.draw_overhead_cycles);
      if (log_)
        *log_ << fmt::format("{},{},{},culled,0,0,0,{},0,0,0,{},{},{}\n", d.frame, d.draw, d.framebuffer, d.triangles, d.gl_samples, "",
                             d.query_lookups);
      continue;
    }
    if (d.may_discard) ++may_discard_replayed_, may_discard_equal_ += d.reason == Reason::Replayed ? 1 : 0;
    std::uint64_t spent = static_cast<std::uint64_t>(config_.draw_overhead_cycles);
    if (d.reason == Reason::Replayed) {
      ++replayed_;
      triangles_ += d.triangles, fragments_ += d.fragments, depth_tests_ += d.depth_tests, samples_ += d.samples;
      if (d.stale) {
        ++after_stale_;
      } else {
        ++compared_;
        gl_samples_compared_ += d.gl_samples;
        if (d.samples == d.gl_samples) ++matched_;
        else ++mismatched_;
      }
      spent += std::max(ceil_div(static_cast<double>(d.triangles), config_.setup_triangles_per_cycle),
                        ceil_div(static_cast<double>(d.depth_tests), config_.tests_per_cycle));
    } else {
      ++*flagged_[static_cast<std::size_t>(d.reason)];
      depth_changes_ += d.depth_change ? 1 : 0;
    }
    label_with([&] { return fmt::format("app draw {} ({})", d.draw, to_string(d.reason)); });
    work(spent);
    cycles_ += spent;
    if (log_)
      *log_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", d.frame, d.draw, d.framebuffer, to_string(d.reason), d.stale ? 1 : 0,
                           d.depth_change ? 1 : 0, d.may_discard ? 1 : 0, d.triangles, d.fragments, d.depth_tests, d.samples, d.gl_samples,
                           d.reason != Reason::Replayed || d.stale ? "" : d.samples == d.gl_samples ? "1" : "0",
                           d.query_lookups + d.primitive_lookups);
  }
}

}  // namespace nbsim::apps
