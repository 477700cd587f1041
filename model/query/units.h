// The depth-query structures as units (query::Structure, structure.h) with their timing: the
// N-buffer unit (model/nbuffer/unit.h, its own update engine and query port), the tile Hi-Z and
// the Hi-Z pyramid (plain cores in model/hiz/, timed here). Each is a named SystemC module with its
// own statistics group ("gpu.nbuffer", "gpu.hiz"); the top level builds them from configuration.
#pragma once

#include <memory>
#include <optional>

#include "model/hiz/hiz_config.h"
#include "model/nbuffer/unit.h"
#include "model/query/structure.h"
#include "model/sim/unit.h"

namespace nbsim::query {

// The N-buffer unit as a structure: clears, changes and end-of-pass updates go to its update
// engine; queries take its query port (model/nbuffer/unit.h has the timing).
class NBufferStructure : public Structure {
 public:
  NBufferStructure(const sc_core::sc_module_name& name, stats::Registry& registry, const nbuffer::NBufferUnitConfig& config,
                   int width_px, int height_px, FarOp op, memory::Channel* channel);

  Kind structure_kind() const noexcept override { return Kind::NBuffer; }
  FarOp op() const noexcept override { return op_; }
  long long storage_bytes() const noexcept override { return unit_.core().levels().storage_bytes(); }
  std::uint64_t cleared(float depth) override;
  std::uint64_t changed(const DepthImage& depth, const Rect& dirty) override;
  std::uint64_t prepare(const DepthImage& depth) override;
  Answer query(const Rect& r, float nearest_depth) override;
  void query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) override;

  nbuffer::NBufferUnit& unit() noexcept { return unit_; }

 private:
  FarOp op_;
  nbuffer::NBufferUnit unit_;
  std::vector<nbuffer::QueryAnswer> scratch_;
};

// A single-level tile Hi-Z: depth changes recompute the tiles they touch (counted when they
// happen, spent as one build batch when queries come next); a query reads every tile the
// rectangle touches.
class TileHiZUnit : public sim::Unit, public Structure {
 public:
  TileHiZUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const HiZUnitConfig& config, int width_px,
              int height_px, FarOp op);

  Kind structure_kind() const noexcept override { return Kind::TileHiZ; }
  FarOp op() const noexcept override { return tile_.config().op; }
  long long storage_bytes() const noexcept override { return tile_.storage_bytes(); }
  std::uint64_t cleared(float depth) override;
  std::uint64_t changed(const DepthImage& depth, const Rect& dirty) override;
  std::uint64_t prepare(const DepthImage& depth) override;
  Answer query(const Rect& r, float nearest_depth) override;
  void query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) override;

 private:
  HiZUnitConfig config_;
  TileHiZ tile_;
  std::uint64_t pending_texels_ = 0;  // depth pixels read by changes since the last prepare()
};

// A Hi-Z pyramid, rebuilt from the depth buffer whenever queries come next (prepare()); a query
// reads at most 2x2 texels of one level.
class HiZPyramidUnit : public sim::Unit, public Structure {
 public:
  HiZPyramidUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const HiZUnitConfig& config, FarOp op);

  Kind structure_kind() const noexcept override { return Kind::HiZPyramid; }
  FarOp op() const noexcept override { return op_; }
  long long storage_bytes() const noexcept override { return pyramid_ ? pyramid_->storage_bytes() : 0; }
  std::uint64_t cleared(float) override { return 0; }
  std::uint64_t changed(const DepthImage&, const Rect&) override { return 0; }
  std::uint64_t prepare(const DepthImage& depth) override;
  Answer query(const Rect& r, float nearest_depth) override;
  void query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<Answer>& answers) override;

 private:
  Answer lookup(const Rect& r, float nearest_depth) const;
  HiZUnitConfig config_;
  FarOp op_;
  std::optional<HiZPyramid> pyramid_;
};

}  // namespace nbsim::query
