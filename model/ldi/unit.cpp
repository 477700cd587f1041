// LdiUnit: the layered-depth-image technique's frame program, timing, memory and counters; see unit.h.
#include "model/ldi/unit.h"

#include <fmt/format.h>

#include <algorithm>
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
  for (const auto& [key, v] : {std::pair{"ldi.pass_latency_cycles", pass_latency_cycles}, std::pair{"ldi.vpt_latency_cycles", vpt_latency_cycles}})
    if (v < 0 || v > kMaxLatency) throw InputError(fmt::format("{} is {}, not in [0, {}]", key, v, kMaxLatency));
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
      memory_stall_cycles_(stats().counter("memory_stall_cycles", "cycles", "cycles waiting for the channel after the work was done")) {
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

void LdiUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor&) {
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
