// The depth-query structures as units; see units.h.
#include "model/query/units.h"

#include <fmt/format.h>

#include "model/common/error.h"
#include "model/common/names.h"

namespace nbsim::query {

std::string_view to_string(Kind k) noexcept { return enum_name(kKindNames, k); }

// ---- N-buffer -----------------------------------------------------------------------------------

NBufferStructure::NBufferStructure(const sc_core::sc_module_name& name, stats::Registry& registry,
                                   const nbuffer::NBufferUnitConfig& config, int width_px, int height_px, FarOp op,
                                   memory::Channel* channel)
    : op_(op), unit_(name, registry, config, width_px, height_px, op, channel) {}

std::uint64_t NBufferStructure::cleared(float depth) { return unit_.depth_cleared(depth).recomputed(); }

std::uint64_t NBufferStructure::changed(const DepthImage& depth, const Rect& dirty) {
  return unit_.depth_changed(depth, dirty).recomputed();
}

std::uint64_t NBufferStructure::prepare(const DepthImage&) { return unit_.end_of_pass().recomputed(); }

Answer NBufferStructure::query(const Rect& r, float nearest_depth) {
  const nbuffer::QueryAnswer a = unit_.query(r, nearest_depth);
  return {a.hidden, static_cast<std::uint64_t>(a.lookups), a.update.recomputed()};
}

void NBufferStructure::query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) {
  unit_.query_batch(rects, nearest, scratch_);
  answers.clear();
  for (const nbuffer::QueryAnswer& a : scratch_)
    answers.push_back({a.hidden, static_cast<std::uint64_t>(a.lookups), a.update.recomputed()});
}

// ---- tile Hi-Z ----------------------------------------------------------------------------------

TileHiZUnit::TileHiZUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const HiZUnitConfig& config,
                         int width_px, int height_px, FarOp op)
    : sim::Unit(name, registry), config_(config), tile_(width_px, height_px, (config.validate(), config.tile(op))) {}

std::uint64_t TileHiZUnit::cleared(float depth) {
  tile_.clear(depth);  // a fast clear: not counted as work
  return 0;
}

std::uint64_t TileHiZUnit::changed(const DepthImage& depth, const Rect& dirty) {
  const std::uint64_t texels = tile_.update(depth, dirty).pixels_read;
  pending_texels_ += texels;
  return texels;
}

std::uint64_t TileHiZUnit::prepare(const DepthImage&) {
  if (pending_texels_) work(sim::batch_cycles(pending_texels_, config_.build_texels_per_cycle, config_.build_latency_cycles));
  pending_texels_ = 0;
  return 0;  // counted by changed()
}

Answer TileHiZUnit::query(const Rect& r, float nearest_depth) {
  const TileHiZAnswer a = tile_.query(r, nearest_depth);
  const auto lookups = static_cast<std::uint64_t>(a.lookups);
  work(sim::batch_cycles(lookups, config_.lookups_per_cycle, config_.lookup_latency_cycles));
  return {a.hidden, lookups, 0};
}

void TileHiZUnit::query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) {
  NBSIM_CHECK(rects.size() == nearest.size(), "a query batch needs one nearest depth per rectangle");
  answers.clear();
  std::uint64_t lookups = 0;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    const TileHiZAnswer a = tile_.query(rects[i], nearest[i]);
    answers.push_back({a.hidden, static_cast<std::uint64_t>(a.lookups), 0});
    lookups += static_cast<std::uint64_t>(a.lookups);
  }
  label_with([&] { return fmt::format("{} primitive tests", rects.size()); });
  work(sim::batch_cycles(lookups, config_.lookups_per_cycle, config_.lookup_latency_cycles));
}

// ---- Hi-Z pyramid -------------------------------------------------------------------------------

HiZPyramidUnit::HiZPyramidUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const HiZUnitConfig& config,
                               FarOp op)
    : sim::Unit(name, registry), config_(config), op_(op) {
  config_.validate();
}

std::uint64_t HiZPyramidUnit::prepare(const DepthImage& depth) {
  pyramid_.emplace(depth, config_.pyramid(op_));
  std::uint64_t texels = 0;
  for (int k = 0; k < pyramid_->level_count(); ++k)
    texels += static_cast<std::uint64_t>(pyramid_->level_width(k)) * static_cast<std::uint64_t>(pyramid_->level_height(k));
  label("hiz pyramid build");
  work(sim::batch_cycles(texels, config_.build_texels_per_cycle, config_.build_latency_cycles));
  return texels;
}

Answer HiZPyramidUnit::lookup(const Rect& r, float nearest_depth) const {
  NBSIM_CHECK(pyramid_.has_value(), "Hi-Z pyramid queried before it was built");
  const QueryResult q = pyramid_->query(r);
  return {q.complete && nbuffer::hidden_behind(op_, nearest_depth, q.value), static_cast<std::uint64_t>(q.texel_count), 0};
}

Answer HiZPyramidUnit::query(const Rect& r, float nearest_depth) {
  const Answer a = lookup(r, nearest_depth);
  work(sim::batch_cycles(a.lookups, config_.lookups_per_cycle, config_.lookup_latency_cycles));
  return a;
}

void HiZPyramidUnit::query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) {
  NBSIM_CHECK(rects.size() == nearest.size(), "a query batch needs one nearest depth per rectangle");
  answers.clear();
  std::uint64_t lookups = 0;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    answers.push_back(lookup(rects[i], nearest[i]));
    lookups += answers.back().lookups;
  }
  label_with([&] { return fmt::format("{} primitive tests", rects.size()); });
  work(sim::batch_cycles(lookups, config_.lookups_per_cycle, config_.lookup_latency_cycles));
}

}  // namespace nbsim::query
