// LdiUnit: the layered-depth-image technique's frame program, timing, memory and counters; see unit.h.
#include "model/ldi/unit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "model/common/error.h"
#include "model/sim/quantum.h"

namespace nbsim::ldi {

namespace {

// Limits of the "ldi." keys (describe and validate share them).
constexpr double kMinRate = 0.01, kMaxRate = 4096.0;
constexpr int kMaxLatency = 100000;

std::uint64_t ceil_div(std::uint64_t items, double per_cycle) {
  if (items == 0) return 0;
  const double c = static_cast<double>(items) / per_cycle;
  auto whole = static_cast<std::uint64_t>(c);
  if (static_cast<double>(whole) < c) ++whole;
  return whole;
}

}  // namespace

void LdiUnitConfig::describe(config::Schema& s, LdiUnitConfig& c) {
  s.add("ldi.setup_triangles_per_cycle", c.setup_triangles_per_cycle, "triangles/cycle", "peel triangles through setup a cycle",
        kMinRate, kMaxRate);
  s.add("ldi.blocks_per_cycle", c.blocks_per_cycle, "blocks/cycle", "4x4 blocks the peel's rasterizer hands on a cycle", kMinRate,
        kMaxRate);
  s.add("ldi.tests_per_cycle", c.tests_per_cycle, "tests/cycle",
        "peel fragment tests a cycle: the previous-layer read (pass k > 0) and the depth test share these lanes", kMinRate, kMaxRate);
  s.add("ldi.pass_latency_cycles", c.pass_latency_cycles, "cycles", "fill and drain of one peel pass", 0, kMaxLatency);
  s.add("ldi.vpt_cycles_per_point", c.vpt_cycles_per_point, "cycles/point",
        "issue cost of one parity test, both readers (its texel fetches are memory traffic of client ldi)", 0.0, 1e6);
  s.add("ldi.vpt_latency_cycles", c.vpt_latency_cycles, "cycles", "latency of a frame's batch of parity tests", 0, kMaxLatency);
  s.add("ldi.clip_lanes", c.clip_lanes, "lanes", "clipping draws: fragments the volume-test stage works on at once", kMinRate, kMaxRate);
  s.add("ldi.clip_volume_test_cycles", c.clip_volume_test_cycles, "lane-cycles",
        "clipping draws: rebuilding a fragment's point in one volume's LDI and checking its crop", 0.0, 1e6);
  s.add("ldi.clip_layer_fetch_cycles", c.clip_layer_fetch_cycles, "lane-cycles", "clipping draws: one layer fetch (readers layers, all)",
        0.0, 1e6);
  s.add("ldi.clip_range_fetch_cycles", c.clip_range_fetch_cycles, "lane-cycles",
        "clipping draws: one compressed fetch with its texel coordinates (reader ranges)", 0.0, 1e6);
  s.add("ldi.clip_draw_latency_cycles", c.clip_draw_latency_cycles, "cycles", "fill and drain of one clipping draw", 0, kMaxLatency);
  s.add("ldi.clip_cache_bytes", c.clip_cache_bytes, "bytes", "the LDI texel cache of clipping draws (0: every fetch misses)", 0, 1 << 26);
  s.add("ldi.clip_cache_line_bytes", c.clip_cache_line_bytes, "bytes", "its line (a power of two)", 4, 4096);
  s.add("ldi.clip_cache_ways", c.clip_cache_ways, "ways", "its associativity", 1, 64);
}

void LdiUnitConfig::validate() const {
  const auto rate = [](const char* key, double v) {
    if (!(v >= kMinRate && v <= kMaxRate)) throw InputError(fmt::format("{} is {}, not in [{}, {}]", key, v, kMinRate, kMaxRate));
  };
  rate("ldi.setup_triangles_per_cycle", setup_triangles_per_cycle);
  rate("ldi.blocks_per_cycle", blocks_per_cycle);
  rate("ldi.tests_per_cycle", tests_per_cycle);
  if (!(vpt_cycles_per_point >= 0.0 && vpt_cycles_per_point <= 1e6))
    throw InputError(fmt::format("ldi.vpt_cycles_per_point is {}, not in [0, 1e6]", vpt_cycles_per_point));
  for (const auto& [key, v] : {std::pair{"ldi.pass_latency_cycles", pass_latency_cycles}, std::pair{"ldi.vpt_latency_cycles", vpt_latency_cycles},
                               std::pair{"ldi.clip_draw_latency_cycles", clip_draw_latency_cycles}})
    if (v < 0 || v > kMaxLatency) throw InputError(fmt::format("{} is {}, not in [0, {}]", key, v, kMaxLatency));
  rate("ldi.clip_lanes", clip_lanes);
  for (const auto& [key, v] : {std::pair{"ldi.clip_volume_test_cycles", clip_volume_test_cycles},
                               std::pair{"ldi.clip_layer_fetch_cycles", clip_layer_fetch_cycles},
                               std::pair{"ldi.clip_range_fetch_cycles", clip_range_fetch_cycles}})
    if (!(v >= 0.0 && v <= 1e6)) throw InputError(fmt::format("{} is {}, not in [0, 1e6]", key, v));
  if (clip_cache_bytes < 0 || clip_cache_bytes > (1 << 26))
    throw InputError(fmt::format("ldi.clip_cache_bytes is {}, not in [0, {}]", clip_cache_bytes, 1 << 26));
  if (clip_cache_line_bytes < 4 || clip_cache_line_bytes > 4096 || (clip_cache_line_bytes & (clip_cache_line_bytes - 1)) != 0)
    throw InputError(fmt::format("ldi.clip_cache_line_bytes is {}, not a power of two in [4, 4096]", clip_cache_line_bytes));
  if (clip_cache_ways < 1 || clip_cache_ways > 64) throw InputError(fmt::format("ldi.clip_cache_ways is {}, not in [1, 64]", clip_cache_ways));
}

LdiUnit::LdiUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const LdiUnitConfig& config, memory::Channel& memory,
                 bool fused_interpolation)
    : sim::Unit(name, registry),
      config_(config),
      memory_(memory),
      client_(memory.add_client("ldi")),
      fused_(fused_interpolation),
      frames_(stats().counter("frames", "frames", "frames replayed")),
      peel_passes_(stats().counter("peel_passes", "passes", "peel passes replayed (LdiPeel draws, the last, empty one included)")),
      peel_triangles_(stats().counter("peel_triangles", "triangles", "peel triangles handed to setup")),
      peel_blocks_(stats().counter("peel_blocks", "blocks", "4x4 blocks with at least one peel fragment")),
      peel_fragments_(stats().counter("peel_fragments", "fragments", "the model's rasterized peel fragments (before the discard)")),
      gl_peel_fragments_(stats().counter("gl_peel_fragments", "fragments", "GL's rasterized peel fragments (its fragment counter)")),
      peel_samples_(stats().counter("peel_samples", "samples", "the model's peel samples kept and passing the depth test")),
      gl_peel_samples_(stats().counter("gl_peel_samples", "samples", "GL's samples passed of the peel draws")),
      peel_reads_(stats().counter("peel_reads", "reads", "previous-layer reads of the peel's strict compare (a fragment of pass k > 0)")),
      peel_discarded_(stats().counter("peel_discarded", "fragments", "peel fragments not strictly behind the previous layer")),
      peel_layer_texels_(stats().counter("peel_layer_texels", "texels", "layer texels the peel wrote (a sample passed there)")),
      peel_pass_mismatches_(stats().counter("peel_pass_mismatches", "passes",
                                            "peel passes whose fragments or passed samples differ from GL's counters (expected 0)")),
      layers_(stats().counter("layers", "layers", "the model's layers (passes that passed a sample), summed over frames")),
      gl_layers_(stats().counter("gl_layers", "layers", "LDIL layer_count, summed over frames")),
      layer_count_mismatches_(stats().counter("layer_count_mismatches", "frames", "frames whose model layer count differs from GL's")),
      layer_texel_mismatches_(stats().counter("layer_texel_mismatches", "texels",
                                              "(texel, layer) values whose bits differ between the model's LDI and GL's (expected 0)")),
      crop_mismatch_(stats().counter("crop_mismatch", "frames", "frames whose model crop rectangle differs from GL's")),
      compressed_mismatches_(stats().counter("compressed_mismatches", "values",
                                             "values of the model's compressed RG32UI texture that differ from GL's (expected 0)")),
      m_crop_(stats().counter("m_crop", "values", "M_crop of the model's LDI (w_crop * h_crop * d), summed over frames")),
      m_comp_(stats().counter("m_comp", "values", "M_comp of the model's compressed LDI (2 w_c^2), summed over frames")),
      test_points_(stats().counter("test_points", "points", "LDIT test points")),
      parity_mismatches_layers_(stats().counter("parity_mismatches_layers", "points",
                                                "points whose uncompressed parity answer differs from GL's")),
      parity_mismatches_ranges_(stats().counter("parity_mismatches_ranges", "points",
                                                "points whose compressed parity answer differs from GL's")),
      fetch_mismatches_layers_(stats().counter("fetch_mismatches_layers", "points",
                                               "points whose uncompressed fetch count differs from GL's")),
      fetch_mismatches_ranges_(stats().counter("fetch_mismatches_ranges", "points",
                                               "points whose compressed fetch count differs from GL's")),
      fetches_layers_(stats().counter("fetches_layers", "texels", "layer texels the model's uncompressed tests read")),
      fetches_ranges_(stats().counter("fetches_ranges", "texels", "RG32UI texels the model's compressed tests read")),
      gl_fetches_layers_(stats().counter("gl_fetches_layers", "texels", "layer texels GL's uncompressed tests read")),
      gl_fetches_ranges_(stats().counter("gl_fetches_ranges", "texels", "RG32UI texels GL's compressed tests read")),
      misclassified_layers_(stats().counter("misclassified_layers", "points",
                                            "classified points whose model uncompressed answer differs from the exact reference")),
      misclassified_ranges_(stats().counter("misclassified_ranges", "points",
                                            "classified points whose model compressed answer differs from the exact reference")),
      all_points_(stats().counter("all_points", "points", "test points the paper's reader (every layer read) answered (frames with LDIA)")),
      parity_mismatches_all_(stats().counter("parity_mismatches_all", "points", "points whose paper's-reader answer differs from GL's")),
      fetch_mismatches_all_(stats().counter("fetch_mismatches_all", "points", "points whose paper's-reader fetch count differs from GL's")),
      fetches_all_(stats().counter("fetches_all", "texels", "layer texels the model's paper's reader read (not charged: one reader runs)")),
      gl_fetches_all_(stats().counter("gl_fetches_all", "texels", "layer texels GL's paper's reader read")),
      misclassified_all_(stats().counter("misclassified_all", "points",
                                         "classified points whose paper's-reader answer differs from the exact reference")),
      classified_points_(stats().counter("classified_points", "points", "points with a reference count (not within epsilon of a surface)")),
      near_surface_points_(stats().counter("near_surface_points", "points",
                                           "points within epsilon of a surface (reference -1): counted apart, not classified")),
      peel_cycles_(stats().counter("peel_cycles", "cycles", "cycles of the peel passes (memory stalls included)")),
      vpt_cycles_(stats().counter("vpt_cycles", "cycles", "cycles of the parity tests (memory stalls included)")),
      peel_bytes_(stats().counter("peel_bytes", "bytes", "peel layer traffic: 4 B a previous-layer read, 4 B a layer texel written")),
      vpt_bytes_(stats().counter("vpt_bytes", "bytes", "parity-test traffic: 4 B a layer fetch, 8 B an RG32UI fetch (no cache)")),
      memory_stall_cycles_(stats().counter("memory_stall_cycles", "cycles", "cycles waiting for the channel after the work was done")),
      clip_frames_(stats().counter("clip_frames", "frames", "clipping and lens frames (LdiClip records)")),
      clip_draws_(stats().counter("clip_draws", "draws", "draws that ran the volume test")),
      clip_fragments_(stats().counter("clip_fragments", "fragments", "the model's rasterized fragments of those draws")),
      gl_clip_fragments_(stats().counter("gl_clip_fragments", "fragments", "GL's (its fragment counter)")),
      clip_samples_(stats().counter("clip_samples", "samples", "the model's samples passed of those draws")),
      gl_clip_samples_(stats().counter("gl_clip_samples", "samples", "GL's samples passed")),
      clip_discarded_(stats().counter("clip_discarded", "fragments", "fragments the model's volume test discarded")),
      gl_clip_discarded_(stats().counter("gl_clip_discarded", "fragments", "fragments GL's volume test discarded")),
      clip_fetches_(stats().counter("clip_fetches", "texels", "texels the model's reader fetched")),
      gl_clip_fetches_(stats().counter("gl_clip_fetches", "texels", "texels GL's reader fetched")),
      clip_depth_tests_(stats().counter("clip_depth_tests", "tests", "depth tests of those draws (the discarded fragments saved theirs)")),
      clip_volume_tests_(stats().counter("clip_volume_tests", "tests", "(fragment, volume) tests: volumes are tested until one holds the point")),
      clip_draw_mismatches_(stats().counter("clip_draw_mismatches", "draws",
                                            "draws whose fragments, samples, discards, fetches or discard sums differ from GL's (expected 0)")),
      clip_decision_mismatches_(stats().counter("clip_decision_mismatches", "draws",
                                                "draws whose discarded fragments differ from GL's, by count or sums (expected 0)")),
      clip_depth_mismatches_(stats().counter("clip_depth_mismatches", "frames", "frames whose final depth buffer differs from GL's (expected 0)")),
      clip_volumes_(stats().counter("clip_volumes", "volumes", "volumes loaded (LdiVolume records)")),
      clip_volume_mismatches_(stats().counter("clip_volume_mismatches", "volumes",
                                              "volumes whose GL crop or compressed texture differ from the model's (expected 0)")),
      clip_classified_(stats().counter("clip_classified", "fragments", "tested fragments with an exact reference (not near a surface)")),
      clip_near_surface_(stats().counter("clip_near_surface", "fragments", "tested fragments within epsilon of a volume's surface")),
      clip_misclassified_(stats().counter("clip_misclassified", "fragments", "classified fragments whose answer differs from the exact reference")),
      clip_fetches_layers_(stats().counter("clip_fetches_layers", "texels", "what the early-exit reader fetches for the same tests")),
      clip_fetches_all_(stats().counter("clip_fetches_all", "texels", "what the paper's reader (every layer) fetches for the same tests")),
      clip_fetches_ranges_(stats().counter("clip_fetches_ranges", "texels", "what the compressed reader fetches for the same tests")),
      clip_cache_hits_(stats().counter("clip_cache_hits", "fetches", "fetches the LDI texel cache held")),
      clip_cache_misses_(stats().counter("clip_cache_misses", "fetches", "fetches that missed it (a line over the channel each)")),
      clip_cycles_(stats().counter("clip_cycles", "cycles", "cycles of the clipping and lens draws (memory stalls included)")),
      clip_bytes_(stats().counter("clip_bytes", "bytes", "LDI texel-cache line fills of those draws")) {
  config_.validate();
  for (std::size_t i = 0; i < kPointKinds; ++i) {
    const std::string kind = kPointKindNames[i];
    kind_points_[i] = &stats().counter("points_" + kind, "points", "test points of kind " + kind);
    kind_classified_[i] = &stats().counter("classified_" + kind, "points", "classified test points of kind " + kind);
    kind_misclassified_layers_[i] =
        &stats().counter("misclassified_layers_" + kind, "points", "misclassified points of kind " + kind + ", uncompressed test");
    kind_misclassified_ranges_[i] =
        &stats().counter("misclassified_ranges_" + kind, "points", "misclassified points of kind " + kind + ", compressed test");
  }
}

