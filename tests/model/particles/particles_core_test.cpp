// ParticlesCoreTest: the particles program's plain core (model/particles/sprite.h): the sprite
// rectangle of the capture's shader, its tests, and the refusal of a damaged PRTC record.
#include <gtest/gtest.h>

#include <string>

#include "model/common/error.h"
#include "model/particles/sprite.h"
#include "model/particles/roles.h"

namespace nbsim::particles {
namespace {

// The rectangle: the pixels whose centres a sprite covers, one wider at a pixel-centre tie, clipped.
TEST(ParticlesCoreTest, SpriteRectangleAsTheShader) {
  struct Case {
    Particle p;
    int lo_x, hi_x, lo_y, hi_y;
    Rect clipped;
    bool on_screen;
    const char* why;
  };
  const Case cases[] = {
      {{10.0f, 20.0f, 0.5f, 16.0f}, 2, 18, 12, 28, {2, 12, 16, 16}, true, "centre on a pixel corner: 16 whole pixels"},
      {{10.5f, 20.5f, 0.5f, 16.0f}, 2, 19, 12, 29, {2, 12, 17, 17}, true, "centre on a pixel centre: a tie, one wider"},
      {{10.8f, 20.8f, 0.5f, 16.0f}, 3, 19, 13, 29, {3, 13, 16, 16}, true, "no tie: the ceiling"},
      {{1.0f, 1.0f, 0.5f, 16.0f}, -7, 9, -7, 9, {0, 0, 9, 9}, true, "partly off-screen: clipped"},
      {{-20.0f, 5.0f, 0.5f, 16.0f}, -28, -12, -3, 13, {}, false, "wholly off-screen"},
      {{10.0f, 20.0f, 1.5f, 16.0f}, 2, 18, 12, 28, {}, false, "depth outside [0, 1]: behind the eye"},
      {{10.0f, 20.0f, 0.5f, 24.0f}, -2, 22, 8, 32, {0, 8, 22, 24}, true, "24 px"},
  };
  for (const Case& c : cases) {
    const SpriteRect r = sprite_rect(c.p, 64, 48);
    EXPECT_EQ(r.lo_x, c.lo_x) << c.why;
    EXPECT_EQ(r.hi_x, c.hi_x) << c.why;
    EXPECT_EQ(r.lo_y, c.lo_y) << c.why;
    EXPECT_EQ(r.hi_y, c.hi_y) << c.why;
    EXPECT_EQ(r.on_screen, c.on_screen) << c.why;
    if (c.on_screen) {
      EXPECT_EQ(r.clipped.x, c.clipped.x) << c.why;
      EXPECT_EQ(r.clipped.y, c.clipped.y) << c.why;
      EXPECT_EQ(r.clipped.w, c.clipped.w) << c.why;
      EXPECT_EQ(r.clipped.h, c.clipped.h) << c.why;
    }
  }
}

// HIDDEN with the margin, both conventions; equal depth is never hidden.
TEST(ParticlesCoreTest, HiddenNeedsTheMargin) {
  EXPECT_FALSE(hidden_behind(0.5f, 0.5f, 1e-6f, FarOp::Max)) << "equal depth is not hidden";
  EXPECT_FALSE(hidden_behind(0.5f + 5e-7f, 0.5f, 1e-6f, FarOp::Max)) << "within the margin is not hidden";
  EXPECT_TRUE(hidden_behind(0.6f, 0.5f, 1e-6f, FarOp::Max));
  EXPECT_TRUE(hidden_behind(0.4f, 0.5f, 1e-6f, FarOp::Min)) << "reversed Z: smaller is farther";
  EXPECT_FALSE(hidden_behind(0.6f, 0.5f, 1e-6f, FarOp::Min));
}

// center reads one texel at floor(centre); the exact test finds the one passing pixel at a corner.
TEST(ParticlesCoreTest, CenterPopsWhereTheExactTestDoesNot) {
  DepthImage depth(32, 32, 0.2f);
  depth.at(0, 0) = 1.0f;  // one pixel of the sprite shows the far plane
  const Particle p{8.0f, 8.0f, 0.5f, 16.0f};  // covers [0, 16) x [0, 16)
  const SpriteRect r = sprite_rect(p, 32, 32);
  const Decision d = center_test(p, r, depth, 1e-6f, FarOp::Max);
  EXPECT_TRUE(d.culled) << "the centre is hidden";
  EXPECT_EQ(d.lookups, 1u);
  const Rect drawn = drawn_rect(p, 32, 32);
  EXPECT_EQ(drawn.x, 0);
  EXPECT_EQ(drawn.w, 16) << "GL's square: 16 pixels";
  EXPECT_TRUE(sprite_passes(drawn, p.depth, depth, FarOp::Max)) << "a corner is visible: culling it pops";
}

// hiz: at most 2x2 texels of the lowest level that holds the rectangle, kept above the top level.
TEST(ParticlesCoreTest, HiZLevelAndKeptWhenTooLarge) {
  DepthImage depth(64, 64, 0.2f);
  const HiZPyramid pyramid(depth, HiZConfig{FarOp::Max, StorageFormat::F32});
  const Particle p{20.0f, 20.0f, 0.5f, 16.0f};  // [12, 28): 3 texels of level 3, 2 of level 4
  const SpriteRect r = sprite_rect(p, 64, 64);
  const Decision d = hiz_test(p, r, pyramid, 4, 1e-6f, FarOp::Max);
  EXPECT_TRUE(d.culled);
  EXPECT_EQ(d.lookups, 4u) << "level 4: texels 0 and 1 in x and y";
  const Decision kept = hiz_test(p, r, pyramid, 3, 1e-6f, FarOp::Max);
  EXPECT_FALSE(kept.culled) << "needs level 4, only 0..3 built";
  EXPECT_TRUE(kept.too_large);
  EXPECT_EQ(hiz_build_texels(64, 64, 2), 64u * 64u + 32u * 32u + 16u * 16u);
}

// GL's square: the left/bottom fill rule at a pixel-centre tie, the centre clipping.
TEST(ParticlesCoreTest, DrawnRectangleAsLlvmpipe) {
  const Rect tie = drawn_rect({10.5f, 20.5f, 0.5f, 16.0f}, 64, 48);  // edges through pixel centres 2 and 18
  EXPECT_EQ(tie.x, 2) << "the left edge owns its pixel";
  EXPECT_EQ(tie.w, 16) << "the right edge does not: 16, where the shader's rectangle widens to 17";
  EXPECT_TRUE(drawn_rect({-0.5f, 20.0f, 0.5f, 16.0f}, 64, 48).empty()) << "centre outside: clipped, nothing drawn";
  const Rect edge = drawn_rect({0.0f, 20.0f, 0.5f, 16.0f}, 64, 48);
  EXPECT_EQ(edge.x, 0);
  EXPECT_EQ(edge.w, 8) << "centre on the viewport edge: drawn, clipped to the viewport";
}

// nb tests a sprite only when its unclipped rectangle fits the levels built.
TEST(ParticlesCoreTest, NBufferTestableUpToTheTopLevel) {
  const SpriteRect r16 = sprite_rect({10.0f, 20.0f, 0.5f, 16.0f}, 64, 48);
  const SpriteRect r17 = sprite_rect({10.5f, 20.5f, 0.5f, 16.0f}, 64, 48);
  EXPECT_TRUE(nb_testable(r16, 4));
  EXPECT_FALSE(nb_testable(r16, 3));
  EXPECT_TRUE(nb_testable(r17, 4)) << "17 px still needs level 4";
  EXPECT_FALSE(nb_testable(sprite_rect({10.0f, 20.0f, 0.5f, 32.0f}, 64, 48), 4));
}

scene::Frame particle_frame(std::uint32_t points, std::uint64_t count) {
  scene::Frame f;
  scene::DrawRecord d;
  d.role = nbsim::particles::kParticlesRole;
  d.topology = scene::Topology::Points;
  d.clip_positions.assign(points, {0.0f, 0.0f, 0.5f, 1.0f});
  d.point_sizes.assign(points, 16.0f);
  f.draws.push_back(d);
  scene::TechniqueRecord rec;
  rec.type = kParticlesRecordType;
  rec.decoded = true;
  rec.fields.push_back({"count", std::uint64_t{count}});
  for (const char* n : {"draw", "culled", "lookups", "reference_samples"})
    rec.fields.push_back({n, std::vector<std::uint32_t>(count, 0u)});
  for (const char* n : {"x", "y", "depth", "size"}) rec.fields.push_back({n, std::vector<float>(count, 1.0f)});
  f.technique_records.push_back(rec);
  return f;
}

// A record whose count does not match the particle draws' points is refused, naming both.
TEST(ParticlesCoreTest, DamagedRecordRefused) {
  EXPECT_EQ(read_particles(particle_frame(5, 5)).particles.size(), 5u);
  try {
    read_particles(particle_frame(5, 4));
    ADD_FAILURE() << "a count of 4 for 5 points was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("count is 4, but the frame's particle draws hold 5 points"), std::string::npos)
        << e.what();
  }
  scene::Frame none = particle_frame(5, 5);
  none.technique_records.clear();
  EXPECT_THROW(read_particles(none), InputError) << "a frame without its record";
}

}  // namespace
}  // namespace nbsim::particles
