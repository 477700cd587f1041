// ShadowsHardCasesTest: the shadows hard cases not covered elsewhere, each a small capture on
// llvmpipe with a fixed light (--light) and a fixed camera (CaptureOptions::poses), in the three
// shadow modes, replayed by the shadows program. For each case: the culled and clamped masks equal
// the infinite one pixel for pixel on every frame (and GL's count of differing pixels is 0); the
// model's draws (fill), stencil buffer and masks equal GL's, its z_min/z_max, lookups and decisions
// the capture's; and the case's own expectation, checked on the SHDC record and the images.
//
// Covered elsewhere, not repeated: the ground facing the light (z_min == z_max) and the camera
// inside a shadow volume (ShadowsTest, capture side), the three scenes in every mode replayed
// (ShadowsReplayTest).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "tests/common/light_text.h"
#include "tests/common/run_nbsim.h"
#include "tests/common/technique_record.h"
#include "traces/capture/capture.h"
#include "traces/capture/scenes.h"
#include "traces/format/reader.h"
#include "traces/format/shadows/shadows_chunk.h"
#include "model/shadows/caster.h"

namespace nbsim::capture {
namespace {

namespace fs = std::filesystem;
using trace::CasterDecision;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_shadows_hard", name); }

glm::vec3 lo_of(const scene::Aabb& b) { return {b.lo[0], b.lo[1], b.lo[2]}; }
glm::vec3 hi_of(const scene::Aabb& b) { return {b.hi[0], b.hi[1], b.hi[2]}; }

using nbsim::testing::field;

struct Case {
  std::string scene = "boxes";
  OptionValues options;  // scene and technique options but the mode
  std::vector<CameraPose> poses;
  int width = 128, height = 96;
};

// One mode's capture: what each frame recorded, and the replay's shadows summary.
struct ModeRun {
  std::vector<scene::Frame> frames;
  std::uint64_t mask_pixels = 0, fill = 0;
  nlohmann::json shadows;
};

// `mode` is a shadow mode, or "clamped/caster": mode clamped with the clamp rule "caster".
ModeRun run_mode(const Case& c, const std::string& tag, const std::string& mode) {
  ModeRun out;
  CaptureOptions o;
  o.technique = "shadows";
  o.scene = c.scene;
  o.path = "fly";  // replaced by the poses
  o.width = c.width;
  o.height = c.height;
  o.frames = static_cast<int>(c.poses.size());
  o.poses = c.poses;
  o.options = c.options;
  const bool caster_rule = mode == "clamped/caster";
  o.options.set("shadow-mode", caster_rule ? "clamped" : mode);
  if (caster_rule) o.options.set("clamp-rule", "caster");
  o.options.set("levels-every", "1");
  const std::string name = caster_rule ? "clamped_caster" : mode;
  const fs::path file = scratch(tag + "_" + name + ".nbt");
  const CaptureSummary sum = capture(o, file.string());
  std::map<std::string, std::uint64_t> counts(sum.technique_counts.begin(), sum.technique_counts.end());
  EXPECT_EQ(counts["mask_diff_pixels"], 0u) << "GL's count of mask pixels unlike the infinite reference";
  out.mask_pixels = counts["mask_pixels"];
  out.fill = counts["fill"];

  trace::FrameReader frames(file);
  while (auto f = frames.next()) {
    const auto* mask = f->stencil("shadow_mask");
    const auto* reference = f->stencil("shadow_mask_infinite");
    EXPECT_TRUE(mask && reference && mask->texels == reference->texels) << "frame " << f->begin.frame << ": GL's mask is the infinite one";
    EXPECT_EQ(f->technique_records.size(), f->begin.frame == 0 ? 3u : 1u) << "SHDC, and SHDG and SHDM in the first frame";
    out.frames.push_back(std::move(*f));
  }
  EXPECT_EQ(out.frames.size(), c.poses.size());

  const fs::path dir = scratch(tag + "_" + name + "_run");
  const auto r = nbsim::testing::run_nbsim("replay " + file.string() + " --out " + dir.string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  std::ifstream in(dir / "run.json");
  const auto run = nlohmann::json::parse(in);
  const auto& sum_json = run["summary"];
  EXPECT_EQ(sum_json["draws_exact"], sum_json["draws"]) << "every draw's fragments and passed samples are GL's";
  EXPECT_EQ(sum_json["stencil_pixels_matching"], sum_json["stencil_pixels"]) << "the stencil buffer is GL's";
  EXPECT_EQ(sum_json["depth_pixels_matching"], sum_json["depth_pixels"]);
  out.shadows = sum_json["shadows"];
  const auto& s = out.shadows;
  EXPECT_EQ(s["mask_diff"], 0) << "the model's mask is GL's";
  EXPECT_EQ(s["mask_diff_infinite"], 0) << "and the infinite reference's";
  EXPECT_EQ(s["gl_mask_diff"], 0);
  EXPECT_EQ(s["mask_pixels"], s["gl_mask_pixels"]);
  EXPECT_EQ(s["fill"], s["gl_fill"]) << "the model's fill is GL's";
  EXPECT_EQ(s["stencil_tests"], s["fill"]);
  for (const char* k : {"zmin_mismatches", "zmax_mismatches", "lookup_mismatches", "decision_mismatches", "unsafe_culls", "not_conservative"})
    EXPECT_EQ(s[k], 0) << k;
  fs::remove(file);
  fs::remove_all(dir);
  return out;
}

// The three modes of a case and the clamp rule "caster": each checked by run_mode, the masks
// equal across modes frame by frame, fill clamped <= culled <= infinite. Returns the runs by mode.
std::map<std::string, ModeRun> run_case(const Case& c, const std::string& tag) {
  std::map<std::string, ModeRun> runs;
  for (const std::string mode : {"infinite", "culled", "clamped", "clamped/caster"}) {
    SCOPED_TRACE(tag + " " + mode);
    runs[mode] = run_mode(c, tag, mode);
  }
  const auto& inf = runs["infinite"];
  for (const std::string mode : {"culled", "clamped", "clamped/caster"}) {
    const auto& m = runs[mode];
    EXPECT_EQ(m.frames.size(), inf.frames.size());
    for (std::size_t f = 0; f < std::min(m.frames.size(), inf.frames.size()); ++f) {
      const auto *a = m.frames[f].stencil("shadow_mask"), *b = inf.frames[f].stencil("shadow_mask");
      if (!a || !b) {
        ADD_FAILURE() << "no shadow_mask";
        continue;
      }
      std::size_t differ = 0;
      for (std::size_t i = 0; i < a->texels.size(); ++i) differ += a->texels[i] != b->texels[i];
      EXPECT_EQ(differ, 0u) << tag << " frame " << f << ": " << mode << " mask pixels unlike infinite's";
    }
  }
  EXPECT_LE(runs["clamped"].fill, runs["culled"].fill);
  EXPECT_LE(runs["clamped/caster"].fill, runs["culled"].fill);
  EXPECT_LE(runs["culled"].fill, runs["infinite"].fill);
  EXPECT_GT(inf.mask_pixels, 0u) << tag << ": the case casts a visible shadow";
  std::printf("[ %s ] mask pixels %llu; fill infinite %llu, culled %llu, clamped %llu (rule caster %llu)\n", tag.c_str(),
              static_cast<unsigned long long>(inf.mask_pixels), static_cast<unsigned long long>(inf.fill),
              static_cast<unsigned long long>(runs["culled"].fill), static_cast<unsigned long long>(runs["clamped"].fill),
              static_cast<unsigned long long>(runs["clamped/caster"].fill));
  return runs;
}

// One box (the boxes scene, seed 5) lit from its -x side, 45 degrees up, so that its shadow falls
// on +x over the box's z extent; the light's option is set in `c`.
struct LitBox {
  Case c;
  glm::vec3 lo{0.0f}, hi{0.0f}, light{0.0f};
  float cz = 0.0f;  // the box's middle z
};
LitBox box_lit_from_minus_x(const std::string& litmap) {
  LitBox l;
  l.c.options = {{"boxes", "1"}, {"seed", "5"}, {"litmap", litmap}};
  const CaptureScene scene = find_scene("boxes").make(l.c.options);
  const scene::Aabb& b = scene.scene.objects[1];
  l.lo = lo_of(b), l.hi = hi_of(b);
  l.cz = 0.5f * (l.lo.z + l.hi.z);
  l.light = {l.lo.x - 40.0f, 40.0f + l.hi.y, l.cz};
  l.c.options.set("light", nbsim::testing::light_text(l.light, {l.hi.x, 0.0f, l.cz}));
  return l;
}

// Index in the SHDC vectors of the caster that is scene object `object`, or -1.
int caster_of(const scene::TechniqueRecord& rec, std::uint32_t object) {
  const auto& objects = field<std::uint32_t>(rec, "object");
  const auto it = std::find(objects.begin(), objects.end(), object);
  return it == objects.end() ? -1 : static_cast<int>(it - objects.begin());
}

// Receivers smaller than a lexel: 16-lexel litmaps over 40 boxes, the light high and oblique, so
// that every box's bounds span less than a lexel of the litmap (the litmaps may miss a box's faces
// entirely); the observer looks down at the boxes, which receive each other's shadows.
// What it guards: each lexel of a 16-lexel litmap spans tens of metres of ground, whose lexel-centre
// samples end 218.6 m from the light while mask pixels lie up to 223.6 m, so a slab taken from the
// lexel centres alone would lose 46 mask pixels over 2 frames in the clamped mode; the slab must
// hold the light depth of every mask pixel's receiver (the receiver splat, docs/shadows.md).
TEST(ShadowsHardCasesTest, ReceiversSmallerThanALexel) {
  Case c;
  c.options = {{"boxes", "40"}, {"seed", "3"}, {"litmap", "16"}, {"light-fov", "60"}};
  const CaptureScene scene = find_scene("boxes").make(c.options);
  const float e = static_cast<float>(scene.site.extent_m);
  const glm::vec3 centre{0.5f * e, 0.0f, 0.5f * e};
  c.options.set("light", nbsim::testing::light_text(centre + glm::vec3(-0.8f * e, 1.4f * e, 0.1f * e), centre));
  c.poses = {{centre + glm::vec3(0.0f, 0.5f * e, -0.45f * e), centre}, {centre + glm::vec3(0.3f * e, 0.35f * e, -0.4f * e), centre}};
  const auto runs = run_case(c, "small_receivers");
  // The boxes' light-space footprints, from the recorded light camera.
  const auto& f = runs.at("clamped").frames.at(0);
  ASSERT_TRUE(f.light.has_value());
  const glm::mat4 light = glm::make_mat4(f.light->proj.data()) * glm::make_mat4(f.light->view.data());
  int below_a_lexel = 0, boxes = 0;
  for (std::size_t o = 1; o < scene.scene.objects.size(); ++o) {
    const scene::Aabb& b = scene.scene.objects[o];
    float x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int k = 0; k < 8; ++k) {
      const glm::vec4 q = light * glm::vec4(k & 1 ? b.hi[0] : b.lo[0], k & 2 ? b.hi[1] : b.lo[1], k & 4 ? b.hi[2] : b.lo[2], 1.0f);
      x0 = std::min(x0, q.x / q.w), x1 = std::max(x1, q.x / q.w), y0 = std::min(y0, q.y / q.w), y1 = std::max(y1, q.y / q.w);
    }
    ++boxes;
    below_a_lexel += (x1 - x0) * 8.0f < 1.0f && (y1 - y0) * 8.0f < 1.0f;  // 16 lexels over [-1, 1]: a lexel is 1/8
  }
  std::printf("[ small_receivers ] %d of %d boxes span less than a lexel each way\n", below_a_lexel, boxes);
  EXPECT_GT(below_a_lexel, boxes / 2) << "most boxes are smaller than a lexel";
  const auto& rec = f.technique_records.at(0);
  const auto& decision = field<std::uint32_t>(rec, "decision");
  EXPECT_GT(std::count(decision.begin(), decision.end(), static_cast<std::uint32_t>(CasterDecision::Volume)), 0) << "volumes are drawn";
}

// Receivers at grazing angles from the light: a light 2 m above the ground, 150 m beyond the
// site's edge, looking across it: the ground meets its rays at about 1 degree; the boxes' shadows
// are long streaks on it, seen from above.
// What it guards: one lexel row spans up to about 100 m of ground, so far planes from lexel
// centres (212 to 260 m) fall short of shadowed ground seen by the observer (up to 270 m) and the
// clamped mode would lose 1,031 mask pixels; the slab must hold every mask pixel's receiver.
TEST(ShadowsHardCasesTest, ReceiversAtGrazingAngles) {
  Case c;
  c.options = {{"boxes", "12"}, {"seed", "6"}, {"litmap", "128"}, {"light-fov", "40"}};
  const CaptureScene scene = find_scene("boxes").make(c.options);
  const float e = static_cast<float>(scene.site.extent_m);
  const glm::vec3 light{-150.0f, 2.0f, 0.5f * e}, target{0.5f * e, 0.0f, 0.5f * e};
  c.options.set("light", nbsim::testing::light_text(light, target));
  c.poses = {{{0.5f * e, 0.6f * e, 0.1f * e}, target}};
  const auto runs = run_case(c, "grazing");
  const float near_angle = std::atan2(light.y, 150.0f) * 57.29578f, far_angle = std::atan2(light.y, 150.0f + e) * 57.29578f;
  std::printf("[ grazing ] the light's rays meet the site's ground at %.2f to %.2f degrees\n", far_angle, near_angle);
  EXPECT_LT(near_angle, 1.0f);
  const auto& rec = runs.at("clamped").frames.at(0).technique_records.at(0);
  const auto& decision = field<std::uint32_t>(rec, "decision");
  const auto& z_min = field<float>(rec, "z_min");
  const auto& z_max = field<float>(rec, "z_max");
  int drawn = 0;
  for (std::size_t k = 0; k < decision.size(); ++k)
    if (decision[k] == static_cast<std::uint32_t>(CasterDecision::Volume)) {
      ++drawn;
      EXPECT_LE(z_min[k], z_max[k]) << "caster " << k << ": a visible receiver in its rectangle";
    }
  EXPECT_GT(drawn, 0);
}

// Casters crossing the light's near plane (decision 3): the light 0.2 m above one corner edge of a
// box, looking down across it: its near corners lie closer than the light's near plane (0.5 m). It
// is never culled nor clamped: drawn infinite in every mode, and the mask is kept.
TEST(ShadowsHardCasesTest, CasterCrossingTheLightsNearPlane) {
  Case c;
  c.options = {{"boxes", "6"}, {"seed", "8"}, {"litmap", "128"}, {"light-fov", "90"}};
  const CaptureScene scene = find_scene("boxes").make(c.options);
  const scene::Aabb& b = scene.scene.objects[1];
  const glm::vec3 lo = lo_of(b), hi = hi_of(b);
  const float cz = 0.5f * (lo.z + hi.z);
  c.options.set("light", nbsim::testing::light_text({lo.x - 0.2f, hi.y + 0.2f, cz}, {hi.x + 20.0f, 0.0f, cz}));
  c.poses = {{{hi.x + 12.0f, 8.0f, lo.z - 14.0f}, {hi.x + 5.0f, 0.0f, cz}}};
  const auto runs = run_case(c, "near_plane");
  for (const std::string mode : {"infinite", "culled", "clamped"}) {
    const auto& rec = runs.at(mode).frames.at(0).technique_records.at(0);
    const int k = caster_of(rec, 1);
    ASSERT_GE(k, 0);
    EXPECT_EQ(field<std::uint32_t>(rec, "decision")[static_cast<std::size_t>(k)], static_cast<std::uint32_t>(CasterDecision::CrossesNear)) << mode;
    EXPECT_GE(field<std::int32_t>(rec, "draw")[static_cast<std::size_t>(k)], 0) << mode << ": its volume is drawn";
    EXPECT_TRUE(std::isinf(field<float>(rec, "clamp_far")[static_cast<std::size_t>(k)])) << mode << ": drawn infinite";
    EXPECT_EQ(field<float>(rec, "clamp_near")[static_cast<std::size_t>(k)], 0.0f) << mode;
  }
}

// Intermediate occluders (the paper's Figure 5(e)): the light on the line through the middles of
// two boxes, beyond the taller one A, so that A stands between the light and the other box B. In
// B's light-space rectangle the nearest visible receiver is A, in front of B: B's slab starts
// before B, so its volume is loose (no near plane) but drawn and correct.
// What it guards: B's far plane from the lexel centres (z_max 0.998497, 101.8 m with the margin)
// falls short of ground behind B that the observer sees (up to 111.6 m; the light is low, so the
// ground's depth changes metres within a lexel), and the clamped mode would lose 59 mask pixels;
// the slab must hold every mask pixel's receiver.
TEST(ShadowsHardCasesTest, IntermediateOccluder) {
  Case c;
  c.options = {{"boxes", "2"}, {"seed", "12"}, {"litmap", "256"}, {"light-fov", "60"}};
  const CaptureScene scene = find_scene("boxes").make(c.options);
  std::uint32_t a = 1, b = 2;
  if (scene.scene.objects[a].hi[1] < scene.scene.objects[b].hi[1]) std::swap(a, b);
  const glm::vec3 la = lo_of(scene.scene.objects[a]), ha = hi_of(scene.scene.objects[a]);
  const glm::vec3 lb = lo_of(scene.scene.objects[b]), hb = hi_of(scene.scene.objects[b]);
  const glm::vec3 pa = 0.5f * (la + ha), pb = 0.5f * (lb + hb);  // pa.y >= pb.y: the light is above the ground
  const glm::vec3 light = pa + (pa - pb) * (15.0f / glm::length(pa - pb));
  c.options.set("light", nbsim::testing::light_text(light, pb));
  const glm::vec3 mid = 0.5f * (pa + pb), along = glm::normalize(pb - pa), side{-along.z, 0.0f, along.x};
  c.poses = {{mid + side * (glm::length(pb - pa) + 25.0f) + glm::vec3(0.0f, 12.0f, 0.0f), glm::vec3(mid.x, 0.0f, mid.z)}};
  const auto runs = run_case(c, "intermediate_occluder");
  const auto& rec = runs.at("clamped").frames.at(0).technique_records.at(0);
  const int kb = caster_of(rec, b), ka = caster_of(rec, a);
  ASSERT_GE(kb, 0);
  ASSERT_GE(ka, 0);
  const auto ub = static_cast<std::size_t>(kb), ua = static_cast<std::size_t>(ka);
  const float z_min = field<float>(rec, "z_min")[ub], caster_near = field<float>(rec, "caster_near")[ub];
  std::printf("[ intermediate_occluder ] B: z_min %.6f, caster_near %.6f, z_max %.6f, decision %u; A: caster_near %.6f\n", z_min,
              caster_near, field<float>(rec, "z_max")[ub], field<std::uint32_t>(rec, "decision")[ub], field<float>(rec, "caster_near")[ua]);
  EXPECT_LT(z_min, caster_near) << "a visible receiver in front of B in its rectangle: the occluder A";
  EXPECT_LE(field<float>(rec, "caster_near")[ua], z_min) << "that receiver is no nearer than A's bounds";
  EXPECT_EQ(field<std::uint32_t>(rec, "decision")[ub], static_cast<std::uint32_t>(CasterDecision::Volume)) << "B is not culled";
  EXPECT_EQ(field<float>(rec, "clamp_near")[ub], 0.0f) << "loose: no near plane";
  EXPECT_GE(field<std::int32_t>(rec, "draw")[ub], 0);
}

// The paper's Figure 5 (a) to (d), one frame each, with one box lit from the -x side 45 degrees up
// (its shadow falls on +x): (a) the observer sees the box and its shadow: kept as a seen caster;
// (b) it sees the shadow, not the box: kept for its receivers, the volume starting at the min
// plane, in front of the ground and behind the box's top (the paper's tight volume around the
// shadow); (c) it sees the box from the light's side, which hides the shadow: kept as a seen caster,
// its far plane before the shadow's far end; (d) it looks away from both: culled. Case (e) is
// IntermediateOccluder.
TEST(ShadowsHardCasesTest, Figure5Configurations) {
  LitBox box = box_lit_from_minus_x("256");
  Case& c = box.c;
  const glm::vec3 lo = box.lo, hi = box.hi, light = box.light;
  const float cz = box.cz;
  // The shadow's far end: the light ray over the box's far top edge meets the ground.
  const glm::vec3 top{hi.x, hi.y, cz};
  const glm::vec3 tip = light + (top - light) * (light.y / (light.y - top.y));
  const float d = 0.5f * (tip.x - hi.x);  // from the box's +x face to the shadow's middle
  c.poses = {{{hi.x + 10.0f, hi.y, lo.z - 25.0f}, {hi.x + 0.5f * d, 0.0f, cz}},                 // (a)
             {{hi.x + d, 0.9f * d, cz}, {hi.x + d + 0.3f * 0.9f * d, 0.0f, cz}},                    // (b)
             {{lo.x - 15.0f, 0.5f * hi.y, cz}, {hi.x, 0.4f * hi.y, cz}},                           // (c)
             {{lo.x - 10.0f, 2.0f, cz}, {lo.x - 30.0f, 0.0f, cz}}};                                 // (d)
  const auto runs = run_case(c, "figure5");
  const auto& frames = runs.at("clamped").frames;
  ASSERT_EQ(frames.size(), 4u);
  const auto caster = [&](std::size_t frame) {
    const auto& rec = frames[frame].technique_records.at(0);
    const int k = caster_of(rec, 1);
    EXPECT_GE(k, 0);
    return std::pair{&rec, static_cast<std::size_t>(std::max(k, 0))};
  };
  using nbsim::shadows::KeptBy;
  const auto kept = [&](std::size_t frame) {
    const auto [rec, k] = caster(frame);
    return static_cast<KeptBy>(field<std::uint32_t>(*rec, "kept")[k]);
  };
  EXPECT_EQ(kept(0), KeptBy::SeenCaster) << "(a)";
  EXPECT_EQ(kept(1), KeptBy::Receivers) << "(b)";
  EXPECT_EQ(kept(2), KeptBy::SeenCaster) << "(c)";
  EXPECT_EQ(kept(3), KeptBy::Dropped) << "(d)";
  {
    const auto [rec, k] = caster(1);
    const float near = field<float>(*rec, "clamp_near")[k];
    EXPECT_GT(near, field<float>(*rec, "caster_near")[k]) << "(b): the volume starts behind the box's top, at the min plane";
    EXPECT_LT(near, field<float>(*rec, "z_min")[k]) << "(b): in front of the shadowed ground";
    EXPECT_GE(field<std::int32_t>(*rec, "draw")[k], 0);
  }
  {
    const auto [rec, k] = caster(2);
    const glm::mat4 view = glm::make_mat4(frames[2].light->view.data()), proj = glm::make_mat4(frames[2].light->proj.data());
    const glm::vec4 q = proj * view * glm::vec4(tip, 1.0f);
    EXPECT_LT(field<float>(*rec, "clamp_far")[k], 0.5f * q.z / q.w + 0.5f) << "(c): the volume ends before the hidden shadow's far end";
  }
  {
    const auto [rec, k] = caster(3);
    EXPECT_EQ(field<std::uint32_t>(*rec, "decision")[k], static_cast<std::uint32_t>(CasterDecision::Culled)) << "(d)";
    EXPECT_EQ(field<std::int32_t>(*rec, "draw")[k], -1) << "(d): no volume";
  }
}

// Reprojection at depth discontinuities: a box's shadow on the ground seen by the observer right
// beside the box's silhouette edge (the ground behind the edge, metres farther than the box at
// the next pixel). The litmap pass keeps a fragment by the farthest observer depth of its 3x3
// pixels; mask pixels next to the edge must survive.
TEST(ShadowsHardCasesTest, ReprojectionAtDepthDiscontinuities) {
  LitBox box = box_lit_from_minus_x("128");  // the shadow falls on +x, over the box's z extent
  Case& c = box.c;
  const glm::vec3 lo = box.lo, hi = box.hi;
  const float cz = box.cz;
  // The eye on the -x, -z side: the box's right silhouette is its (hi.x, lo.z) edge, the shadowed
  // ground right behind it.
  c.poses = {{{lo.x - 4.0f, 0.6f * hi.y, lo.z - 16.0f}, {hi.x + 2.0f, 0.0f, 0.5f * (lo.z + cz)}},
             {{lo.x - 2.0f, 0.4f * hi.y, lo.z - 10.0f}, {hi.x + 1.0f, 0.0f, cz}}};
  const auto runs = run_case(c, "discontinuity");
  int at_edge = 0;
  for (const auto& f : runs.at("clamped").frames) {
    const auto* mask = f.stencil("shadow_mask");
    const auto* depth = f.depth("final");
    ASSERT_TRUE(mask && depth);
    // View distance from the window depth (GL's default convention, the frame's projection).
    const auto view_z = [&](float d) {
      const glm::mat4 p = glm::make_mat4(f.begin.proj.data());
      const float ndc = 2.0f * d - 1.0f;
      return p[3][2] / (ndc + p[2][2]);  // -z_view for a perspective projection
    };
    for (int y = 0; y < mask->height; ++y)
      for (int x = 0; x + 1 < mask->width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(mask->width) + static_cast<std::size_t>(x);
        for (const std::size_t j : {i - (x > 0 ? 1 : 0), i + 1}) {
          if (j == i || !mask->texels[i]) continue;
          if (view_z(depth->texels[j]) + 1.0f < view_z(depth->texels[i])) {
            ++at_edge;
            break;
          }
        }
      }
  }
  std::printf("[ discontinuity ] %d mask pixels beside a surface at least 1 m nearer\n", at_edge);
  EXPECT_GT(at_edge, 0) << "shadowed ground right behind the box's edge";
}

}  // namespace
}  // namespace nbsim::capture
