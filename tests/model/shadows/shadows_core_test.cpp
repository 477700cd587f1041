// ShadowsCoreTest: the shadows program's plain core (model/shadows/caster.h) without SystemC: the
// header's clamp margin, light depth <-> distance from the light's projection, the cull rule and
// the per-caster checks, and the shadow mask.
#include <gtest/gtest.h>

#include <cmath>

#include "model/common/error.h"
#include "model/raster/depth_test.h"
#include "model/shadows/caster.h"
#include "model/shadows/litmap.h"
#include "model/shadows/volume.h"

namespace {

using namespace nbsim::shadows;

// A GL perspective projection's depth terms for near n and far f (column-major [10], [14], [11]).
nbsim::scene::Camera light_camera(double n, double f) {
  nbsim::scene::Camera c;
  c.proj[10] = static_cast<float>(-(f + n) / (f - n));
  c.proj[14] = static_cast<float>(-2.0 * f * n / (f - n));
  c.proj[11] = -1.0f;
  return c;
}

// The capture's clamp_margin property parses; malformed ones do not.
TEST(ShadowsCoreTest, ClampMarginParses) {
  const auto m = parse_clamp_margin("0.01 + 0.1 m");
  ASSERT_TRUE(m.has_value());
  EXPECT_DOUBLE_EQ(m->rel, 0.01);
  EXPECT_DOUBLE_EQ(m->metres, 0.1);
  for (const char* bad : {"", "0.01", "0.01 + 0.1", "x + 0.1 m", "0.01 + y m", "-1 + 0.1 m", "0.01 + 0.1 mm"})
    EXPECT_FALSE(parse_clamp_margin(bad).has_value()) << "'" << bad << "' is not '<rel> + <metres> m'";
}

// Depth and distance are inverse; depth 0 is the near plane, 1 the far plane.
TEST(ShadowsCoreTest, LightDepthRoundTrips) {
  const auto l = LightDepth::make(light_camera(0.5, 200.0));
  ASSERT_TRUE(l.has_value());
  EXPECT_NEAR(l->depth_of_distance(0.5), 0.0, 1e-5);
  EXPECT_NEAR(l->depth_of_distance(200.0), 1.0, 1e-5);
  for (double d : {0.1, 0.5, 0.9, 0.999}) EXPECT_NEAR(l->depth_of_distance(l->distance_of_depth(d)), d, 1e-9);
  nbsim::scene::Camera ortho = light_camera(0.5, 200.0);
  ortho.proj[11] = 0.0f;
  EXPECT_FALSE(LightDepth::make(ortho).has_value()) << "not a perspective frustum";
  EXPECT_FALSE(LightDepth::make(light_camera(2.0, 2.0)).has_value()) << "near == far";
}

// The cull rule, row by row (light 0.5 m to 200 m, margin 1% + 10 cm).
TEST(ShadowsCoreTest, CullRuleTable) {
  const auto l = *LightDepth::make(light_camera(0.5, 200.0));
  const ClampMargin m;
  const auto depth = [&](double metres) { return static_cast<float>(l.depth_of_distance(metres)); };
  struct Row {
    double z_min_m, z_max_m, caster_near_m;
    bool culled;
    const char* why;
  };
  const Row rows[] = {
      {50, 60, 40, false, "receivers behind the caster: a volume"},
      {10, 20, 40, true, "every receiver in front of the caster: culled"},
      {10, 39.7, 40, false, "the farthest receiver within the margin of the caster (39.7 m + 1% + 10 cm > 40 m): kept"},
      {10, 39.0, 40, true, "the farthest receiver beyond the margin in front: culled"},
      {45, 45, 40, false, "a slab of zero thickness behind the caster (a plane facing the light): kept"},
  };
  for (const Row& r : rows)
    EXPECT_EQ(litmap_rule_culls(depth(r.z_min_m), depth(r.z_max_m), depth(r.caster_near_m), l, m), r.culled) << r.why;
  EXPECT_TRUE(litmap_rule_culls(1.0f, 0.0f, depth(40), l, m)) << "no receiver in the rectangle (z_min 1, z_max 0): culled";
}

FrameCasters one_caster(float z_min, float z_max, float caster_near, std::uint32_t decision) {
  FrameCasters c;
  c.litmap_size = 64;
  c.object = {0}, c.lookups = {8}, c.decision = {decision};
  c.x = {1}, c.y = {1}, c.w = {4}, c.h = {4}, c.draw = {-1};
  c.caster_near = {caster_near}, c.caster_far = {caster_near}, c.z_min = {z_min}, c.z_max = {z_max};
  c.clamp_near = {0}, c.clamp_far = {1};
  return c;
}

// The checks: equal values agree; a looser (conservative) answer never culls what GL's values keep;
// a tighter one is flagged as not conservative and unsafe.
TEST(ShadowsCoreTest, CasterChecks) {
  const auto l = *LightDepth::make(light_camera(0.5, 200.0));
  const ClampMargin m;
  const auto depth = [&](double metres) { return static_cast<float>(l.depth_of_distance(metres)); };
  const FrameCasters kept = one_caster(depth(50), depth(60), depth(40), 0);
  const DepthRange exact{depth(50), depth(60)};  // GL's answer is the exact range here
  CasterCheck k = check_caster(kept, 0, kept.z_min[0], kept.z_max[0], exact, l, m);
  EXPECT_FALSE(k.model_culled || k.decision_mismatch || k.zmin_mismatch || k.zmax_mismatch || k.unsafe_cull || k.not_conservative);
  k = check_caster(kept, 0, depth(50), depth(30), exact, l, m);  // a z_max below GL's: a lossy design
  EXPECT_TRUE(k.not_conservative);
  k = check_caster(kept, 0, depth(20), depth(30), exact, l, m);
  EXPECT_TRUE(k.unsafe_cull) << "culls a caster the rule on the exact range keeps";
  const FrameCasters culled = one_caster(depth(10), depth(20), depth(40), 1);
  k = check_caster(culled, 0, depth(5), depth(60), {depth(10), depth(20)}, l, m);  // a looser answer keeps it
  EXPECT_TRUE(k.cull_lost);
  EXPECT_FALSE(k.unsafe_cull || k.not_conservative || k.decision_mismatch);
  const FrameCasters widened = one_caster(depth(10), depth(20), depth(40), 0);  // GL kept: its slab was wider
  k = check_caster(widened, 0, widened.z_min[0], widened.z_max[0], {depth(10), depth(20)}, l, m);
  EXPECT_TRUE(k.kept_by_slab);
  EXPECT_FALSE(k.decision_mismatch);
  const FrameCasters wrong = one_caster(depth(50), depth(60), depth(40), 1);  // GL culled a caster with receivers behind it
  EXPECT_TRUE(check_caster(wrong, 0, wrong.z_min[0], wrong.z_max[0], exact, l, m).decision_mismatch);
  // GL's covering read past the rectangle: its z_max is looser than the exact range; a design
  // between the two is conservative although it differs from GL's value.
  const FrameCasters loose = one_caster(depth(50), depth(70), depth(40), 0);
  k = check_caster(loose, 0, depth(50), depth(65), exact, l, m);
  EXPECT_TRUE(k.zmax_mismatch);
  EXPECT_FALSE(k.not_conservative || k.unsafe_cull);
}

// The exact range reads the rectangle's lexels only: the min of litmap_min, the max of litmap_max.
TEST(ShadowsCoreTest, ExactRangeOfARectangle) {
  nbsim::DepthImage lo(3, 2, 0.0f), hi(3, 2, 0.0f);
  lo.texels = {0.5f, 0.2f, 0.9f, 0.6f, 0.7f, 0.1f};
  hi.texels = {0.5f, 0.8f, 0.9f, 0.6f, 0.7f, 0.95f};
  const DepthRange r = exact_range(lo, hi, nbsim::Rect{0, 0, 2, 2});
  EXPECT_FLOAT_EQ(r.z_min, 0.2f);
  EXPECT_FLOAT_EQ(r.z_max, 0.8f) << "0.9 and 0.95 lie outside the rectangle";
  const DepthRange none = exact_range(lo, hi, nbsim::Rect{3, 0, 1, 1});
  EXPECT_EQ(none.z_min, 1.0f) << "no lexel: no receiver";
  EXPECT_EQ(none.z_max, 0.0f);
}

// The mask is light_region AND stencil != 0; pixels differing from a given mask are counted.
TEST(ShadowsCoreTest, MaskFromStencil) {
  const std::vector<std::uint8_t> stencil = {0, 1, 2, 0, 255, 0};
  const nbsim::scene::StencilSnapshot region{"light_region", 3, 2, {1, 1, 0, 1, 1, 0}};
  const nbsim::scene::StencilSnapshot same{"shadow_mask", 3, 2, {0, 1, 0, 0, 1, 0}};
  const nbsim::scene::StencilSnapshot other{"shadow_mask", 3, 2, {1, 1, 1, 0, 1, 0}};
  std::uint64_t set = 0;
  EXPECT_EQ(mask_pixels_differing(stencil, region, same, &set), 0u);
  EXPECT_EQ(set, 2u) << "stencil 2 outside the light region is not shadow";
  EXPECT_EQ(mask_pixels_differing(stencil, region, other), 2u);
}

// The casters' meshes (SHDG): a closed tetrahedron reads back as a caster with its bounds; a mesh
// with a face missing (its volume would leak) or a vertex index out of range is refused naming the
// caster and its object.
TEST(ShadowsCoreTest, CasterMeshesReadAndOpenMeshRefused) {
  const auto frame_with = [](std::vector<std::uint32_t> triangles, std::vector<float> vertices) {
    nbsim::scene::Frame f;
    f.begin.frame = 0;
    nbsim::scene::TechniqueRecord r;
    r.type = kCasterMeshesRecordType;
    r.decoded = true;
    const std::uint32_t n = static_cast<std::uint32_t>(triangles.size() / 3);
    r.fields = {{"count", std::uint64_t{1}},
                {"object", std::vector<std::uint32_t>{7}},
                {"bounds", std::vector<float>{0, 0, 0, 1, 1, 1}},
                {"first_triangle", std::vector<std::uint32_t>{0}},
                {"triangle_count", std::vector<std::uint32_t>{n}},
                {"vertices", std::move(vertices)},
                {"triangles", std::move(triangles)}};
    f.technique_records.push_back(std::move(r));
    return f;
  };
  const std::vector<float> corners = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::vector<std::uint32_t> tetra = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  const auto m = read_caster_meshes(frame_with(tetra, corners));
  ASSERT_TRUE(m.has_value());
  ASSERT_EQ(m->meshes.size(), 1u);
  EXPECT_EQ(m->meshes[0].object, 7u);
  EXPECT_EQ(m->meshes[0].triangles.size(), 4u);
  EXPECT_EQ(m->bounds[0].hi[2], 1.0f);
  EXPECT_FALSE(read_caster_meshes(nbsim::scene::Frame{}).has_value()) << "a frame without the record";
  const auto message = [&](std::vector<std::uint32_t> t, std::vector<float> v) {
    try {
      read_caster_meshes(frame_with(std::move(t), std::move(v)));
    } catch (const nbsim::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string open = message({0, 2, 1, 0, 1, 3, 0, 3, 2}, corners);
  EXPECT_NE(open.find("caster 0 (object 7)'s mesh"), std::string::npos) << open;
  EXPECT_NE(open.find("not closed"), std::string::npos) << open;
  const std::string range = message({0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 9}, corners);
  EXPECT_NE(range.find("names vertex 9 of 4"), std::string::npos) << range;
}

// The observer depth as the litmap shaders read it: a float buffer as stored; a 24-bit one as
// llvmpipe's texelFetch converts the stored value q (float(q) times the float of 1 / (2^24 - 1)),
// which for half of the values is not the quotient's float the model stores.
TEST(ShadowsCoreTest, ObserverDepthAsTheShaderSamplesIt) {
  nbsim::DepthImage stored(2, 1, 0.0f);
  const std::uint32_t q = 3;  // 3 / (2^24 - 1): the product and the quotient round apart
  stored.texels = {nbsim::raster::from_unorm24(q), 1.0f};
  const float product = 3.0f * static_cast<float>(1.0 / 16777215.0);
  ASSERT_NE(product, stored.texels[0]) << "a value where the two conversions differ";
  const nbsim::DepthImage s = sampled_depth_image(stored, nbsim::raster::DepthFormat::Unorm24);
  EXPECT_EQ(s.texels[0], product);
  EXPECT_EQ(s.texels[1], 1.0f);
  EXPECT_EQ(sampled_depth_image(stored, nbsim::raster::DepthFormat::Float32).texels, stored.texels);
}

}  // namespace