std::uint64_t LdiUnit::pass_cycles(const PeelPassCounts& p, const LdiUnitConfig& c) {
  const std::uint64_t setup = ceil_div(p.triangles, c.setup_triangles_per_cycle);
  const std::uint64_t walk = ceil_div(p.blocks, c.blocks_per_cycle);
  const std::uint64_t tests = ceil_div(p.peel_reads + p.depth_tests, c.tests_per_cycle);
  return std::max({setup, walk, tests}) + static_cast<std::uint64_t>(c.pass_latency_cycles);
}

std::uint64_t LdiUnit::timed(std::uint64_t cycles, std::uint64_t bytes) {
  const std::uint64_t start = sim::local_cycles();
  const std::uint64_t mem_done = bytes ? memory_.transfer(start, bytes, client_) : start;
  work(cycles);
  memory_stall_cycles_ += sim::spend_until(mem_done);
  return sim::local_cycles() - start;
}

std::uint64_t LdiUnit::clip_draw_cycles(const ClipDrawCounts& d, ClipReader reader) const {
  const std::uint64_t setup = ceil_div(d.path.setup.triangles, config_.setup_triangles_per_cycle);
  const std::uint64_t walk = ceil_div(d.path.depth.blocks, config_.blocks_per_cycle);
  const double fetch = reader == ClipReader::Ranges ? config_.clip_range_fetch_cycles : config_.clip_layer_fetch_cycles;
  const double lane_cycles = static_cast<double>(d.volume_tests) * config_.clip_volume_test_cycles + static_cast<double>(d.fetches) * fetch;
  const auto vpt = static_cast<std::uint64_t>(std::ceil(lane_cycles / config_.clip_lanes));
  const std::uint64_t tests = ceil_div(d.path.depth.depth_tests, config_.tests_per_cycle);
  return std::max({setup, walk, vpt, tests}) + static_cast<std::uint64_t>(config_.clip_draw_latency_cycles);
}

