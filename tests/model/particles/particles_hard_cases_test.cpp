// ParticlesHardCasesTest: the hard cases of particle culling, each built by hand on a small depth
// buffer and decided twice: by GL (the capture's own vertex shader, shaders/particles/particles.vert,
// run on Mesa's llvmpipe with the same defines as the capture, against levels built by the model's
// N-buffer core, which ParticlesTest.PartialLevelsEqualTheCoreAndBigSpritesAreKept shows equal to
// the capture's GLSL levels) and by the model's cores (model/particles/sprite.h). For each case:
// GL's decision and lookups equal the model's, what GL draws (mode none: its covered pixels and
// GL_SAMPLES_PASSED) is the model's drawn_rect and exact sprite test, and nb never culls a sprite
// GL draws a passing sample of.
//
// Already covered elsewhere, not repeated here: GL's coverage of ties, partly off-screen squares,
// centres outside the frustum, equal depth under LESS/LEQUAL, sizes beyond 255 and reversed Z per
// pixel (PointGlCompareTest); the shader's rectangle and the margin (ParticlesCoreTest); popping
// of center and none in nb/hiz on a whole walk, both conventions (ParticlesTest).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "model/common/depth.h"
#include "model/hiz/pyramid.h"
#include "model/nbuffer/nbuffer.h"
#include "model/particles/sprite.h"
#include "nbsim_shaders.h"
#include "traces/capture/gl_program.h"
#include "traces/gl/context.h"

namespace nbsim::particles {
namespace {

// The particles' covering: the paper's, a power-of-two sprite in one lookup (the capture's default).
constexpr CoveringSpec kSpriteCovering{CoveringKind::Paper, CoveringAlign::Top, true};

// Powers of two: window <-> clip conversions are exact, so GL's window position is the one given.
constexpr int kW = 64, kH = 32;
constexpr float kMargin = 1e-6f;  // the capture's cull_margin (traces/capture/particles/particles.cpp)

// Mode none draws with this fragment shader: rasterized fragments per pixel (no early tests).
constexpr const char* kCountFragments = R"(#version 450
layout(r32ui, binding = 0) uniform coherent uimage2D counts;
void main() { imageAtomicAdd(counts, ivec2(gl_FragCoord.xy), 1u); }
)";

struct Sprite {
  float x = 0, y = 0, depth = 0.5f, size = 16;  // window position, window depth, gl_PointSize
};

// What GL decided and drew for one sprite.
struct GlOutcome {
  Particle window;  // the shader's window position, depth and size (its Decision record)
  bool culled = false;
  std::uint32_t lookups = 0;
  Rect covered;     // bounding box of the pixels GL rasterized (mode none)
  std::uint64_t covered_pixels = 0, samples_passed = 0;
};

class GlParticles {
 public:
  GlParticles() {
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_);
    glTextureStorage2D(depth_, 1, GL_DEPTH_COMPONENT32F, kW, kH);
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_copy_);
    glTextureStorage2D(depth_copy_, 1, GL_R32F, kW, kH);
    glCreateTextures(GL_TEXTURE_2D, 1, &counts_);
    glTextureStorage2D(counts_, 1, GL_R32UI, kW, kH);
    for (GLuint t : {depth_copy_}) {
      glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glCreateFramebuffers(1, &fbo_);
    glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
    glNamedFramebufferDrawBuffer(fbo_, GL_NONE);
    glNamedFramebufferReadBuffer(fbo_, GL_NONE);
    glCreateVertexArrays(1, &vao_);
    glCreateBuffers(1, &vbo_);
    glNamedBufferStorage(vbo_, 16, nullptr, GL_DYNAMIC_STORAGE_BIT);
    glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, 16);
    glEnableVertexArrayAttrib(vao_, 0);
    glVertexArrayAttribFormat(vao_, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao_, 0, 0);
    glCreateBuffers(1, &decisions_);
    glNamedBufferStorage(decisions_, 32, nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
    glGenQueries(1, &q_samples_);
  }
  ~GlParticles() {
    for (auto& [key, prog] : programs_) glDeleteProgram(prog);
    const GLuint tex[] = {depth_, depth_copy_, counts_, levels_};
    glDeleteTextures(levels_ ? 4 : 3, tex);
    glDeleteFramebuffers(1, &fbo_);
    glDeleteBuffers(1, &vbo_);
    glDeleteBuffers(1, &decisions_);
    glDeleteVertexArrays(1, &vao_);
    glDeleteQueries(1, &q_samples_);
  }

