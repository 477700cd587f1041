// CaptureTest: the occlusion-culling technique run headless on a small city, checked against itself
// and against the C++ core: GLSL N-buffer levels equal the core's bit for bit, GL's counters are
// consistent, the ID-buffer ground truth adds up, and no culling mode hides a visible object.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include <filesystem>
#include <set>

#include "model/common/error.h"
#include "model/nbuffer/nbuffer.h"
#include "traces/capture/capture.h"
#include "traces/capture/city.h"
#include "traces/capture/paths.h"
#include "traces/capture/renderer.h"
#include "traces/capture/scenes.h"
#include "traces/capture/technique.h"
#include "traces/format/reader.h"
#include "tests/common/bsp_writer.h"
#include "tests/common/scratch.h"

namespace nbsim::capture {
namespace {

// A small city and `frames` poses of a camera path, from the scene and path tables.
struct Small {
  CaptureScene scene;
  std::vector<CameraPose> poses;
  Small(const char* path, int frames) {
    const OptionValues o = {{"objects", "600"}, {"seed", "7"}};
    scene = find_scene("city").make(o);
    poses = find_path(path).make(scene, frames, o);
  }
};

// occlusion_culling at 160x120 in `mode`; levels_every 1 records every frame's levels.
RendererOptions options(trace::TestMode mode, bool reversed = false, int levels_every = 0) {
  RendererOptions o;
  o.technique = "occlusion_culling";
  o.width = 160;
  o.height = 120;
  o.options = {{"mode", std::string(scene::to_string(mode))}, {"levels-every", std::to_string(levels_every)}};
  o.projection.reversed_z = reversed;
  return o;
}

// The city has the requested objects, a BVH whose leaves hold every object once, and bounds that
// contain each object's triangles.
TEST(CaptureTest, CityAndBvhAreConsistent) {
  CityParams p;
  p.objects = 5000;
  const City c = make_city(p);
  ASSERT_EQ(c.objects.size(), 5000u);
  std::vector<int> seen(c.objects.size(), 0);
  for (std::size_t n = 0; n < c.scene.node_bounds.size(); ++n)
    if (c.scene.node_left[n] < 0)
      for (std::uint32_t i = c.scene.node_first[n]; i < c.scene.node_first[n] + c.scene.node_count[n]; ++i) ++seen[c.scene.leaf_objects[i]];
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int k) { return k == 1; })) << "every object in exactly one leaf";
  for (std::size_t n = 0; n < c.scene.node_bounds.size(); ++n) {
    if (c.scene.node_left[n] < 0) continue;
    for (auto child : {c.scene.node_left[n], c.scene.node_right[n]})
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(c.scene.node_bounds[n].lo[k], c.scene.node_bounds[static_cast<std::size_t>(child)].lo[k]) << "parent bounds contain children";
        EXPECT_GE(c.scene.node_bounds[n].hi[k], c.scene.node_bounds[static_cast<std::size_t>(child)].hi[k]);
      }
  }
}

// The GLSL N-buffer levels equal the C++ core's levels built from the captured depth, bit for bit.
TEST(CaptureTest, GlslLevelsEqualCoreLevels) {
  for (bool reversed : {false, true}) {
    Small s("walk", 3);
    Renderer r(s.scene, options(trace::TestMode::NBuffer, reversed, 1));
    for (std::uint32_t f = 0; f < 3; ++f) {
      const scene::Frame fr = r.render(f, s.poses[f]).frame;
      ASSERT_EQ(fr.levels.size(), 1u) << "levels every frame";
      const auto& d = fr.depths.at(0);
      ASSERT_EQ(d.name, "after_occluders");
      DepthImage img(d.width, d.height, 0.0f);
      img.texels = d.texels;
      const NBuffer core(img, {reversed ? FarOp::Min : FarOp::Max, StorageFormat::F32, -1});
      ASSERT_EQ(fr.levels[0].levels, core.level_count());
      for (int i = 0; i < core.level_count(); ++i) {
        const auto level = core.level(i);
        const float* gl = fr.levels[0].texels.data() + static_cast<std::size_t>(i) * level.size();
        EXPECT_EQ(std::memcmp(gl, level.data(), level.size() * 4), 0) << "frame " << f << " level " << i << " reversed " << reversed;
      }
    }
  }
}

