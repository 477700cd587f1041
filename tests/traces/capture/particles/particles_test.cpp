// ParticlesTest: the particles technique (traces/capture/particles/) run headless on a small city
// in every culling mode, checked on GL's own records: the PRTC record is whole, GL's passed samples
// are the reference samples of the particles it drew, the N-buffer and Hi-Z modes never pop (no
// culled particle has reference samples), the centre test's culls are recorded, the partial
// N-buffer equals the core's, and the same capture twice gives the same records.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <variant>

#include "model/common/error.h"
#include "model/nbuffer/nbuffer.h"
#include "traces/capture/capture.h"
#include "traces/capture/particles/particle_systems.h"
#include "traces/capture/scenes.h"
#include "traces/format/particles/particles_chunk.h"
#include "traces/format/reader.h"
#include "traces/format/technique_chunks.h"
#include "tests/common/scratch.h"
#include "model/particles/roles.h"

namespace nbsim::capture {
namespace {

namespace fs = std::filesystem;

// A small capture: 128x96, 500 particles, 2 frames along the walk, a city of 600 objects.
CaptureOptions small(const std::string& mode, const std::string& sprite = "16") {
  CaptureOptions o;
  o.technique = "particles";
  o.width = 128;
  o.height = 96;
  o.frames = 2;
  o.options = {{"objects", "600"}, {"seed", "3"}, {"mode", mode}, {"sprite", sprite}, {"particles", "500"}, {"levels-every", "1"}};
  return o;
}

fs::path scratch(const std::string& name) {
  return nbsim::testing::scratch_path("nbsim_particles", name + ".nbt");
}

// The PRTC record's fields by name.
struct Particles {
  std::uint64_t count = 0;
  std::vector<std::uint32_t> draw, culled, lookups, samples;
  std::vector<float> x, y, depth, size;
};

Particles particles_of(const scene::Frame& f) {
  Particles p;
  int records = 0;
  for (const auto& r : f.technique_records) {
    if (r.type != trace::kParticlesChunk) continue;
    ++records;
    EXPECT_TRUE(r.decoded) << "the format library registers PRTC";
    for (const auto& field : r.fields) {
      if (field.name == "count") p.count = std::get<std::uint64_t>(field.value);
      if (field.name == "draw") p.draw = std::get<std::vector<std::uint32_t>>(field.value);
      if (field.name == "culled") p.culled = std::get<std::vector<std::uint32_t>>(field.value);
      if (field.name == "lookups") p.lookups = std::get<std::vector<std::uint32_t>>(field.value);
      if (field.name == "reference_samples") p.samples = std::get<std::vector<std::uint32_t>>(field.value);
      if (field.name == "x") p.x = std::get<std::vector<float>>(field.value);
      if (field.name == "y") p.y = std::get<std::vector<float>>(field.value);
      if (field.name == "depth") p.depth = std::get<std::vector<float>>(field.value);
      if (field.name == "size") p.size = std::get<std::vector<float>>(field.value);
    }
  }
  EXPECT_EQ(records, 1) << "one PRTC record a frame";
  return p;
}

struct Totals {
  std::uint64_t culled = 0, popping = 0, visible = 0, tested = 0, frames = 0;
};

// Reads a particles trace and checks what every mode must satisfy; returns the totals.
Totals check_trace(const fs::path& file, const std::string& mode, std::uint32_t particles) {
  Totals t;
  trace::FrameReader frames(file);
  EXPECT_EQ(*frames.trace().property("technique"), "particles");
  EXPECT_EQ(*frames.trace().property("particle_mode"), mode);
  while (auto f = frames.next()) {
    ++t.frames;
    const Particles p = particles_of(*f);
    EXPECT_EQ(p.count, particles);
    for (const auto* v : {&p.draw, &p.culled, &p.lookups, &p.samples}) EXPECT_EQ(v->size(), particles) << "a value a particle";
    for (const auto* v : {&p.x, &p.y, &p.depth, &p.size}) EXPECT_EQ(v->size(), particles) << "a value a particle";
    if (p.culled.size() != particles || p.samples.size() != particles || p.draw.size() != particles) return t;
    EXPECT_NE(f->depth("scene"), nullptr) << "the scene depth is recorded";
    // GL's passed samples of each particle draw are the reference samples of the particles it kept.
    std::vector<std::uint64_t> kept_samples(f->draws.size(), 0);
    std::uint64_t points = 0;
    for (std::uint32_t i = 0; i < particles; ++i) {
      t.culled += p.culled[i];
      t.visible += p.samples[i] > 0;
      t.popping += p.culled[i] && p.samples[i] > 0;
      t.tested += p.lookups[i] > 0;
      EXPECT_LE(p.lookups[i], mode == "none" ? 0u : mode == "center" ? 1u : 4u) << "particle " << i;
      if (!p.culled[i] && p.draw[i] < kept_samples.size()) kept_samples[p.draw[i]] += p.samples[i];
    }
    for (const auto& d : f->draws) {
      EXPECT_LE(d.gl.samples_passed, d.gl.fragments) << "draw " << d.index;
      if (d.role != nbsim::particles::kParticlesRole) continue;
      EXPECT_EQ(d.topology, trace::Topology::Points);
      EXPECT_EQ(d.clip_positions.size(), d.point_sizes.size()) << "gl_Position and gl_PointSize a vertex";
      EXPECT_EQ(d.gl.clip_prims_in, d.clip_positions.size()) << "one point a vertex";
      EXPECT_FALSE(d.state.write) << "particles do not write depth";
      EXPECT_EQ(d.gl.samples_passed, kept_samples[d.index]) << "draw " << d.index << ": GL's samples = kept particles' reference";
      points += d.clip_positions.size();
    }
    EXPECT_EQ(points, particles) << "every particle in one draw";
  }
  EXPECT_EQ(t.frames, 2u);
  return t;
}

// Every mode writes a whole trace: the PRTC record, point draws with their sizes, GL's samples equal
// to the reference samples of the particles kept; nb and hiz never pop; centre culls and pops
// are recorded; none culls nothing.
TEST(ParticlesTest, EveryModeCapturesAConsistentTrace) {
  for (const std::string& mode : std::vector<std::string>{"none", "center", "nb", "hiz"}) {
    SCOPED_TRACE(mode);
    const fs::path file = scratch(mode);
    const CaptureSummary sum = capture(small(mode), file.string());
    EXPECT_EQ(sum.frames, 2);
    const Totals t = check_trace(file, mode, 500);
    EXPECT_GT(t.visible, 0u) << "some particles are seen";
    EXPECT_LT(t.visible, 2u * 500u) << "some particles are hidden";
    if (mode == "none") {
      EXPECT_EQ(t.culled, 0u);
    } else {
      EXPECT_GT(t.culled, 0u) << "the test culls hidden particles";
    }
    if (mode == "nb" || mode == "hiz") {
      EXPECT_EQ(t.popping, 0u) << mode << " is conservative: no culled particle is visible";
    }
    fs::remove(file);
  }
}

// Distance-attenuated sizes (1 to 64 px) and 24 px sprites (four lookups) keep nb and hiz
// conservative, in both depth conventions (a min N-buffer under reversed Z).
TEST(ParticlesTest, NoPoppingWithAnySizeOrConvention) {
  for (const std::string& sprite : std::vector<std::string>{"24", "atten"})
    for (const std::string& mode : std::vector<std::string>{"nb", "hiz"})
      for (bool reversed : {false, true}) {
        SCOPED_TRACE(mode + " " + sprite + (reversed ? " reversed" : ""));
        CaptureOptions o = small(mode, sprite);
        o.reversed_z = reversed;
        const fs::path file = scratch(mode + sprite);
        capture(o, file.string());
        const Totals t = check_trace(file, mode, 500);
        EXPECT_GT(t.culled, 0u);
        EXPECT_EQ(t.popping, 0u);
        fs::remove(file);
      }
}

// Every cull is justified by the recorded scene depth alone (a brute force over the sprite's pixels,
// independent of the reference pass): nb and hiz cull a sprite only when every pixel it covers
// (the pixel centres inside its square, widened by one near a tie, clipped to the viewport) holds
// a depth nearer than the sprite's; center only when its centre pixel does.
TEST(ParticlesTest, CullsAreJustifiedByTheDepthImage) {
  for (const std::string& mode : std::vector<std::string>{"center", "nb", "hiz"})
    for (bool reversed : {false, true}) {
      SCOPED_TRACE(mode + (reversed ? " reversed" : ""));
      CaptureOptions o = small(mode, "atten");
      o.reversed_z = reversed;
      const fs::path file = scratch("brute_" + mode);
      capture(o, file.string());
      trace::FrameReader frames(file);
      std::uint64_t culled = 0;
      while (auto f = frames.next()) {
        const trace::DepthSnapshot* d = f->depth("scene");
        ASSERT_NE(d, nullptr);
        const Particles p = particles_of(*f);
        auto hidden_behind = [&](float depth, float stored) { return reversed ? depth < stored : depth > stored; };
        for (std::size_t i = 0; i < p.culled.size(); ++i) {
          if (!p.culled[i]) continue;
          ++culled;
          if (mode == "center") {
            const int cx = static_cast<int>(std::floor(p.x[i])), cy = static_cast<int>(std::floor(p.y[i]));
            ASSERT_TRUE(cx >= 0 && cy >= 0 && cx < d->width && cy < d->height) << "particle " << i;
            EXPECT_TRUE(hidden_behind(p.depth[i], d->texels[static_cast<std::size_t>(cy * d->width + cx)])) << "particle " << i;
            continue;
          }
          int lo[2], hi[2];
          const float centre[2] = {p.x[i], p.y[i]};
          for (int k = 0; k < 2; ++k) {
            const float a = centre[k] - 0.5f - 0.5f * p.size[i];
            const bool tie = std::fabs(a - std::round(a)) < 1.0f / 64.0f;
            lo[k] = static_cast<int>(tie ? std::round(a) : std::ceil(a));
            hi[k] = lo[k] + static_cast<int>(p.size[i]) + (tie ? 1 : 0);
          }
          for (int y = std::max(lo[1], 0); y < std::min(hi[1], d->height); ++y)
            for (int x = std::max(lo[0], 0); x < std::min(hi[0], d->width); ++x)
              ASSERT_TRUE(hidden_behind(p.depth[i], d->texels[static_cast<std::size_t>(y * d->width + x)]))
                  << "particle " << i << " culled but pixel (" << x << ", " << y << ") holds " << d->texels[static_cast<std::size_t>(y * d->width + x)]
                  << ", the sprite is at " << p.depth[i];
        }
      }
      EXPECT_GT(culled, 0u);
      fs::remove(file);
    }
}

// The centre test is the baseline that pops: its culls and its lookups (one a tested particle) are
// recorded, on the walk's many silhouettes with big sprites.
TEST(ParticlesTest, CenterCullsAreRecorded) {
  CaptureOptions o = small("center", "24");
  o.options.set("particles", "4000");
  const fs::path file = scratch("center_24");
  capture(o, file.string());
  const Totals t = check_trace(file, "center", 4000);
  EXPECT_GT(t.culled, 0u);
  EXPECT_GE(t.tested, t.culled) << "a culled particle was looked up (once: check_trace)";
  EXPECT_GT(t.popping, 0u) << "a centre hidden behind an edge while a corner shows pops";
  fs::remove(file);
}

// The hard case of the paper: a centre hidden behind a building edge while a corner of the sprite
// shows. The same frames (same seed, same particles, same scene depth: particles write no depth)
// in center, nb and hiz: every particle the centre test pops is kept by nb and hiz.
TEST(ParticlesTest, SilhouettesPopWithTheCentreOnly) {
  auto frames_of = [](const std::string& mode) {
    CaptureOptions o = small(mode, "24");
    o.options.set("particles", "4000");
    const fs::path file = scratch("silhouette_" + mode);
    capture(o, file.string());
    std::vector<Particles> out;
    trace::FrameReader frames(file);
    while (auto f = frames.next()) out.push_back(particles_of(*f));
    fs::remove(file);
    return out;
  };
  const auto centre = frames_of("center"), nb = frames_of("nb"), hiz = frames_of("hiz");
  ASSERT_EQ(centre.size(), 2u);
  ASSERT_EQ(nb.size(), 2u);
  ASSERT_EQ(hiz.size(), 2u);
  std::uint64_t popped = 0;
  for (std::size_t f = 0; f < centre.size(); ++f) {
    ASSERT_EQ(centre[f].samples, nb[f].samples) << "the same particles see the same depth in every mode";
    for (std::size_t i = 0; i < centre[f].culled.size(); ++i)
      if (centre[f].culled[i] && centre[f].samples[i] > 0) {
        ++popped;
        EXPECT_EQ(nb[f].culled[i], 0u) << "frame " << f << " particle " << i << ": popped by center, culled by nb";
        EXPECT_EQ(hiz[f].culled[i], 0u) << "frame " << f << " particle " << i << ": popped by center, culled by hiz";
      }
  }
  EXPECT_GT(popped, 0u) << "the centre test pops on this walk";
}

// A power-of-two sprite is one lookup at its lower-left pixel unless it sits on a pixel-centre tie
// or the screen border; 24 px sprites take four (the paper's four quadrants). Three lookups come
// only from sprites the screen border clips into a row or a column of the paper's covering.
TEST(ParticlesTest, LookupsFollowTheCovering) {
  for (const std::string& sprite : std::vector<std::string>{"16", "24"}) {
    const fs::path file = scratch("lookups" + sprite);
    capture(small("nb", sprite), file.string());
    trace::FrameReader frames(file);
    std::uint64_t counts[5] = {};
    while (auto f = frames.next()) {
      const Particles p = particles_of(*f);
      for (auto l : p.lookups) ++counts[std::min<std::uint32_t>(l, 4)];
    }
    if (sprite == "16") {
      EXPECT_GT(counts[1], counts[2] + counts[4]) << "mostly one lookup";
    } else {
      EXPECT_GT(counts[4], counts[1] + counts[2]) << "mostly four lookups";
    }
    EXPECT_LT(counts[3] * 10, counts[1] + counts[2] + counts[4]) << "three only at the screen border";
    fs::remove(file);
  }
}

// The partial build: levels 0 .. the level the largest sprite needs, capped by --level-cap, equal
// to the core's N-buffer with that max_level; sprites that need a higher level are never culled.
TEST(ParticlesTest, PartialLevelsEqualTheCoreAndBigSpritesAreKept) {
  CaptureOptions o = small("nb", "atten");
  o.options.set("level-cap", "3");
  const fs::path file = scratch("cap3");
  capture(o, file.string());
  trace::FrameReader frames(file);
  EXPECT_EQ(*frames.trace().property("levels_built"), "4");
  int checked = 0;
  while (auto f = frames.next()) {
    const trace::DepthSnapshot* d = f->depth("scene");
    const trace::NBufferLevels* l = f->nbuffer("scene", FarOp::Max);
    ASSERT_NE(d, nullptr);
    ASSERT_NE(l, nullptr);
    ASSERT_EQ(l->levels, 4);
    DepthImage img(d->width, d->height, 0.0f);
    img.texels = d->texels;
    const NBuffer core(img, {FarOp::Max, StorageFormat::F32, 3});
    EXPECT_EQ(std::memcmp(l->texels.data(), core.level(0).data(), l->texels.size() * 4), 0) << "GLSL levels differ from the core's";
    const Particles p = particles_of(*f);
    for (std::size_t i = 0; i < p.size.size(); ++i)
      if (p.size[i] >= 16.0f) {  // 16 px and more need level 4
        EXPECT_EQ(p.culled[i], 0u) << "particle " << i << " of " << p.size[i] << " px";
        EXPECT_EQ(p.lookups[i], 0u) << "particle " << i << " of " << p.size[i] << " px is not tested";
        ++checked;
      }
  }
  EXPECT_GT(checked, 0) << "some sprites are larger than the levels built";
  fs::remove(file);
}

// The same capture twice gives the same records (GL's host time aside).
TEST(ParticlesTest, Reproducible) {
  const fs::path a = scratch("a"), b = scratch("b");
  capture(small("nb", "atten"), a.string());
  capture(small("nb", "atten"), b.string());
  trace::FrameReader ra(a), rb(b);
  while (true) {
    auto fa = ra.next();
    auto fb = rb.next();
    ASSERT_EQ(fa.has_value(), fb.has_value());
    if (!fa) break;
    ASSERT_EQ(fa->draws.size(), fb->draws.size());
    for (std::size_t i = 0; i < fa->draws.size(); ++i) {
      EXPECT_EQ(fa->draws[i].clip_positions, fb->draws[i].clip_positions);
      EXPECT_EQ(fa->draws[i].point_sizes, fb->draws[i].point_sizes);
      EXPECT_EQ(fa->draws[i].gl.fragments, fb->draws[i].gl.fragments);
      EXPECT_EQ(fa->draws[i].gl.samples_passed, fb->draws[i].gl.samples_passed);
    }
    ASSERT_EQ(fa->technique_records.size(), fb->technique_records.size());
    for (std::size_t i = 0; i < fa->technique_records.size(); ++i)
      EXPECT_EQ(trace::encode(fa->technique_records[i]), trace::encode(fb->technique_records[i]));
    ASSERT_EQ(fa->depths.size(), fb->depths.size());
    for (std::size_t i = 0; i < fa->depths.size(); ++i) EXPECT_EQ(fa->depths[i].texels, fb->depths[i].texels);
  }
  fs::remove(a);
  fs::remove(b);
}

// Emitters are placed inside the site; one given outside it is refused naming it.
TEST(ParticlesTest, EmittersInsideTheScene) {
  PathSite site;
  site.extent_m = 500.0;
  site.street_pitch_m = 50.0;
  site.blocks_per_side = 10;
  for (const Emitter& e : place_emitters(site, 12, 1000, 7)) EXPECT_TRUE(inside_site(site, e.position.x, e.position.z));
  const auto em = emitters_at(site, {{10.0, 20.0}, {499.0, 0.0}}, 7);
  ASSERT_EQ(em.size(), 2u);
  EXPECT_EQ(em[0].count + em[1].count, 7u);
  try {
    emitters_at(site, {{10.0, 20.0}, {600.0, 5.0}}, 7);
    ADD_FAILURE() << "an emitter outside the site was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("emitter 2 at x 600 m, z 5 m is outside the scene"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim::capture