  // One sprite in `mode` on the scene depth `scene`, the N-buffer levels 0..top_level of `nb`.
  GlOutcome run(const Sprite& s, Mode mode, const DepthImage& scene, const NBuffer& nb, bool reversed) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, kW, kH);
    glDepthRange(0.0, 1.0);
    glClipControl(GL_LOWER_LEFT, reversed ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    glTextureSubImage2D(depth_, 0, 0, 0, kW, kH, GL_DEPTH_COMPONENT, GL_FLOAT, scene.texels.data());
    glTextureSubImage2D(depth_copy_, 0, 0, 0, kW, kH, GL_RED, GL_FLOAT, scene.texels.data());
    upload_levels(nb);
    const GLuint zero = 0;
    glClearTexImage(counts_, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    const float z = reversed ? s.depth : 2.0f * s.depth - 1.0f;
    const float clip[4] = {(s.x - kW / 2) / (kW / 2), (s.y - kH / 2) / (kH / 2), z, 1.0f};
    glNamedBufferSubData(vbo_, 0, sizeof clip, clip);
    const float poison[8] = {-1, -1, -1, -1, 0, 0, 0, 0};
    glNamedBufferSubData(decisions_, 0, sizeof poison, poison);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);

    const GLuint prog = program(mode, reversed);
    glUseProgram(prog);
    const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    glUniformMatrix4fv(glGetUniformLocation(prog, "view_proj"), 1, GL_FALSE, identity);
    glUniform2i(glGetUniformLocation(prog, "viewport"), kW, kH);
    glUniform1f(glGetUniformLocation(prog, "fixed_size"), s.size);
    glUniform1f(glGetUniformLocation(prog, "margin"), kMargin);
    glUniform1i(glGetUniformLocation(prog, "top_level"), nb.top_level());
    glUniform1i(glGetUniformLocation(prog, "depth"), 2);
    glUniform1i(glGetUniformLocation(prog, "levels"), 3);
    glBindTextureUnit(2, depth_copy_);
    glBindTextureUnit(3, levels_);
    glBindImageTexture(0, counts_, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, decisions_);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(reversed ? GL_GREATER : GL_LESS);
    glDepthMask(GL_FALSE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glBindVertexArray(vao_);
    glBeginQuery(GL_SAMPLES_PASSED, q_samples_);
    glDrawArrays(GL_POINTS, 0, 1);
    glEndQuery(GL_SAMPLES_PASSED);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);

    GlOutcome o;
    struct {
      float win[4];
      std::uint32_t culled, lookups, pad0, pad1;
    } d{};
    glGetNamedBufferSubData(decisions_, 0, sizeof d, &d);
    o.window = {d.win[0], d.win[1], d.win[2], d.win[3]};
    o.culled = d.culled != 0;
    o.lookups = d.lookups;
    GLuint64 passed = ~GLuint64{0};
    glGetQueryObjectui64v(q_samples_, GL_QUERY_RESULT, &passed);
    o.samples_passed = passed;
    std::vector<std::uint32_t> counts(static_cast<std::size_t>(kW * kH));
    glGetTextureImage(counts_, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(counts.size() * 4), counts.data());
    int x0 = kW, y0 = kH, x1 = 0, y1 = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        if (counts[static_cast<std::size_t>(y * kW + x)]) {
          ++o.covered_pixels;
          x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x + 1), y1 = std::max(y1, y + 1);
        }
    if (o.covered_pixels) o.covered = Rect{x0, y0, x1 - x0, y1 - y0};
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR)) << "GL reported an error";
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    return o;
  }

 private:
  // The capture's program for a mode (its defines, traces/capture/particles/particles.cpp), with
  // the fragment-counting shader.
  GLuint program(Mode mode, bool reversed) {
    const auto key = std::pair{mode, reversed};
    if (auto it = programs_.find(key); it != programs_.end()) return it->second;
    static constexpr const char* kModeDefines[] = {"MODE_NONE", "MODE_CENTER", "MODE_NB", "MODE_HIZ"};
    std::string defines = std::string("#define ") + kModeDefines[static_cast<int>(mode)] + "\n";
    defines += reversed ? "#define ZERO_TO_ONE\n#define FAR(a, b) min(a, b)\n#define HIDDEN(d, f) ((d) + margin < (f))\n"
                        : "#define FAR(a, b) max(a, b)\n#define HIDDEN(d, f) ((d) - margin > (f))\n";
    defines += capture::covering_glsl(kSpriteCovering);
    const GLuint prog = capture::link_program(
        {capture::compile_shader(GL_VERTEX_SHADER, capture::with_defines(shaders::particles_particles_vert, defines),
                                 "particles/particles.vert"),
         capture::compile_shader(GL_FRAGMENT_SHADER, kCountFragments, "count.frag")},
        "particles hard cases");
    programs_[key] = prog;
    return prog;
  }
  // Level k of the N-buffer in layer k of a 2D array, as the capture's GlslNBuffer keeps them.
  void upload_levels(const NBuffer& nb) {
    if (levels_) glDeleteTextures(1, &levels_);
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &levels_);
    glTextureStorage3D(levels_, 1, GL_R32F, kW, kH, nb.level_count());
    glTextureParameteri(levels_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(levels_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    for (int k = 0; k < nb.level_count(); ++k)
      glTextureSubImage3D(levels_, 0, 0, 0, k, kW, kH, 1, GL_RED, GL_FLOAT, nb.level(k).data());
  }

  GLuint depth_ = 0, depth_copy_ = 0, counts_ = 0, levels_ = 0, fbo_ = 0, vao_ = 0, vbo_ = 0, decisions_ = 0, q_samples_ = 0;
  std::map<std::pair<Mode, bool>, GLuint> programs_;
};