// For every mode: samples passed never exceed rasterized fragments, the ID-buffer pixels add up
// to the covered pixels, and every object with visible pixels was rendered by the technique.
TEST(CaptureTest, CountersAndGroundTruthAreConsistent) {
  for (auto mode : {trace::TestMode::OcclusionQuery, trace::TestMode::OcclusionQueryHier, trace::TestMode::NBuffer,
                    trace::TestMode::NBufferHier, trace::TestMode::None}) {
    for (const char* path : {"walk", "fly"}) {
      Small s(path, 4);
      Renderer r(s.scene, options(mode));
      for (std::uint32_t f = 0; f < 4; ++f) {
        const CapturedFrame cf = r.render(f, s.poses[f]);
        const scene::Frame& fr = cf.frame;
        ASSERT_TRUE(fr.truth.has_value());
        ASSERT_TRUE(cf.rendered_objects.has_value()) << "occlusion culling reports what it drew";
        EXPECT_TRUE(fr.levels.empty()) << "levels-every 0 records no levels";
        for (const auto& d : fr.draws) {
          EXPECT_LE(d.gl.samples_passed, d.gl.fragments) << "draw " << d.index << " frame " << f;
          if (!d.clip_positions.empty()) {
            EXPECT_EQ(d.clip_positions.size() % 3, 0u) << "whole triangles captured";
          }
        }
        std::uint64_t sum = 0;
        for (auto v : fr.truth->visible_pixels) sum += v;
        EXPECT_EQ(sum, fr.truth->covered_pixels) << "ID-buffer pixels add up";
        EXPECT_LE(fr.truth->covered_pixels, 160u * 120u);
        const auto& rendered = *cf.rendered_objects;
        for (std::size_t o = 0; o < fr.truth->visible_pixels.size(); ++o) {
          if (!fr.truth->visible_pixels[o]) continue;
          EXPECT_TRUE(std::binary_search(rendered.begin(), rendered.end(), o))
              << "object " << o << " is visible (" << fr.truth->visible_pixels[o] << " px) but mode "
              << static_cast<int>(mode) << " culled it in frame " << f;
        }
      }
    }
  }
}

// Occlusion-query decisions agree with GL's samples passed, and bounds crossing the near plane
// are never culled.
TEST(CaptureTest, QueryDecisionsFollowGlCounters) {
  Small s("walk", 3);
  Renderer r(s.scene, options(trace::TestMode::OcclusionQuery));
  for (std::uint32_t f = 0; f < 3; ++f) {
    const scene::Frame fr = r.render(f, s.poses[f]).frame;
    int queries = 0;
    for (const auto& d : fr.draws) {
      if (d.role != trace::DrawRole::BoundsQuery) continue;
      ++queries;
      ASSERT_TRUE(d.has_bounds);
      EXPECT_EQ(d.bounds.visible, d.bounds.crosses_near || d.gl.samples_passed > 0) << "draw " << d.index;
      EXPECT_EQ(d.clip_positions.size(), 36u) << "a box is 12 triangles";
      EXPECT_FALSE(d.state.write) << "queries do not write depth";
    }
    if (f > 0) {
      EXPECT_GT(queries, 0) << "frame " << f << " tested no bounds";
    }
  }
}

