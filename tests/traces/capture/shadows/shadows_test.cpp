// ShadowsTest: the shadows technique (traces/capture/shadows/) run headless on the three scenes in
// the three modes, checked on GL's own records: the shadow mask of every mode equals the infinite
// reference on every frame (the recorded count is 0 and the images are equal), the masks of the
// three captures are equal, the fill is clamped <= culled <= infinite, the SHDC record is whole
// and its volume draws are the ShadowVolume draws; and two hard cases of issue 13 (the ground
// facing the light, the camera inside a shadow volume).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <cmath>
#include <map>
#include <string>
#include <variant>

#include "model/common/error.h"
#include "tests/common/light_text.h"
#include "tests/common/technique_record.h"
#include "traces/capture/capture.h"
#include "traces/capture/renderer.h"
#include "traces/capture/scenes.h"
#include "traces/format/reader.h"
#include "traces/format/shadows/shadows_chunk.h"
#include "tests/common/scratch.h"
#include "model/shadows/roles.h"

namespace nbsim::capture {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return nbsim::testing::scratch_path("nbsim_shadows", name + ".nbt");
}

// A small capture: 128x96, 2 frames of the flyover, litmaps of 128, small scenes.
CaptureOptions small(const std::string& scene, const std::string& mode) {
  CaptureOptions o;
  o.technique = "shadows";
  o.scene = scene;
  o.path = "fly";
  o.width = 128;
  o.height = 96;
  o.frames = 2;
  o.options = {{"shadow-mode", mode}, {"litmap", "128"}, {"levels-every", "1"}, {"seed", "4"}};
  if (scene == "city") o.options.set("objects", "300");
  if (scene == "terrain") o.options.set("birds", "400"), o.options.set("towers", "20");
  return o;
}

using nbsim::testing::field;

struct FrameResult {
  std::vector<std::uint8_t> mask, reference;
  std::uint64_t fill = 0;
};

// Reads a shadows trace, checks what every mode must satisfy and returns each frame's mask and fill.
std::vector<FrameResult> check_trace(const fs::path& file, const std::string& mode) {
  std::vector<FrameResult> out;
  trace::FrameReader frames(file);
  EXPECT_EQ(*frames.trace().property("technique"), "shadows");
  EXPECT_EQ(*frames.trace().property("shadow_mode"), mode);
  EXPECT_EQ(*frames.trace().property("depth_format"), "DEPTH24_STENCIL8");
  while (auto f = frames.next()) {
    FrameResult r;
    EXPECT_TRUE(f->light.has_value()) << "the light camera is recorded";
    for (const char* name : {"final", "litmap_min", "litmap_max"}) EXPECT_NE(f->depth(name), nullptr) << name;
    for (const char* name : {"stencil", "light_region", "shadow_mask", "shadow_mask_infinite"}) EXPECT_NE(f->stencil(name), nullptr) << name;
    EXPECT_NE(f->nbuffer("litmap_min", FarOp::Min), nullptr) << "the min N-buffer over the min litmap";
    EXPECT_NE(f->nbuffer("litmap_max", FarOp::Max), nullptr) << "the max N-buffer over the max litmap";
    if (!f->stencil("shadow_mask") || !f->stencil("shadow_mask_infinite")) return out;
    r.mask = f->stencil("shadow_mask")->texels;
    r.reference = f->stencil("shadow_mask_infinite")->texels;
    EXPECT_EQ(r.mask, r.reference) << "frame " << f->begin.frame << ": the " << mode << " mask differs from the infinite one";
    const std::size_t records = f->begin.frame == 0 ? 3 : 1;
    EXPECT_EQ(f->technique_records.size(), records) << "one SHDC record a frame, and the casters' (SHDG) and every object's (SHDM) meshes in the first";
    if (f->technique_records.size() != records) return out;
    const auto& rec = f->technique_records[0];
    EXPECT_EQ(rec.type, trace::kShadowsChunk);
    if (records == 2) {
      EXPECT_EQ(f->technique_records[1].type, trace::kCasterMeshesChunk);
      EXPECT_EQ(std::get<std::uint64_t>(f->technique_records[1].fields[0].value), std::get<std::uint64_t>(rec.fields[0].value))
          << "a mesh for every caster";
    }
    for (const auto& fl : rec.fields) {
      if (fl.name == "mask_diff_pixels") {
        EXPECT_EQ(std::get<std::uint64_t>(fl.value), 0u) << "the recorded count of differing mask pixels";
      }
    }
    const auto& decision = field<std::uint32_t>(rec, "decision");
    const auto& draw = field<std::int32_t>(rec, "draw");
    const auto& clamp_far = field<float>(rec, "clamp_far");
    std::map<std::int32_t, bool> volume_draws;
    // The receiver splat: one point draw into each litmap, one point a receiver pixel in the light's
    // frustum (GL's fragment counter against the capture's double-precision light_region).
    std::uint64_t region_pixels = 0;
    for (std::uint8_t t : f->stencil("light_region")->texels) region_pixels += t;
    std::vector<std::uint64_t> splats;
    for (const auto& d : f->draws)
      if (d.role == nbsim::shadows::kReceiverSplatRole) {
        splats.push_back(d.gl.fragments);
        EXPECT_EQ(d.topology, trace::Topology::Points);
        EXPECT_TRUE(d.state.write) << "the splat writes the litmap's depth";
      }
    EXPECT_EQ(splats, std::vector<std::uint64_t>(2, region_pixels)) << "frame " << f->begin.frame << ": one point per receiver, per litmap";
    for (const auto& d : f->draws) {
      EXPECT_LE(d.gl.samples_passed, d.gl.fragments) << "draw " << d.index;
      if (d.role != nbsim::shadows::kShadowVolumeRole) continue;
      r.fill += d.gl.fragments;
      volume_draws[static_cast<std::int32_t>(d.index)] = true;
      EXPECT_TRUE(d.stencil.test && d.state.depth_clamp && !d.state.write) << "z-fail volumes: stencil, depth clamp, no depth writes";
      EXPECT_EQ(d.stencil.back.depth_fail, trace::StencilOp::IncrWrap);
      EXPECT_EQ(d.stencil.front.depth_fail, trace::StencilOp::DecrWrap);
      EXPECT_EQ(d.clip_positions.size() % 3, 0u) << "triangles captured by transform feedback";
      EXPECT_FALSE(d.clip_positions.empty());
    }
    std::size_t drawn = 0;
    for (std::size_t c = 0; c < decision.size(); ++c) {
      const bool dropped = decision[c] == 1 || decision[c] == 2;
      EXPECT_EQ(draw[c] >= 0, mode == "infinite" || !dropped) << "caster " << c << " decision " << decision[c];
      if (draw[c] >= 0) {
        ++drawn;
        EXPECT_TRUE(volume_draws.count(draw[c])) << "caster " << c << "'s draw is a volume";
      }
      if (dropped) {
        EXPECT_TRUE(std::isinf(clamp_far[c])) << "a culled caster has no clamp planes";
      }
    }
    EXPECT_EQ(drawn, volume_draws.size()) << "one volume draw a drawn caster";
    out.push_back(std::move(r));
  }
  EXPECT_EQ(out.size(), 2u);
  return out;
}