// The model's answers for the same sprite.
struct ModelOutcome {
  SpriteRect rect;
  Rect drawn;
  bool passes = false;  // the exact sprite test: some drawn pixel passes the depth test
  Decision center, nb, hiz;
};

ModelOutcome model(const Particle& p, const DepthImage& scene, const NBuffer& nb, FarOp op) {
  ModelOutcome m;
  m.rect = sprite_rect(p, kW, kH);
  m.drawn = drawn_rect(p, kW, kH);
  m.passes = !m.drawn.empty() && sprite_passes(m.drawn, p.depth, scene, op);
  m.center = center_test(p, m.rect, scene, kMargin, op);
  if (nb_testable(m.rect, nb.top_level())) {
    const QueryResult q = nb.query(m.rect.clipped, kSpriteCovering);
    EXPECT_TRUE(q.complete) << "a testable sprite's level is built";
    m.nb.tested = true;
    m.nb.lookups = static_cast<std::uint32_t>(q.texel_count);
    m.nb.culled = hidden_behind(p.depth, q.value, kMargin, op);
  } else {
    m.nb.too_large = m.rect.on_screen;
  }
  const HiZPyramid pyramid(scene, HiZConfig{op, StorageFormat::F32});
  m.hiz = hiz_test(p, m.rect, pyramid, nb.top_level(), kMargin, op);
  return m;
}

bool same(const Rect& a, const Rect& b) { return a.empty() ? b.empty() : a.x == b.x && a.y == b.y && a.w == b.w && a.h == b.h; }

// Everything both sides say about one sprite, checked against each other.
struct Both {
  GlOutcome none, center, nb;
  ModelOutcome m;
};

class ParticlesHardCasesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = new gl::Context();
    gl_ = new GlParticles();
  }
  static void TearDownTestSuite() {
    delete gl_;
    delete context_;
  }

  // Runs the sprite in none, center and nb on GL and through the model; checks that they agree.
  static Both decide(const Sprite& s, const DepthImage& scene, int top_level, bool reversed) {
    const FarOp op = reversed ? FarOp::Min : FarOp::Max;
    const NBuffer nb(scene, {op, StorageFormat::F32, top_level});
    Both b;
    b.none = gl_->run(s, Mode::None, scene, nb, reversed);
    b.center = gl_->run(s, Mode::Center, scene, nb, reversed);
    b.nb = gl_->run(s, Mode::NBuffer, scene, nb, reversed);
    const Particle p = b.nb.window;
    EXPECT_EQ(p.x, s.x) << "GL's window position is the one given (exact conversions)";
    EXPECT_EQ(p.y, s.y);
    EXPECT_EQ(p.depth, s.depth);
    EXPECT_EQ(p.size, s.size);
    b.m = model(p, scene, nb, op);
    // What GL draws is the model's square, and a passing sample exactly when the exact test says so.
    EXPECT_TRUE(same(b.none.covered, b.m.drawn)) << "GL covered [" << b.none.covered.x << ", " << b.none.covered.x1() << ") x ["
                                                 << b.none.covered.y << ", " << b.none.covered.y1() << "), model drawn_rect ["
                                                 << b.m.drawn.x << ", " << b.m.drawn.x1() << ") x [" << b.m.drawn.y << ", "
                                                 << b.m.drawn.y1() << ")";
    EXPECT_EQ(b.none.covered_pixels, static_cast<std::uint64_t>(b.m.drawn.area())) << "GL's square is a whole rectangle";
    EXPECT_EQ(b.none.samples_passed > 0, b.m.passes) << "GL's passed samples against the model's exact sprite test";
    // GL's decisions are the model's, texel for texel.
    EXPECT_EQ(b.center.culled, b.m.center.culled) << "center: GL and model decide alike";
    EXPECT_EQ(b.center.lookups, b.m.center.lookups) << "center: lookups";
    EXPECT_EQ(b.nb.culled, b.m.nb.culled) << "nb: GL and model decide alike";
    EXPECT_EQ(b.nb.lookups, b.m.nb.lookups) << "nb: lookups (distinct texels read)";
    EXPECT_FALSE(b.none.culled);
    // Conservative: nb and hiz never cull a sprite GL draws a passing sample of.
    if (b.none.samples_passed > 0) {
      EXPECT_FALSE(b.nb.culled) << "nb culled a visible sprite (popping)";
      EXPECT_FALSE(b.m.hiz.culled) << "hiz culled a visible sprite (popping)";
    }
    return b;
  }

  static gl::Context* context_;
  static GlParticles* gl_;
};
gl::Context* ParticlesHardCasesTest::context_ = nullptr;
GlParticles* ParticlesHardCasesTest::gl_ = nullptr;

// A building (near) on columns x < edge, open far plane to its right.
DepthImage building(int edge, float near, float far) {
  DepthImage d(kW, kH, far);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < edge; ++x) d.at(x, y) = near;
  return d;
}

// The centre one pixel behind a building's edge while the sprite's right half shows: center culls
// it and pops; nb and hiz keep it.
TEST_F(ParticlesHardCasesTest, CentreBehindEdgeWithCornerVisibleIsKept) {
  const DepthImage scene = building(20, 0.25f, 1.0f);
  const Both b = decide({19.75f, 16.25f, 0.5f, 16.0f}, scene, 4, false);  // square [12, 28): centre pixel 19
  EXPECT_EQ(b.none.samples_passed, 8u * 16u) << "GL: columns 20..27 show the sprite";
  EXPECT_TRUE(b.center.culled) << "GL center culls it: the centre pixel is behind the building";
  EXPECT_TRUE(b.m.center.culled);
  EXPECT_FALSE(b.nb.culled) << "GL nb keeps it";
  EXPECT_EQ(b.nb.lookups, 1u) << "a power-of-two sprite off a tie: one lookup";
  EXPECT_TRUE(b.m.hiz.tested);
  // One pixel showing, in the sprite's corner only.
  DepthImage corner(kW, kH, 0.25f);
  corner.at(27, 23) = 1.0f;
  const Both c = decide({19.75f, 16.25f, 0.5f, 16.0f}, corner, 4, false);
  EXPECT_EQ(c.none.samples_passed, 1u) << "GL: the corner pixel";
  EXPECT_TRUE(c.center.culled) << "center pops";
  EXPECT_FALSE(c.nb.culled);
}