// A captured trace file checks itself when read back: header properties name the renderer, the
// GLSL levels equal the core's levels from the recorded depth, the counters and the ground truth
// are consistent, and every visible object was drawn (as an occluder or a visible object).
TEST(CaptureTest, TraceFileChecksItself) {
  for (bool reversed : {false, true}) {
    CaptureOptions o;
    o.width = 128;
    o.height = 96;
    o.frames = 4;
    o.options = {{"objects", "800"}, {"seed", "5"}, {"mode", "nb"}, {"levels-every", "1"}};
    o.reversed_z = reversed;
    const auto file = nbsim::testing::scratch_path("nbsim_capture", "capture.nbt");
    const CaptureSummary sum = capture(o, file.string());
    EXPECT_EQ(sum.frames, 4);
    EXPECT_EQ(sum.visible_not_rendered, 0u);

    trace::FrameReader frames(file);
    const trace::TraceReader& tr = frames.trace();
    ASSERT_NE(tr.property("gl_renderer"), nullptr);
    EXPECT_NE(tr.property("gl_renderer")->find("llvmpipe"), std::string::npos) << *tr.property("gl_renderer");
    EXPECT_EQ(*tr.property("depth_func"), reversed ? "GREATER" : "LESS");
    ASSERT_NE(tr.property("technique"), nullptr);
    EXPECT_EQ(*tr.property("technique"), "occlusion_culling") << "the technique's name comes from its row";
    EXPECT_EQ(*tr.property("test_mode"), "nb");
    EXPECT_EQ(*tr.property("scene"), "city");
    EXPECT_EQ(*tr.property("path"), "walk");
    ASSERT_NE(tr.scene(), nullptr);
    EXPECT_EQ(tr.scene()->objects.size(), 800u);
    const FarOp op = reversed ? FarOp::Min : FarOp::Max;
    int count = 0;
    while (auto f = frames.next()) {
      ++count;
      const trace::DepthSnapshot* d = f->depth(trace::DepthWhich::AfterOccluders);
      const trace::NBufferLevels* l = f->nbuffer(op);
      ASSERT_NE(d, nullptr);
      ASSERT_NE(l, nullptr);
      DepthImage img(d->width, d->height, 0.0f);
      img.texels = d->texels;
      const NBuffer core(img, {op, StorageFormat::F32, -1});
      ASSERT_EQ(l->levels, core.level_count());
      EXPECT_EQ(std::memcmp(l->texels.data(), core.level(0).data(), l->texels.size() * 4), 0)
          << "GLSL levels differ from the core's in frame " << f->begin.frame;
      std::set<std::int32_t> drawn;
      for (const auto& draw : f->draws) {
        EXPECT_LE(draw.gl.samples_passed, draw.gl.fragments);
        if (draw.role == trace::DrawRole::Occluder || draw.role == trace::DrawRole::Visible) drawn.insert(draw.object);
        if (draw.role == trace::DrawRole::NBufferBuild) {
          EXPECT_EQ(draw.gl.fragments, 128u * 96u) << "a full-screen pass shades every pixel once";
        }
      }
      ASSERT_TRUE(f->truth.has_value());
      std::uint64_t sum_px = 0;
      for (std::size_t obj = 0; obj < f->truth->visible_pixels.size(); ++obj) {
        sum_px += f->truth->visible_pixels[obj];
        if (f->truth->visible_pixels[obj]) {
          EXPECT_TRUE(drawn.count(static_cast<std::int32_t>(obj))) << "visible object " << obj << " not drawn";
        }
      }
      EXPECT_EQ(sum_px, f->truth->covered_pixels);
    }
    EXPECT_EQ(count, 4);
    std::filesystem::remove(file);
  }
}