// Every scene in every mode: masks equal to the infinite reference on every frame and across the
// modes; fill clamped <= culled <= infinite; shadows exist and some casters are culled.
TEST(ShadowsTest, EverySceneAndModeKeepsTheMask) {
  for (const std::string scene : {"boxes", "terrain", "city"}) {
    std::map<std::string, std::vector<FrameResult>> by_mode;
    std::map<std::string, CaptureSummary> sums;
    for (const std::string mode : {"infinite", "culled", "clamped"}) {
      SCOPED_TRACE(scene + " " + mode);
      const fs::path file = scratch(scene + "_" + mode);
      sums[mode] = capture(small(scene, mode), file.string());
      by_mode[mode] = check_trace(file, mode);
      fs::remove(file);
      std::map<std::string, std::uint64_t> counts(sums[mode].technique_counts.begin(), sums[mode].technique_counts.end());
      EXPECT_EQ(counts["mask_diff_pixels"], 0u) << "the recorded count of mask pixels that differ from infinite";
      EXPECT_GT(counts["mask_pixels"], 0u) << "the scene casts visible shadows";
      EXPECT_GT(counts["casters_culled"], 0u) << "some casters cast no visible shadow";
    }
    ASSERT_EQ(by_mode["infinite"].size(), 2u);
    for (std::size_t f = 0; f < 2 && by_mode["clamped"].size() == 2 && by_mode["culled"].size() == 2; ++f) {
      SCOPED_TRACE(scene + " frame " + std::to_string(f));
      EXPECT_EQ(by_mode["culled"][f].mask, by_mode["infinite"][f].mask) << "culling keeps the mask";
      EXPECT_EQ(by_mode["clamped"][f].mask, by_mode["infinite"][f].mask) << "clamping keeps the mask";
      EXPECT_LE(by_mode["clamped"][f].fill, by_mode["culled"][f].fill) << "clamping only removes fill";
      EXPECT_LE(by_mode["culled"][f].fill, by_mode["infinite"][f].fill) << "culling only removes fill";
    }
    EXPECT_LT(by_mode["clamped"][0].fill, by_mode["infinite"][0].fill) << scene << ": clamping saves fill";
  }
}

// One frame from a pose of our choice through the renderer; its counts by name.
std::map<std::string, std::uint64_t> render_once(const std::string& scene_name, const OptionValues& options, const CameraPose& pose,
                                                 scene::Frame* frame = nullptr) {
  const CaptureScene scene = find_scene(scene_name).make(options);
  RendererOptions ro;
  ro.technique = "shadows";
  ro.width = 128;
  ro.height = 96;
  ro.options = options;
  Renderer renderer(scene, ro);
  CapturedFrame cf = renderer.render(0, pose);
  if (frame) *frame = std::move(cf.frame);
  return {cf.counts.begin(), cf.counts.end()};
}