// A centre on a pixel edge with an odd size (17 px at x 10.0): the square's edges pass through
// pixel centres. GL owns the left/bottom edge (column 1) and not the right/top (column 18); the
// shader's rectangle is one wider there, so nb reads column 18 too and may keep a sprite GL draws
// no passing sample of (conservative), but never culls one showing only on the owned edge.
TEST_F(ParticlesHardCasesTest, CentreOnPixelEdgeFillRuleTie) {
  const Sprite s{10.0f, 16.0f, 0.5f, 17.0f};
  DepthImage owned(kW, kH, 0.25f);
  owned.at(1, 7) = 1.0f;  // the lower-left corner of GL's square [1, 18) x [7, 24)
  const Both a = decide(s, owned, 5, false);
  EXPECT_TRUE(same(a.none.covered, Rect{1, 7, 17, 17})) << "GL: 17x17 from the owned edges";
  EXPECT_EQ(a.none.samples_passed, 1u);
  EXPECT_FALSE(a.nb.culled);
  EXPECT_EQ(a.m.rect.hi_x - a.m.rect.lo_x, 18) << "the shader widens the tie by one";
  DepthImage unowned(kW, kH, 0.25f);
  unowned.at(18, 16) = 1.0f;  // just right of GL's square
  const Both b = decide(s, unowned, 5, false);
  EXPECT_EQ(b.none.samples_passed, 0u) << "GL does not draw the unowned edge's column";
  EXPECT_FALSE(b.nb.culled) << "the widened rectangle reads it: kept (a conservative miss, not a pop)";
  DepthImage hidden(kW, kH, 0.25f);
  const Both c = decide(s, hidden, 5, false);
  EXPECT_TRUE(c.nb.culled) << "all hidden: culled";
  EXPECT_EQ(c.nb.lookups, 4u) << "18 px wide: four squares of level 4";
}

// Partly off-screen (centre inside): GL draws the clipped square, the query reads the clipped
// rectangle. Centre outside the viewport: GL draws nothing, center reads nothing, nb still tests
// the on-screen part of the shader's rectangle. Centre beyond the far plane: nothing drawn, no test.
TEST_F(ParticlesHardCasesTest, PartlyOffscreenAndCentreOutsideTheFrustum) {
  DepthImage hidden(kW, kH, 0.25f);
  const Both in = decide({3.25f, 16.25f, 0.5f, 16.0f}, hidden, 4, false);
  EXPECT_TRUE(same(in.none.covered, Rect{0, 8, 11, 16})) << "GL: square [-5, 11) cut at x 0";
  EXPECT_TRUE(same(in.m.rect.clipped, Rect{0, 8, 11, 16}));
  EXPECT_TRUE(in.nb.culled);
  EXPECT_EQ(in.nb.lookups, 4u) << "11 x 16 clipped: the paper's four quadrants of level 3 (the corner covering read one "
                                   "level-4 square, columns 11..15 too)";
  DepthImage edge = hidden;
  edge.at(0, 8) = 1.0f;  // the only pixel showing is on the screen border
  const Both shown = decide({3.25f, 16.25f, 0.5f, 16.0f}, edge, 4, false);
  EXPECT_EQ(shown.none.samples_passed, 1u);
  EXPECT_FALSE(shown.nb.culled);

  DepthImage open = building(6, 0.25f, 1.0f);
  for (int y = 0; y < kH; ++y) open.at(0, y) = 1.0f;  // a far column the shader's rectangle reaches
  const Both out = decide({-2.0f, 16.25f, 0.5f, 16.0f}, open, 4, false);
  EXPECT_EQ(out.none.covered_pixels, 0u) << "GL clips the point by its centre: nothing drawn";
  EXPECT_EQ(out.center.lookups, 0u) << "the centre pixel is off-screen: no lookup";
  EXPECT_TRUE(out.m.rect.on_screen) << "the shader's rectangle still reaches columns 0..5";
  EXPECT_EQ(out.nb.lookups, 2u) << "nb reads the on-screen part [0, 6) x [8, 24): two stacked level-3 squares";
  EXPECT_FALSE(out.nb.culled);
  const Both hid = decide({-2.0f, 16.25f, 0.5f, 16.0f}, hidden, 4, false);
  EXPECT_TRUE(hid.nb.culled) << "culled though GL would draw nothing anyway: no cost, no pop";

  const Both beyond = decide({32.25f, 16.25f, 1.25f, 16.0f}, hidden, 4, false);
  EXPECT_EQ(beyond.none.covered_pixels, 0u) << "GL: beyond the far plane, nothing drawn";
  EXPECT_FALSE(beyond.m.rect.on_screen);
  EXPECT_EQ(beyond.nb.lookups, 0u);
  EXPECT_EQ(beyond.center.lookups, 0u);
}