// Every technique of the table runs on every scene along every camera path the scene's site allows
// (tiny captures with the rows' default options, scenes at most 300 objects, a level file's scene
// on the room of tests/common/bsp_writer.h): the header names the row, every frame is written, and
// a technique that reports what it drew drew every visible object.
TEST(CaptureTest, EveryTechniqueRunsOnEverySceneAndPath) {
  int runs = 0;
  const std::filesystem::path level = nbsim::testing::scratch_path("nbsim_capture", "room.bsp");
  nbsim::testing::write_bsp(nbsim::testing::room_map(), level);
  for (const auto& t : technique_table()) {
    if (t.no_scene && !t.no_scene(OptionValues{}).empty()) {
      // A capture that draws no scene (by default) builds none, walks no path and refuses both.
      CaptureOptions o;
      o.technique = t.info.name;
      o.width = 48;
      o.height = 32;
      o.frames = 2;
      const auto file = nbsim::testing::scratch_path("nbsim_capture", "every_" + t.info.name + "_no_scene.nbt");
      const CaptureSummary sum = capture(o, file.string());
      EXPECT_EQ(sum.frames, 2);
      trace::FrameReader frames(file);
      EXPECT_EQ(*frames.trace().property("scene"), "none") << t.info.name;
      EXPECT_EQ(*frames.trace().property("path"), "none") << t.info.name;
      EXPECT_TRUE(frames.trace().scene() == nullptr || frames.trace().scene()->objects.empty()) << t.info.name << ": no scene built";
      std::filesystem::remove(file);
      for (const auto& sc : scene_table()) {
        o.scene = sc.info.name;
        o.scene_given = true;
        try {
          capture(o, file.string());
          ADD_FAILURE() << t.info.name << " took --scene " << sc.info.name;
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("draws no scene"), std::string::npos) << e.what();
        }
        EXPECT_FALSE(std::filesystem::exists(file));
      }
      ++runs;
      continue;
    }
    for (const auto& sc : scene_table())
      for (const auto& p : path_table()) {
        CaptureOptions o;
        o.technique = t.info.name;
        o.scene = sc.info.name;
        o.path = p.info.name;
        o.width = 48;
        o.height = 32;
        o.frames = 2;
        for (const auto& spec : sc.info.options) {
          if (spec.name == "objects") o.options.set("objects", "300");
          if (spec.name == "bsp") o.options.set("bsp", level.string());  // a scene read from a level file: the test room
        }
        const auto file =
            nbsim::testing::scratch_path("nbsim_capture", "every_" + t.info.name + "_" + sc.info.name + "_" + p.info.name + ".nbt");
        CaptureSummary sum;
        try {
          sum = capture(o, file.string());
        } catch (const InputError& e) {
          // Only a path that the scene's site does not allow may be refused.
          EXPECT_TRUE(std::string(e.what()).find("needs a scene with") != std::string::npos)
              << t.info.name << " on " << sc.info.name << " along " << p.info.name << ": " << e.what();
          continue;
        }
        ++runs;
        EXPECT_EQ(sum.frames, 2);
        EXPECT_EQ(sum.visible_not_rendered, 0u) << t.info.name << " on " << sc.info.name << " along " << p.info.name;
        trace::FrameReader frames(file);
        ASSERT_NE(frames.trace().property("technique"), nullptr);
        EXPECT_EQ(*frames.trace().property("technique"), t.info.name);
        EXPECT_EQ(*frames.trace().property("scene"), sc.info.name);
        EXPECT_EQ(*frames.trace().property("path"), p.info.name);
        int count = 0;
        while (frames.next()) ++count;
        EXPECT_EQ(count, 2);
        std::filesystem::remove(file);
      }
  }
  EXPECT_GE(runs, 2) << "occlusion culling on the city along walk and fly at least";
}

// A capture that fails mid-way (here: after its first frame, by its progress callback) leaves no
// partial trace, for every technique: neither OUT nor its temporary OUT.partial exists after it,
// and an OUT already there is left as it was.
TEST(CaptureTest, FailedCaptureLeavesNoPartialFile) {
  const std::filesystem::path dir = nbsim::testing::scratch_path("nbsim_capture", "partial");
  std::filesystem::create_directories(dir);
  for (const TechniqueRow& t : technique_table()) {
    SCOPED_TRACE(t.info.name);
    CaptureOptions o;
    o.technique = t.info.name;
    o.scene = "boxes";
    o.path = "fly";
    o.width = 32;
    o.height = 24;
    o.frames = 2;
    const std::filesystem::path out = dir / (t.info.name + ".nbt"), kept = dir / (t.info.name + "_kept.nbt");
    const auto stop = [](int done, int) {
      if (done == 1) throw InputError("stopped after frame 0");
    };
    EXPECT_THROW(capture(o, out.string(), stop), InputError);
    EXPECT_FALSE(std::filesystem::exists(out)) << "no partial trace";
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial")) << "no temporary file left";
    {
      std::FILE* f = std::fopen(kept.string().c_str(), "wb");
      ASSERT_NE(f, nullptr);
      std::fputs("an older trace", f);
      std::fclose(f);
    }
    EXPECT_THROW(capture(o, kept.string(), stop), InputError);
    EXPECT_EQ(std::filesystem::file_size(kept), 14u) << "an existing OUT is left as it was";
    const CaptureSummary whole = capture(o, out.string());
    EXPECT_EQ(whole.frames, 2);
    EXPECT_EQ(whole.bytes, std::filesystem::file_size(out));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nbsim::capture
