// CullCoreTest: the cull stage's modes (model/cull/report.h) and the scene's visibility code
// (model/scene/visibility.h) against what the GL renderer recorded in the sample traces: box geometry, bounds tests and the candidate set. No SystemC.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "model/cull/report.h"
#include "traces/format/reader.h"

namespace nbsim::cull {
namespace {

using scene::FrameView;
using scene::TestItem;

std::filesystem::path sample(const char* name) { return std::filesystem::path(NBSIM_SAMPLES) / name; }

FrameView view_of(const trace::TraceReader& tr, const trace::FrameBegin& b) {
  const trace::Header& h = tr.header();
  return FrameView::make(b, h.viewport->width, h.viewport->height, h.near_m, h.nearest_margin,
                         h.clip_control == trace::ClipControl::ZeroToOne, h.far_op() == FarOp::Min);
}

// Every mode name parses back to its mode, and an unknown name does not parse.
TEST(CullCoreTest, ModeNamesRoundTrip) {
  for (int m = 0; m <= static_cast<int>(CullMode::HizPyramid); ++m) {
    const auto mode = static_cast<CullMode>(m);
    EXPECT_EQ(parse_cull_mode(to_string(mode)), mode) << to_string(mode);
  }
  EXPECT_FALSE(parse_cull_mode("nbuffer").has_value());
  EXPECT_TRUE(hierarchical(CullMode::NbHier));
  EXPECT_FALSE(hierarchical(CullMode::Nb));
}

// The model's box of every tested object is GL's transform-feedback output, bit for bit, and its
// bounds test is the renderer's (rectangle, nearest depth, near-plane crossing).
TEST(CullCoreTest, BoxesAndBoundsMatchGl) {
  trace::FrameReader frames(sample("city_small_oq.nbt"));
  const trace::SceneObjects* scene = frames.trace().scene();
  ASSERT_NE(scene, nullptr);
  std::vector<std::array<float, 4>> box;
  std::size_t boxes = 0;
  while (auto f = frames.next()) {
    const FrameView v = view_of(frames.trace(), f->begin);
    for (const trace::DrawRecord& d : f->draws) {
      if (d.role != trace::DrawRole::BoundsQuery) continue;
      const trace::Aabb& b = scene->objects[static_cast<std::size_t>(d.object)];
      box_clip_positions(b, v, box);
      ASSERT_EQ(box.size(), d.clip_positions.size());
      for (std::size_t i = 0; i < box.size(); ++i)
        for (std::size_t k = 0; k < 4; ++k)
          ASSERT_EQ(box[i][k], d.clip_positions[i][k]) << "frame " << f->begin.frame << " object " << d.object << " vertex " << i;
      const trace::BoundsTest t = bounds_test(b, v);
      EXPECT_EQ(t.crosses_near, d.bounds.crosses_near) << "object " << d.object;
      EXPECT_EQ(std::tie(t.x, t.y, t.w, t.h), std::tie(d.bounds.x, d.bounds.y, d.bounds.w, d.bounds.h)) << "object " << d.object;
      EXPECT_EQ(t.nearest_depth, d.bounds.nearest_depth) << "object " << d.object;
      ++boxes;
    }
  }
  EXPECT_GT(boxes, 100u) << "the sample should hold many occlusion-query boxes";
}

// The candidates (frustum objects minus occluders) are exactly the objects GL tested, flat mode,
// on a normal and a reversed-Z trace.
TEST(CullCoreTest, CandidatesAreTheObjectsGlTested) {
  for (const char* name : {"city_small_oq.nbt", "city_small_nb_reversed.nbt"}) {
    trace::FrameReader frames(sample(name));
    const trace::SceneObjects& scene = *frames.trace().scene();
    const bool flat = *frames.trace().property("test_mode") == "oq" || *frames.trace().property("test_mode") == "nb";
    while (auto f = frames.next()) {
      const FrameView v = view_of(frames.trace(), f->begin);
      std::set<std::int32_t> occluders, tested;
      for (const trace::DrawRecord& d : f->draws) {
        if (d.role == trace::DrawRole::Occluder) occluders.insert(d.object);
        if ((d.role == trace::DrawRole::BoundsQuery || d.role == trace::DrawRole::NBufferQuery) && d.node < 0)
          tested.insert(d.object);
      }
      std::set<std::int32_t> candidates;
      for (auto o : frustum_objects(scene, v))
        if (!occluders.count(static_cast<std::int32_t>(o))) candidates.insert(static_cast<std::int32_t>(o));
      if (flat)
        EXPECT_EQ(candidates, tested) << name << " frame " << f->begin.frame;
      else
        for (auto o : tested) EXPECT_TRUE(candidates.count(o)) << name << " frame " << f->begin.frame << " object " << o;
    }
  }
}

}  // namespace
}  // namespace nbsim::cull