// A sprite at exactly the stored farthest depth: LESS passes no sample, and HIDDEN (strictly
// behind by more than the margin) keeps it; behind by more than the margin it is culled.
TEST_F(ParticlesHardCasesTest, SpriteDepthEqualToStoredFarthest) {
  const DepthImage scene(kW, kH, 0.5f);
  const Both eq = decide({20.25f, 16.25f, 0.5f, 16.0f}, scene, 4, false);
  EXPECT_EQ(eq.none.samples_passed, 0u) << "GL: LESS fails on equal depth";
  EXPECT_FALSE(eq.nb.culled) << "equal is not hidden: kept";
  EXPECT_FALSE(eq.center.culled);
  const Both behind = decide({20.25f, 16.25f, 0.5f + 0x1p-18f, 16.0f}, scene, 4, false);  // beyond the margin
  EXPECT_TRUE(behind.nb.culled);
  EXPECT_TRUE(behind.center.culled);
  const Both rev = decide({20.25f, 16.25f, 0.5f, 16.0f}, scene, 4, true);
  EXPECT_EQ(rev.none.samples_passed, 0u) << "GL: GREATER fails on equal depth";
  EXPECT_FALSE(rev.nb.culled);
}

// Sizes: 7 px (not a power of two) takes up to four lookups of level 2; 24 px with levels 0..3
// built is kept untested (and hiz too); 300 px, beyond GL's range, is drawn as 255 px by GL and
// the model and kept by nb (its rectangle needs level 8).
TEST_F(ParticlesHardCasesTest, SizesNotPowersOfTwoTooLargeAndBeyondGlRange) {
  const DepthImage hidden(kW, kH, 0.25f);
  const Both seven = decide({20.25f, 16.25f, 0.5f, 7.0f}, hidden, 3, false);
  EXPECT_TRUE(seven.nb.culled);
  EXPECT_EQ(seven.nb.lookups, 4u) << "7 x 7: four squares of level 2";
  EXPECT_TRUE(seven.m.hiz.culled);
  const Both big = decide({20.25f, 16.25f, 0.5f, 24.0f}, hidden, 3, false);
  EXPECT_FALSE(big.nb.culled) << "needs level 4, only 0..3 built: kept";
  EXPECT_EQ(big.nb.lookups, 0u) << "kept untested";
  EXPECT_TRUE(big.m.nb.too_large);
  EXPECT_TRUE(big.m.hiz.too_large);
  const Both huge = decide({32.25f, 16.25f, 0.5f, 300.0f}, hidden, 5, false);
  EXPECT_EQ(huge.none.covered_pixels, static_cast<std::uint64_t>(kW * kH)) << "GL: 255 px covers the whole 64x32 target";
  EXPECT_FALSE(huge.nb.culled);
  EXPECT_EQ(huge.nb.lookups, 0u);
  EXPECT_TRUE(huge.m.nb.too_large);
}

// Reversed Z (ZERO_TO_ONE, GREATER, a min N-buffer): near is large. The silhouette case again:
// center pops, nb keeps; a wholly hidden sprite is culled by the min N-buffer.
TEST_F(ParticlesHardCasesTest, ReversedZWithMinNBuffer) {
  const DepthImage scene = building(20, 0.75f, 0.0f);
  const Both b = decide({19.75f, 16.25f, 0.5f, 16.0f}, scene, 4, true);
  EXPECT_EQ(b.none.samples_passed, 8u * 16u);
  EXPECT_TRUE(b.center.culled) << "center pops under reversed Z too";
  EXPECT_FALSE(b.nb.culled);
  const Both h = decide({10.25f, 16.25f, 0.5f, 16.0f}, scene, 4, true);  // [2, 18): behind the building
  EXPECT_EQ(h.none.samples_passed, 0u);
  EXPECT_TRUE(h.nb.culled) << "the min N-buffer culls a hidden sprite";
  EXPECT_FALSE(h.m.hiz.culled) << "hiz's level-4 texels reach the open columns 20..31: kept (less tight, still safe)";
}

}  // namespace
}  // namespace nbsim::particles
