// The apps program's core (model/apps/replay.h) on frames built here: what it replays and what it
// flags, by each reason; the clears, the recorded depth changes and the stale targets; the window's
// framebuffer drawn upside down; damaged records refused by name. GL's side of these counts (the
// samples each draw passes) is checked by the apitrace and native capture tests
// (tests/traces/apitrace, tests/traces/capture/apps).
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "model/apps/draw_flags.h"
#include "model/apps/replay.h"
#include "model/apps/roles.h"
#include "model/common/error.h"
#include "model/scene/technique_record.h"

namespace nbsim::apps {
namespace {

using namespace flags;

constexpr std::uint32_t fourcc(const char (&s)[5]) { return scene::record_type(s); }

constexpr int kW = 32, kH = 16;

// One draw as the AppDraws record and the DRAW record hold it: a full-target rectangle at depth z
// (two triangles, clip w = 1), depth LESS with writes, no culling, into framebuffer `fb`.
struct Draw {
  std::uint32_t fb = 7, flags = kDepthTest | kDepthMask | kFrontCcw, skipped = 0, primitive = 4, bits = 32, is_float = 1, polygon_mode = 0x1B02;
  int width = kW, height = kH;
  std::array<std::int32_t, 4> viewport{0, 0, kW, kH}, scissor{0, 0, kW, kH};
  float near = 0.0f, far = 1.0f, factor = 0.0f, units = 0.0f;
  float z = 0.0f;                                    // clip z (window depth 0.5 + z / 2)
  std::array<float, 4> rect{-1.0f, -1.0f, 1.0f, 1.0f};  // clip x0, y0, x1, y1
  std::uint64_t gl_samples = 0;
};

struct Clear {
  std::uint32_t before = 0, fb = 7, buffers = kClearDepth, flags = kDepthMask, stencil_mask = 0xFF;
  std::array<std::int32_t, 4> scissor{0, 0, kW, kH};
  std::int32_t stencil = 0;
  float depth = 1.0f;
};

struct Change {
  std::uint32_t draw = 0;
  std::vector<std::uint32_t> pixel;
  std::vector<float> depth;
};

scene::TechniqueField field(std::string name, decltype(scene::TechniqueField::value) v) { return {std::move(name), std::move(v)}; }

scene::Frame frame_of(const std::vector<Draw>& draws, const std::vector<Clear>& clears, const std::vector<Change>& changes = {},
                      std::uint32_t main_fb = 7, const std::vector<float>* final_depth = nullptr) {
  scene::Frame f;
  f.begin.frame = 3;
  scene::TechniqueRecord d;
  d.type = fourcc("APDS");
  d.decoded = true;
  std::vector<std::uint32_t> mode, call, skipped, primitive, fl, fb, w, h, bits, is_float, pm;
  std::vector<std::int32_t> vx, vy, vw, vh, sx, sy, sw, sh;
  std::vector<float> near, far, factor, units;
  for (std::size_t k = 0; k < draws.size(); ++k) {
    const Draw& x = draws[k];
    scene::DrawRecord r;
    r.index = static_cast<std::uint32_t>(k);
    r.role = kAppDrawRole;
    r.state.func = scene::DepthFunc::Less;
    r.state.test = (x.flags & kDepthTest) != 0;
    r.state.write = (x.flags & kDepthMask) != 0;
    r.state.cull = scene::CullFace::None;
    r.gl.samples_passed = x.gl_samples;
    const auto [x0, y0, x1, y1] = x.rect;
    r.clip_positions = {{x0, y0, x.z, 1}, {x1, y0, x.z, 1}, {x1, y1, x.z, 1}, {x0, y0, x.z, 1}, {x1, y1, x.z, 1}, {x0, y1, x.z, 1}};
    f.draws.push_back(r);
    mode.push_back(4), call.push_back(0), skipped.push_back(x.skipped), primitive.push_back(x.primitive), fl.push_back(x.flags);
    fb.push_back(x.fb), w.push_back(static_cast<std::uint32_t>(x.width)), h.push_back(static_cast<std::uint32_t>(x.height));
    bits.push_back(x.bits), is_float.push_back(x.is_float), pm.push_back(x.polygon_mode);
    vx.push_back(x.viewport[0]), vy.push_back(x.viewport[1]), vw.push_back(x.viewport[2]), vh.push_back(x.viewport[3]);
    sx.push_back(x.scissor[0]), sy.push_back(x.scissor[1]), sw.push_back(x.scissor[2]), sh.push_back(x.scissor[3]);
    near.push_back(x.near), far.push_back(x.far), factor.push_back(x.factor), units.push_back(x.units);
  }
  d.fields = {field("count", std::uint64_t{draws.size()}), field("mode", mode), field("call", call), field("skipped", skipped),
              field("primitive", primitive), field("flags", fl), field("framebuffer", fb), field("target_width", w),
              field("target_height", h), field("depth_bits", bits), field("depth_float", is_float), field("polygon_mode", pm),
              field("viewport_x", vx), field("viewport_y", vy), field("viewport_w", vw), field("viewport_h", vh), field("scissor_x", sx),
              field("scissor_y", sy), field("scissor_w", sw), field("scissor_h", sh), field("depth_near", near), field("depth_far", far),
              field("offset_factor", factor), field("offset_units", units)};
  f.technique_records.push_back(d);
  scene::TechniqueRecord c;
  c.type = fourcc("APCL");
  c.decoded = true;
  std::vector<std::uint32_t> before, cfb, buffers, cfl, smask;
  std::vector<std::int32_t> csx, csy, csw, csh, sv;
  std::vector<float> depth;
  for (const Clear& x : clears) {
    before.push_back(x.before), cfb.push_back(x.fb), buffers.push_back(x.buffers), cfl.push_back(x.flags), smask.push_back(x.stencil_mask);
    csx.push_back(x.scissor[0]), csy.push_back(x.scissor[1]), csw.push_back(x.scissor[2]), csh.push_back(x.scissor[3]);
    sv.push_back(x.stencil), depth.push_back(x.depth);
  }
  c.fields = {field("count", std::uint64_t{clears.size()}), field("before_draw", before), field("framebuffer", cfb), field("buffers", buffers),
              field("flags", cfl), field("stencil_write_mask", smask), field("scissor_x", csx), field("scissor_y", csy),
              field("scissor_w", csw), field("scissor_h", csh), field("stencil", sv), field("depth", depth)};
  f.technique_records.push_back(c);
  scene::TechniqueRecord fr;
  fr.type = fourcc("APFR");
  fr.decoded = true;
  fr.fields = {field("framebuffer", std::uint64_t{main_fb}), field("width", std::uint64_t{kW}), field("height", std::uint64_t{kH}),
               field("unhandled", std::string())};
  f.technique_records.push_back(fr);
  for (const Change& x : changes) {
    scene::TechniqueRecord r;
    r.type = fourcc("APDC");
    r.decoded = true;
    r.fields = {field("draw", std::uint64_t{x.draw}), field("framebuffer", std::uint64_t{7}), field("width", std::uint64_t{kW}),
                field("height", std::uint64_t{kH}), field("pixel", x.pixel), field("depth", x.depth)};
    f.technique_records.push_back(r);
  }
  if (final_depth) {
    scene::DepthSnapshot s;
    s.name = "final";
    s.width = kW, s.height = kH;
    s.texels = *final_depth;
    f.depths.push_back(s);
  }
  return f;
}

constexpr std::uint64_t kArea = static_cast<std::uint64_t>(kW) * kH;

TEST(AppsReplayTest, ReplaysDrawsAfterTheirClearsAndComparesTheirSamples) {
  AppsReplay replay;
  Draw near, far;
  near.z = -0.5f, near.gl_samples = kArea;
  far.z = 0.5f, far.gl_samples = 0;  // behind the first everywhere
  std::vector<float> final_depth(kArea, 0.25f);  // window depth of clip z -0.5
  const AppFrameCounts k = replay.run_frame(frame_of({near, far}, {Clear{}}, {}, 7, &final_depth));
  ASSERT_EQ(k.draws.size(), 2u);
  EXPECT_EQ(k.clears, 1u);
  for (const AppDrawCounts& d : k.draws) {
    EXPECT_EQ(d.reason, Reason::Replayed);
    EXPECT_FALSE(d.stale) << "cleared whole before the draw";
    EXPECT_FALSE(d.mismatch()) << d.draw << ": model " << d.samples << " GL " << d.gl_samples;
  }
  EXPECT_EQ(k.draws[0].samples, kArea);
  EXPECT_EQ(k.draws[1].samples, 0u);
  EXPECT_TRUE(k.depth_compared);
  EXPECT_EQ(k.depth_pixels, kArea);
  EXPECT_EQ(k.depth_mismatches, 0u);
  // A GL count the model does not reproduce is a mismatch.
  Draw wrong = near;
  wrong.gl_samples = kArea - 1;
  AppsReplay again;
  EXPECT_TRUE(again.run_frame(frame_of({wrong}, {Clear{}})).draws[0].mismatch());
}

TEST(AppsReplayTest, EveryReasonFlagsItsDraw) {
  struct Case {
    Reason reason;
    void (*edit)(Draw&);
  };
  const std::vector<Case> cases = {
      {Reason::NotCaptured, [](Draw& d) { d.skipped = 1; }},
      {Reason::NotCaptured, [](Draw& d) { d.flags |= kOverflow; }},
      {Reason::Points, [](Draw& d) { d.primitive = 0; }},
      {Reason::Lines, [](Draw& d) { d.primitive = 1; }},
      {Reason::Discard, [](Draw& d) { d.flags |= kDiscards; }},
      {Reason::Discard, [](Draw& d) { d.flags |= kAlphaTest; }},
      {Reason::FragDepth, [](Draw& d) { d.flags |= kWritesDepth; }},
      {Reason::PolygonOffset, [](Draw& d) { d.flags |= kPolygonOffsetFill, d.units = 1.0f; }},
      {Reason::PolygonMode, [](Draw& d) { d.polygon_mode = 0x1B01; }},
      {Reason::Multisample, [](Draw& d) { d.flags |= kMultisample; }},
      {Reason::ClipDistance, [](Draw& d) { d.flags |= kClipDistance; }},
      {Reason::Viewport, [](Draw& d) { d.viewport[2] = kW / 2; }},
      {Reason::DepthRange, [](Draw& d) { d.far = 0.5f; }},
      {Reason::Scissor, [](Draw& d) { d.flags |= kScissor, d.scissor[1] = 2; }},
      {Reason::DepthFormat, [](Draw& d) { d.bits = 16, d.is_float = 0; }},
      {Reason::NonFinite, [](Draw& d) { d.z = std::numeric_limits<float>::quiet_NaN(); }},
      {Reason::NoTarget, [](Draw& d) { d.width = 0; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(to_string(c.reason)));
    Draw d;
    c.edit(d);
    AppsReplay replay;
    const AppDrawCounts k = replay.run_frame(frame_of({d}, {Clear{}})).draws.at(0);
    EXPECT_EQ(k.reason, c.reason);
    EXPECT_FALSE(k.mismatch()) << "a flagged draw is never compared";
    EXPECT_EQ(k.samples, 0u);
  }
  // What the model replays: an enabled offset of zero, a scissor covering the target, no depth buffer.
  for (void (*edit)(Draw&) : {+[](Draw& d) { d.flags |= kPolygonOffsetFill; }, +[](Draw& d) { d.flags |= kScissor, d.scissor = {-4, -4, 99, 99}; },
                              +[](Draw& d) { d.bits = 0, d.gl_samples = kArea; }, +[](Draw& d) { d.bits = 24, d.is_float = 0; }}) {
    Draw d;
    edit(d);
    AppsReplay replay;
    EXPECT_EQ(replay.run_frame(frame_of({d}, {Clear{}})).draws.at(0).reason, Reason::Replayed);
  }
}

TEST(AppsReplayTest, AFlaggedDrawsDepthChangeKeepsTheNextDrawsCompared) {
  Draw flagged;  // writes the left half at window depth 0.25, but its positions are not captured
  flagged.skipped = 1;
  Change change{0, {}, {}};
  for (std::uint32_t y = 0; y < kH; ++y)
    for (std::uint32_t x = 0; x < kW / 2; ++x) change.pixel.push_back(y * kW + x), change.depth.push_back(0.25f);
  Draw behind;  // at 0.5 everywhere: passes only in the right half
  behind.gl_samples = kArea / 2;
  AppsReplay replay;
  const AppFrameCounts k = replay.run_frame(frame_of({flagged, behind}, {Clear{}}, {change}));
  EXPECT_TRUE(k.draws[0].depth_change);
  EXPECT_FALSE(k.draws[1].stale);
  EXPECT_EQ(k.draws[1].samples, kArea / 2);
  EXPECT_FALSE(k.draws[1].mismatch());

  // Without the change the target is stale until a whole clear: the draw after is replayed apart.
  AppsReplay stale;
  const AppFrameCounts s = stale.run_frame(frame_of({flagged, behind, behind}, {Clear{}, Clear{2}}));
  EXPECT_FALSE(s.draws[0].depth_change);
  EXPECT_TRUE(s.draws[1].stale);
  EXPECT_FALSE(s.draws[1].mismatch()) << "a stale draw is not compared";
  EXPECT_FALSE(s.draws[2].stale) << "the clear before it covers the target";
  // A scissored clear does not make it known again.
  Clear part;
  part.before = 2, part.flags |= kScissor, part.scissor = {0, 0, kW / 2, kH};
  AppsReplay partial;
  EXPECT_TRUE(partial.run_frame(frame_of({flagged, behind, behind}, {Clear{}, part})).draws[2].stale);
  // A flagged draw that writes no depth leaves it known.
  Draw no_write = flagged;
  no_write.flags &= ~kDepthMask;
  AppsReplay kept;
  EXPECT_FALSE(kept.run_frame(frame_of({no_write, behind}, {Clear{}})).draws[1].stale);
  // The first draw into a target never cleared is stale: its depth was GL's before the frame.
  AppsReplay fresh;
  EXPECT_TRUE(fresh.run_frame(frame_of({behind}, {})).draws[0].stale);
}

TEST(AppsReplayTest, ADrawThatMayDiscardIsCheckedAgainstGlsDepthChange) {
  // A full-target rectangle at window depth 0.25 whose shader may discard: GL's recorded change says
  // it wrote every pixel (it discarded nothing), so it counts as replayed and equal; a change that
  // leaves out one pixel (GL discarded it) keeps it flagged, and GL's change stands.
  Draw maybe;
  maybe.flags |= kDiscards, maybe.z = -0.5f, maybe.gl_samples = kArea;
  Change all{0, {}, {}};
  for (std::uint32_t i = 0; i < kArea; ++i) all.pixel.push_back(i), all.depth.push_back(0.25f);
  Draw behind;  // at 0.5: hidden wherever the first drew
  behind.gl_samples = 0;
  AppsReplay replay;
  const AppFrameCounts k = replay.run_frame(frame_of({maybe, behind}, {Clear{}}, {all}));
  EXPECT_EQ(k.draws[0].reason, Reason::Replayed);
  EXPECT_TRUE(k.draws[0].may_discard);
  EXPECT_FALSE(k.draws[0].mismatch());
  EXPECT_EQ(k.draws[1].samples, 0u);
  Change holed = all;
  holed.pixel.erase(holed.pixel.begin() + 5), holed.depth.pop_back();
  Draw discarded = maybe;
  discarded.gl_samples = kArea - 1;
  behind.gl_samples = 1;  // the hole
  AppsReplay other;
  const AppFrameCounts h = other.run_frame(frame_of({discarded, behind}, {Clear{}}, {holed}));
  EXPECT_EQ(h.draws[0].reason, Reason::Discard);
  EXPECT_TRUE(h.draws[0].may_discard);
  EXPECT_TRUE(h.draws[0].depth_change);
  EXPECT_EQ(h.draws[1].samples, 1u) << "GL's change applied: the next draw passes in the hole only";
  EXPECT_FALSE(h.draws[1].mismatch());
  // Equal samples but another depth change: still flagged.
  discarded.gl_samples = kArea;
  AppsReplay third;
  EXPECT_EQ(third.run_frame(frame_of({discarded}, {Clear{}}, {holed})).draws[0].reason, Reason::Discard);
}

TEST(AppsReplayTest, ClearsKeepTheirScissorAndWriteMask) {
  Clear left;  // depth 0.25 in the left half only
  left.flags |= kScissor, left.scissor = {0, 0, kW / 2, kH}, left.depth = 0.25f;
  Draw at_half;  // window depth 0.5: hidden in the left half
  at_half.gl_samples = kArea / 2;
  AppsReplay replay;
  EXPECT_EQ(replay.run_frame(frame_of({at_half}, {Clear{}, left})).draws[0].samples, kArea / 2);
  Clear masked = left;  // depth writes off: the clear leaves depth alone
  masked.flags &= ~kDepthMask;
  AppsReplay unmasked;
  EXPECT_EQ(unmasked.run_frame(frame_of({at_half}, {Clear{}, masked})).draws[0].samples, kArea);
}

TEST(AppsReplayTest, TheWindowFramebufferIsDrawnUpsideDown) {
  // A draw covering the bottom half of the window (clip y < 0), its depth compared with GL's read-back
  // image (bottom row first): the model keeps the window's rows flipped and compares them right.
  Draw bottom;
  bottom.fb = 0, bottom.bits = 24, bottom.is_float = 0, bottom.rect = {-1.0f, -1.0f, 1.0f, 0.0f}, bottom.z = -0.5f;
  bottom.gl_samples = kArea / 2;
  Clear clear;
  clear.fb = 0;
  std::vector<float> gl(kArea, 1.0f);
  for (std::size_t i = 0; i < kArea / 2; ++i) gl[i] = raster::stored_depth(raster::DepthFormat::Unorm24, 0.25f);
  AppsReplay replay;
  const AppFrameCounts k = replay.run_frame(frame_of({bottom}, {clear}, {}, 0, &gl));
  EXPECT_EQ(k.draws[0].samples, kArea / 2);
  ASSERT_TRUE(k.depth_compared);
  EXPECT_EQ(k.depth_mismatches, 0u);
  // The same image upside down is all wrong.
  std::vector<float> flipped(gl.rbegin(), gl.rend());
  AppsReplay other;
  EXPECT_EQ(other.run_frame(frame_of({bottom}, {clear}, {}, 0, &flipped)).depth_mismatches, kArea);
}

// A tester that keeps its own copy of the target, made only from what the core tells it (rebuild,
// clears, changes), answers at full resolution from that copy, and checks at every query that the
// copy is the target: every change reached it.
class MirrorTester : public DrawTester {
 public:
  void rebuild(const DepthImage& depth) override { mirror = depth, ++rebuilds; }
  void cleared(const DepthImage&, float value) override { std::fill(mirror.texels.begin(), mirror.texels.end(), value); }
  void changed(const DepthImage& depth, const Rect& dirty) override {
    ASSERT_GE(dirty.x, 0);
    ASSERT_LE(dirty.x1(), depth.width);
    for (int y = dirty.y; y < dirty.y1(); ++y)
      for (int x = dirty.x; x < dirty.x1(); ++x) mirror.at(x, y) = depth.at(x, y);
  }
  void prepare(const DepthImage&) override { ++prepares; }
  void query(const DepthImage& depth, std::span<const Rect> rects, std::span<const float> nearest,
             std::vector<query::Answer>& answers) override {
    EXPECT_EQ(std::memcmp(mirror.texels.data(), depth.texels.data(), depth.texels.size() * sizeof(float)), 0)
        << "a change of the target did not reach the tester";
    answers.clear();
    for (std::size_t i = 0; i < rects.size(); ++i) answers.push_back(full_depth_query(mirror, rects[i], nearest[i], FarOp::Max));
    queries += rects.size();
  }
  DepthImage mirror;
  int rebuilds = 0, prepares = 0;
  std::size_t queries = 0;
};

CullSettings settings(DrawTester& t, bool primitives = false) {
  CullSettings s;
  s.tester = &t;
  s.width = kW, s.height = kH;
  s.primitives = primitives;
  return s;
}

TEST(AppsCullTest, AHiddenDrawIsCulledAndAVisibleOneDrawn) {
  MirrorTester tester;
  AppsReplay replay;
  replay.set_culling(settings(tester));
  Draw near, far, half;
  near.z = -0.5f, near.gl_samples = kArea;
  far.z = 0.5f;  // behind `near` everywhere: GL passed none
  half.z = -0.75f, half.rect = {-1.0f, -1.0f, 0.0f, 1.0f}, half.gl_samples = kArea / 2;  // nearer, on the left half
  std::vector<float> final_depth(kArea, 0.25f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW / 2; ++x) final_depth[static_cast<std::size_t>(y * kW + x)] = 0.125f;
  const AppFrameCounts k = replay.run_frame(frame_of({near, far, half}, {Clear{}}, {}, 7, &final_depth));
  ASSERT_EQ(k.draws.size(), 3u);
  EXPECT_EQ(k.draws[0].untested, Untested::Tested);
  EXPECT_FALSE(k.draws[0].culled) << "nothing in front of it yet";
  EXPECT_TRUE(k.draws[1].culled);
  EXPECT_FALSE(k.draws[1].false_cull());
  EXPECT_EQ(k.draws[1].samples, 0u);
  EXPECT_FALSE(k.draws[2].culled);
  EXPECT_EQ(k.draws[2].samples, kArea / 2);
  EXPECT_FALSE(k.draws[2].mismatch());
  EXPECT_EQ(k.draws[1].query_lookups, kArea) << "the full-resolution test reads the rectangle's pixels";
  EXPECT_EQ(tester.queries, 3u);
  EXPECT_EQ(tester.rebuilds, 1);
  EXPECT_EQ(k.depth_mismatches, 0u);
  // A culled draw GL drew samples of is a false cull.
  Draw wrong = far;
  wrong.gl_samples = 1;
  AppsReplay again;
  MirrorTester t2;
  again.set_culling(settings(t2));
  EXPECT_TRUE(again.run_frame(frame_of({near, wrong}, {Clear{}})).draws[1].false_cull());
}

TEST(AppsCullTest, DrawsThatCannotBeCulledSafelyAreNotTested) {
  MirrorTester tester;
  AppsReplay replay;
  replay.set_culling(settings(tester));
  Draw near, other_target, no_test, always, stencil, offscreen, flagged, after;
  near.z = -0.5f, near.gl_samples = kArea;
  other_target.fb = 9, other_target.z = 0.5f;
  no_test.z = 0.5f, no_test.flags = kDepthMask | kFrontCcw;
  stencil.z = 0.5f, stencil.flags |= kStencilTest;
  flagged.z = 0.5f, flagged.primitive = 1;  // lines
  offscreen.z = 0.5f, offscreen.rect = {2.0f, 2.0f, 3.0f, 3.0f};
  after.z = 0.5f;  // after the flagged draw, which may have written depth GL did not record: stale
  scene::Frame f = frame_of({near, other_target, no_test, always, stencil, offscreen, flagged, after}, {Clear{}});
  f.draws[3].state.func = scene::DepthFunc::Always;
  f.draws[3].clip_positions[0][2] = 0.5f;
  f.draws[4].stencil.test = true;
  f.draws[4].stencil.front.write_mask = 0xFF;
  const AppFrameCounts k = replay.run_frame(f);
  ASSERT_EQ(k.draws.size(), 8u);
  EXPECT_EQ(k.draws[1].untested, Untested::OtherTarget);
  EXPECT_EQ(k.draws[2].untested, Untested::DepthFunc);
  EXPECT_EQ(k.draws[3].untested, Untested::DepthFunc);
  EXPECT_EQ(k.draws[4].untested, Untested::StencilWrites);
  EXPECT_EQ(k.draws[5].untested, Untested::NoTriangles);
  EXPECT_EQ(k.draws[6].untested, Untested::Flagged);
  EXPECT_EQ(k.draws[7].untested, Untested::Stale);
  for (std::size_t i = 1; i < k.draws.size(); ++i) EXPECT_FALSE(k.draws[i].culled) << i;
}

TEST(AppsCullTest, PerPrimitiveCullingSkipsTheHiddenTriangleOfAVisibleDraw) {
  MirrorTester tester;
  AppsReplay replay;
  replay.set_culling(settings(tester, true));
  Draw left, both;
  left.z = -0.5f, left.rect = {-1.0f, -1.0f, 0.0f, 1.0f}, left.gl_samples = kArea / 2;
  both.z = 0.0f;
  scene::Frame f = frame_of({left, both}, {Clear{}});
  // The second draw: one triangle behind the left half's depth, one on the right (nothing in front).
  f.draws[1].clip_positions = {{-1.0f, -1.0f, 0.0f, 1.0f}, {-0.25f, -1.0f, 0.0f, 1.0f}, {-1.0f, 1.0f, 0.0f, 1.0f},
                               {0.25f, -1.0f, 0.0f, 1.0f}, {1.0f, -1.0f, 0.0f, 1.0f}, {1.0f, 1.0f, 0.0f, 1.0f}};
  // GL's samples: the right triangle's, which the model counts when it draws it alone.
  AppsReplay plain;
  const AppFrameCounts truth = plain.run_frame(f);
  f.draws[1].gl.samples_passed = truth.draws[1].samples;
  const AppFrameCounts k = replay.run_frame(f);
  EXPECT_FALSE(k.draws[1].culled);
  EXPECT_EQ(k.draws[1].primitive_tests, 2u);
  EXPECT_EQ(k.draws[1].primitives_culled, 1u);
  EXPECT_GT(k.draws[1].samples, 0u);
  EXPECT_FALSE(k.draws[1].mismatch());
  EXPECT_LT(k.draws[1].fragments, truth.draws[1].fragments) << "the hidden triangle's fragments are not rasterized";
}

TEST(AppsCullTest, RandomFramesCullOnlyHiddenDrawsAndKeepTheDepth) {
  // Quads of random size and depth, some behind others; GL's samples are the model's without
  // culling (its own replay is exact against GL on such draws). Culling must never remove a draw
  // with samples and must leave the final depth as it was.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::size_t culled = 0;
  for (int round = 0; round < 40; ++round) {
    std::vector<Draw> draws(12);
    for (Draw& d : draws) {
      float a = u(rng), b = u(rng), c = u(rng), e = u(rng);
      d.rect = {std::min(a, b), std::min(c, e), std::max(a, b) + 0.1f, std::max(c, e) + 0.1f};
      d.z = u(rng);
    }
    scene::Frame f = frame_of(draws, {Clear{}});
    AppsReplay plain;
    const AppFrameCounts truth = plain.run_frame(f);
    for (std::size_t k = 0; k < draws.size(); ++k) f.draws[k].gl.samples_passed = truth.draws[k].samples;
    MirrorTester tester;
    AppsReplay culling;
    culling.set_culling(settings(tester, round % 2 == 1));
    const AppFrameCounts k = culling.run_frame(f);
    for (const AppDrawCounts& d : k.draws) {
      EXPECT_FALSE(d.false_cull()) << "round " << round << " draw " << d.draw;
      EXPECT_FALSE(d.mismatch()) << "round " << round << " draw " << d.draw;
      culled += d.culled ? 1 : 0;
    }
    ASSERT_TRUE(plain.depth_of(7) && culling.depth_of(7));
    EXPECT_EQ(plain.depth_of(7)->texels, culling.depth_of(7)->texels) << "round " << round;
  }
  EXPECT_GT(culled, 20u) << "the frames hide draws behind others";
}

TEST(AppsReplayTest, DamagedRecordsAreRefusedByName) {
  Draw d;
  scene::Frame f = frame_of({d}, {Clear{}});
  f.draws.push_back(f.draws[0]);  // two DRAW records, one AppDraws entry
  AppsReplay replay;
  try {
    replay.run_frame(f);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("AppDraws (APDS) record counts 1 draws, the frame has 2"), std::string::npos) << e.what();
  }
  scene::Frame no_clears = frame_of({d}, {});
  no_clears.technique_records.erase(no_clears.technique_records.begin() + 1);
  EXPECT_THROW(replay.run_frame(no_clears), InputError);
  Change outside{5, {0}, {0.5f}};
  EXPECT_THROW(replay.run_frame(frame_of({d}, {Clear{}}, {outside})), InputError);
  Draw flagged;
  flagged.skipped = 1;
  Change beyond{0, {static_cast<std::uint32_t>(kArea)}, {0.5f}};
  EXPECT_THROW(replay.run_frame(frame_of({flagged}, {Clear{}}, {beyond})), InputError);
}

}  // namespace
}  // namespace nbsim::apps