// The ground facing the light: a light straight above the plane (its axis perpendicular to it)
// and a box the observer does not see, whose shadow on the plane the observer sees: the only
// receivers in the box's rectangle are the plane at one light depth, so z_min == z_max, a slab of
// zero thickness. The margin keeps the shadow: the caster is kept, and the mask is the infinite one.
TEST(ShadowsTest, GroundFacingTheLightKeepsItsShadow) {
  // No levels: 1024-lexel litmaps with their levels exceed a 128x96 trace frame's limit.
  OptionValues o{{"boxes", "1"}, {"seed", "2"}, {"litmap", "1024"}, {"light-fov", "170"}, {"levels-every", "0"}};
  const CaptureScene scene = find_scene("boxes").make(o);
  const scene::Aabb& b = scene.scene.objects[1];
  const float h = b.hi[1], bx = 0.5f * (b.lo[0] + b.hi[0]), bz = 0.5f * (b.lo[2] + b.hi[2]);
  // The light 50 m to the box's -x side, 6 h high, looking straight down: the shadow on the plane
  // runs from the box's +x face about 10 m on.
  o.set("light", nbsim::testing::light_text({bx - 50.0f, 6.0f * h, bz}, {bx - 50.0f, 0.0f, bz}));
  scene::Frame f;
  // The eye 3 m above the shadow's middle, looking down and away from the box.
  const auto counts = render_once("boxes", o, {{b.hi[0] + 5.0f, 3.0f, bz}, {b.hi[0] + 5.5f, 0.0f, bz}}, &f);
  EXPECT_GT(counts.at("mask_pixels"), 0u) << "the box's shadow is seen";
  EXPECT_EQ(counts.at("mask_diff_pixels"), 0u) << "clamped to a zero-thickness slab, the mask is the infinite one";
  ASSERT_EQ(f.technique_records.size(), 3u) << "SHDC and, in the first frame, SHDG and SHDM";
  const auto& rec = f.technique_records[0];
  const auto& object = field<std::uint32_t>(rec, "object");
  ASSERT_EQ(object.size(), 1u) << "one caster: the box (the plane is open)";
  EXPECT_EQ(object[0], 1u);
  EXPECT_EQ(field<std::uint32_t>(rec, "decision")[0], 0u) << "the caster is kept";
  const float z_min = field<float>(rec, "z_min")[0], z_max = field<float>(rec, "z_max")[0];
  EXPECT_NEAR(z_min, z_max, 1e-6f) << "only the plane, square to the light, is in the rectangle";
  EXPECT_GT(field<float>(rec, "clamp_far")[0], z_max) << "the far plane lies beyond the slab by the margin";
}

// The camera inside a shadow volume (standing in a box's ground shadow, a light low on one side):
// z-fail with caps counts right there, so the mask is non-empty and equal to the infinite one.
TEST(ShadowsTest, CameraInsideAShadowVolume) {
  OptionValues o{{"boxes", "1"}, {"seed", "5"}, {"litmap", "256"}};
  const CaptureScene scene = find_scene("boxes").make(o);
  const scene::Aabb& b = scene.scene.objects[1];
  const float cz = 0.5f * (b.lo[2] + b.hi[2]), height = b.hi[1];
  // The light 100 m to the -x side and 100 m up: the shadow falls on +x, 45 degrees down.
  o.set("light", nbsim::testing::light_text({b.lo[0] - 100.0f, 100.0f, cz}, {b.hi[0], 0.0f, cz}));
  scene::Frame f;
  // The eye 0.5 m above the ground, 0.5 m past the box: its light ray crosses the box (1 m up at
  // the box's face, the box at least 2 m tall).
  const auto counts = render_once("boxes", o, {{b.hi[0] + 0.5f, 0.5f, cz}, {b.hi[0] + 30.0f, 0.0f, cz}}, &f);
  ASSERT_GE(height, 2.0f);
  EXPECT_GT(counts.at("mask_pixels"), 0u) << "the ground around the eye is in shadow";
  EXPECT_EQ(counts.at("mask_diff_pixels"), 0u);
  const auto* mask = f.stencil("shadow_mask");
  ASSERT_NE(mask, nullptr);
  EXPECT_EQ(mask->texels[static_cast<std::size_t>(2 * 128 + 64)], 1) << "the ground just in front of the eye is in shadow";
}

// A light inside a caster is refused with an InputError naming it, before any frame.
TEST(ShadowsTest, LightInsideACasterIsRefused) {
  OptionValues o{{"boxes", "3"}, {"seed", "7"}};
  const CaptureScene scene = find_scene("boxes").make(o);
  const scene::Aabb& b = scene.scene.objects[2];
  o.set("light", nbsim::testing::light_text({0.5f * (b.lo[0] + b.hi[0]), 0.5f * (b.lo[1] + b.hi[1]), 0.5f * (b.lo[2] + b.hi[2])}, {0.0f, 0.0f, 0.0f}));
  RendererOptions ro;
  ro.technique = "shadows";
  ro.width = 32;
  ro.height = 24;
  ro.options = o;
  try {
    Renderer renderer(scene, ro);
    ADD_FAILURE() << "a light inside a caster was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is inside caster object 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim::capture