void LdiUnit::run_clip_frame(const scene::Frame& f) {
  if (!clip_) clip_ = std::make_unique<ClipReplay>(fused_, memory::CacheConfig{config_.clip_cache_bytes, config_.clip_cache_line_bytes, config_.clip_cache_ways});
  const ClipFrameCounts k = clip_->run_frame(f);
  ++frames_;
  ++clip_frames_;
  clip_volumes_ += k.volumes_loaded, clip_volume_mismatches_ += k.volume_mismatches;
  clip_draw_mismatches_ += k.draw_mismatches, clip_decision_mismatches_ += k.decision_mismatches;
  clip_depth_mismatches_ += k.depth_mismatch ? 1 : 0;
  clip_fetches_layers_ += k.reader_fetches[0], clip_fetches_all_ += k.reader_fetches[1], clip_fetches_ranges_ += k.reader_fetches[2];
  const std::uint64_t line = clip_->cache_line_bytes();
  for (const ClipDrawCounts& d : k.draws) {
    label_with([&] { return fmt::format("clipping draw {}, {} fragments", d.draw, d.path.depth.fragments); });
    const std::uint64_t bytes = d.cache_misses * line;
    clip_bytes_ += bytes;
    clip_cycles_ += timed(clip_draw_cycles(d, k.reader), bytes);
    if (!d.tested) continue;
    ++clip_draws_;
    clip_fragments_ += d.path.depth.fragments, gl_clip_fragments_ += d.gl_fragments;
    clip_samples_ += d.path.depth.passed, gl_clip_samples_ += d.gl_samples;
    clip_discarded_ += d.discarded, gl_clip_discarded_ += d.gl_discarded;
    clip_fetches_ += d.fetches, gl_clip_fetches_ += d.gl_fetches;
    clip_depth_tests_ += d.path.depth.depth_tests, clip_volume_tests_ += d.volume_tests;
    clip_classified_ += d.classified, clip_near_surface_ += d.near_surface, clip_misclassified_ += d.misclassified;
    clip_cache_hits_ += d.cache_hits, clip_cache_misses_ += d.cache_misses;
  }
}

void LdiUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor&) {
  if (ClipReplay::is_clip_frame(*f)) {
    run_clip_frame(*f);
    return;
  }
  const std::array<int, 2> size = read_ldi_size(*f);  // the peel's render target
  if (!peel_ || peel_->width() != size[0] || peel_->height() != size[1]) peel_.emplace(size[0], size[1], fused_);
  const LdiFrameCounts k = ldi::run_frame(*f, *peel_);
  ++frames_;
  // Timing and memory, pass by pass, then the parity tests.
  for (const PeelPassCounts& p : k.passes) {
    label_with([&] { return fmt::format("peel pass, {} fragments", p.fragments); });
    const std::uint64_t bytes = 4 * (p.peel_reads + p.layer_texels);
    peel_bytes_ += bytes;
    peel_cycles_ += timed(pass_cycles(p, config_), bytes);
    ++peel_passes_;
    peel_triangles_ += p.triangles, peel_blocks_ += p.blocks, peel_reads_ += p.peel_reads, peel_discarded_ += p.peel_discarded;
    peel_layer_texels_ += p.layer_texels;
  }
  peel_fragments_ += k.peel_fragments, gl_peel_fragments_ += k.gl_peel_fragments;
  peel_samples_ += k.peel_samples, gl_peel_samples_ += k.gl_peel_samples;
  peel_pass_mismatches_ += k.peel_pass_mismatches;
  layers_ += static_cast<std::uint64_t>(k.layers), gl_layers_ += static_cast<std::uint64_t>(k.gl_layers);
  layer_count_mismatches_ += k.layers != k.gl_layers ? 1 : 0;
  layer_texel_mismatches_ += k.layer_texel_mismatches;
  crop_mismatch_ += k.crop_mismatch ? 1 : 0;
  compressed_mismatches_ += k.compressed_mismatches;
  m_crop_ += k.m_crop, m_comp_ += k.m_comp;

  const std::uint64_t vpt_bytes = 4 * k.fetches_layers + 8 * k.fetches_ranges;
  label_with([&] { return fmt::format("{} parity tests", k.test_points); });
  const auto issue = static_cast<std::uint64_t>(static_cast<double>(k.test_points) * config_.vpt_cycles_per_point + 0.5);
  vpt_bytes_ += vpt_bytes;
  vpt_cycles_ += timed(k.test_points ? issue + static_cast<std::uint64_t>(config_.vpt_latency_cycles) : 0, vpt_bytes);
  test_points_ += k.test_points;
  parity_mismatches_layers_ += k.parity_mismatches_layers, parity_mismatches_ranges_ += k.parity_mismatches_ranges;
  fetch_mismatches_layers_ += k.fetch_mismatches_layers, fetch_mismatches_ranges_ += k.fetch_mismatches_ranges;
  fetches_layers_ += k.fetches_layers, fetches_ranges_ += k.fetches_ranges;
  gl_fetches_layers_ += k.gl_fetches_layers, gl_fetches_ranges_ += k.gl_fetches_ranges;
  misclassified_layers_ += k.misclassified_layers, misclassified_ranges_ += k.misclassified_ranges;
  all_points_ += k.all_points, parity_mismatches_all_ += k.parity_mismatches_all, fetch_mismatches_all_ += k.fetch_mismatches_all;
  fetches_all_ += k.fetches_all, gl_fetches_all_ += k.gl_fetches_all, misclassified_all_ += k.misclassified_all;
  classified_points_ += k.classified_points, near_surface_points_ += k.near_surface_points;
  for (std::size_t i = 0; i < kPointKinds; ++i) {
    *kind_points_[i] += k.kind_points[i];
    *kind_classified_[i] += k.kind_classified[i];
    *kind_misclassified_layers_[i] += k.kind_misclassified_layers[i];
    *kind_misclassified_ranges_[i] += k.kind_misclassified_ranges[i];
  }
}

}  // namespace nbsim::ldi
