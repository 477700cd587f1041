// Occlusion culling; see occlusion_culling.h.
#include "traces/capture/occlusion/occlusion_culling.h"

#include <fmt/format.h>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>

#include "model/scene/visibility.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/glsl_nbuffer.h"
#include "traces/capture/ground_truth.h"
#include "traces/capture/readback.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"

namespace nbsim::capture {

namespace {

using scene::DrawRecord;
using scene::DrawRole;
using scene::TestMode;

// Margin subtracted from (LESS) or added to (reversed Z) a bounds' nearest depth, so that GL's
// interpolated fragment depths can never be nearer than it. Tunable; 1e-6 is ~16 float ulps at 1.
constexpr float kNearestMargin = 1e-6f;

std::vector<std::string> test_mode_names() {
  std::vector<std::string> names;
  for (int m = 0; m < 256; ++m) {
    const std::string_view s = scene::to_string(static_cast<TestMode>(m));
    if (s == "?") break;
    names.emplace_back(s);
  }
  return names;
}

const OptionSpec& mode_option() {
  static const OptionSpec spec = choice_option("mode",
                                                "Visibility test: oq, oq_hier (occlusion queries, flat or over the BVH), nb, nb_hier "
                                                "(GLSL N-buffer), none",
                                                "nb_hier", test_mode_names());
  return spec;
}

const OptionSpec& levels_every_option() {
  static const OptionSpec spec = levels_every_spec("the GLSL N-buffer levels");
  return spec;
}

const OptionSpec& culling_covering_option() {
  static const OptionSpec spec = covering_option();
  return spec;
}

class OcclusionCulling final : public Technique {
 public:
  explicit OcclusionCulling(const TechniqueSetup& s)
      : scene_(s.scene),
        width_(s.width),
        height_(s.height),
        projection_(s.projection),
        reversed_(s.projection.reversed_z),
        mode_(*scene::parse_test_mode(s.options.text(mode_option()))),
        levels_every_(static_cast<int>(s.options.integer(levels_every_option()))),
        covering_(read_covering(s.options, culling_covering_option())),
        pass_(s.scene, true),
        target_(s.width, s.height) {
    if (mode_ == TestMode::NBuffer || mode_ == TestMode::NBufferHier)
      nbuffer_ = std::make_unique<GlslNBuffer>(s.width, s.height, reversed_ ? FarOp::Min : FarOp::Max, 1 << 30, covering_);
    if (reversed_) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  }

  trace::Properties variant_properties() const override { return {{"test_mode", std::string(scene::to_string(mode_))}}; }

  trace::Properties setting_properties() const override {
    return {{"nearest_margin", fmt::format("{}", kNearestMargin)},
            {"levels_every", std::to_string(levels_every_)},
            covering_property(covering_)};
  }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose) override;

 private:
  void test_with_queries(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests);
  void test_with_nbuffer(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests);

  const CaptureScene& scene_;
  int width_, height_;
  Projection projection_;
  bool reversed_;
  TestMode mode_;
  int levels_every_;
  CoveringSpec covering_;  // of the GLSL N-buffer's queries (nb, nb_hier); the model's default too
  ScenePass pass_;
  RenderTarget target_;
  DrawRecorder recorder_;
  std::unique_ptr<GlslNBuffer> nbuffer_;  // nb and nb_hier
  glm::mat4 view_proj_{1.0f};
  std::vector<std::uint32_t> previous_visible_;  // last frame's visible objects: this frame's occluders
};

CapturedFrame OcclusionCulling::render(std::uint32_t index, const CameraPose& pose) {
  CapturedFrame out;
  scene::Frame& f = out.frame;
  const std::size_t object_count = scene_.objects.size();
  const glm::mat4 view = view_matrix(pose);
  const glm::mat4 proj = projection_matrix(projection_, static_cast<double>(width_) / height_);
  view_proj_ = proj * view;
  f.begin.frame = index;
  f.begin.mode = mode_;
  std::memcpy(f.begin.view.data(), glm::value_ptr(view), 64);
  std::memcpy(f.begin.proj.data(), glm::value_ptr(proj), 64);
  f.begin.eye = {pose.eye.x, pose.eye.y, pose.eye.z};

  const scene::FrameView v =
      scene::FrameView::make(f.begin, width_, height_, projection_.near_m, kNearestMargin, reversed_, reversed_);
  const std::vector<std::uint32_t> in_frustum = scene::frustum_objects(scene_.scene, v);
  std::vector<char> is_occluder(object_count, 0), in_view(object_count, 0);
  for (auto o : in_frustum) in_view[o] = 1;
  for (auto o : previous_visible_)
    if (in_view[o]) is_occluder[o] = 1;

  const auto t0 = std::chrono::steady_clock::now();
  glBindFramebuffer(GL_FRAMEBUFFER, target_.framebuffer());
  target_.clear_depth(reversed_);
  // Fragment counters of this frame (capacity grows as draws are issued).
  recorder_.begin_frame(std::max<std::size_t>(4 * in_frustum.size() + 64, 256));

  // 1. Occluders: last frame's visible objects.
  pass_.begin(target_, view_proj_, reversed_, recorder_);
  std::vector<std::uint32_t> rendered;
  for (auto o : in_frustum)
    if (is_occluder[o]) {
      DrawRecord d;
      d.role = DrawRole::Occluder;
      d.object = static_cast<std::int32_t>(o);
      d.state = depth_state(reversed_, true, true);
      pass_.draw_object(recorder_, std::move(d), o);
      rendered.push_back(o);
    }
  f.depths.push_back(read_depth(target_.framebuffer(), width_, height_, scene::DepthWhich::AfterOccluders));

  // 2. Bounds tests of every other object in the frustum.
  std::vector<char> visible(object_count, 0);
  if (nbuffer_) {
    scene::DepthState build_state = depth_state(reversed_, false, false);
    build_state.cull = scene::CullFace::None;
    nbuffer_->build(target_.depth_texture(), recorder_, build_state);
  }
  if (mode_ == TestMode::None) {
    for (auto o : in_frustum) visible[o] = !is_occluder[o];
  } else {
    const bool hier = mode_ == TestMode::OcclusionQueryHier || mode_ == TestMode::NBufferHier;
    const scene::BatchTester tester = [&](const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests) {
      if (nbuffer_)
        test_with_nbuffer(items, tests);
      else
        test_with_queries(items, tests);
    };
    visible = scene::find_visible(scene_.scene, v, in_frustum, is_occluder, hier, tester);
  }

  // 3. The objects found visible.
  pass_.begin(target_, view_proj_, reversed_, recorder_);
  for (auto o : in_frustum)
    if (visible[o] && !is_occluder[o]) {
      DrawRecord d;
      d.role = DrawRole::Visible;
      d.object = static_cast<std::int32_t>(o);
      d.state = depth_state(reversed_, true, true);
      pass_.draw_object(recorder_, std::move(d), o);
      rendered.push_back(o);
    }
  glFinish();
  f.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  f.depths.push_back(read_depth(target_.framebuffer(), width_, height_, scene::DepthWhich::Final));
  if (nbuffer_ && levels_every_ > 0 && index % static_cast<std::uint32_t>(levels_every_) == 0) f.levels.push_back(nbuffer_->read());
  f.draws = recorder_.collect();

  // 4. Ground truth: every object in the frustum, nothing culled, in the technique's order
  //    (occluders first), so that ties at equal depth resolve as in the frame.
  std::vector<std::uint32_t> order;
  for (auto o : in_frustum)
    if (is_occluder[o]) order.push_back(o);
  for (auto o : in_frustum)
    if (!is_occluder[o]) order.push_back(o);
  f.truth = ground_truth(pass_, target_, recorder_, view_proj_, reversed_, order);
  previous_visible_.clear();
  for (std::size_t o = 0; o < f.truth->visible_pixels.size(); ++o)
    if (f.truth->visible_pixels[o]) previous_visible_.push_back(static_cast<std::uint32_t>(o));
  std::sort(rendered.begin(), rendered.end());
  out.rendered_objects = std::move(rendered);
  f.end.frame = index;
  f.end.draws = static_cast<std::uint32_t>(f.draws.size());
  return out;
}

// One batch of bounds tests as occlusion queries: each box drawn inside a query, then every
// query's passed samples read (the round trip the technique stalls on).
void OcclusionCulling::test_with_queries(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests) {
  pass_.begin(target_, view_proj_, reversed_, recorder_);
  std::vector<std::size_t> slots;
  for (std::size_t i = 0; i < items.size(); ++i) {
    DrawRecord d;
    d.role = items[i].node >= 0 ? DrawRole::NodeQuery : DrawRole::BoundsQuery;
    d.object = items[i].object;
    d.node = items[i].node;
    d.state = depth_state(reversed_, false, true);  // queries do not write depth
    d.has_bounds = true;
    d.bounds = tests[i];
    slots.push_back(pass_.draw_box(recorder_, std::move(d)));
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    tests[i].visible = tests[i].crosses_near || recorder_.samples_passed(slots[i]) > 0;
    recorder_.record(slots[i]).bounds.visible = tests[i].visible;
  }
}

// One batch of bounds tests against the GLSL N-buffer (one compute dispatch), each recorded as a
// draw without geometry.
void OcclusionCulling::test_with_nbuffer(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests) {
  nbuffer_->query(tests);
  for (std::size_t i = 0; i < items.size(); ++i) {
    DrawRecord d;
    d.role = DrawRole::NBufferQuery;
    d.object = items[i].object;
    d.node = items[i].node;
    d.state = depth_state(reversed_, false, false);
    d.has_bounds = true;
    d.bounds = tests[i];
    recorder_.add_record(std::move(d));
  }
}

}  // namespace

const std::vector<OptionSpec>& occlusion_culling_options() {
  static const std::vector<OptionSpec> options = {mode_option(), levels_every_option(), culling_covering_option(), align_option()};
  return options;
}

BenchPreset occlusion_culling_bench_preset() {
  // The flat occlusion queries draw every candidate's box: the most raster work.
  return {"city", "walk", "512x512", {{"mode", "oq"}, {"levels-every", "0"}}, "mode", {}};
}

std::unique_ptr<Technique> make_occlusion_culling(const TechniqueSetup& setup) { return std::make_unique<OcclusionCulling>(setup); }

// This technique's row of the capture's table (technique.h).
TechniqueRow occlusion_technique() {
  return {{"occlusion_culling",
           "Occlusion culling with occlusion queries or the GLSL N-buffer, flat or over the BVH (N-buffer paper, 3.1 and 4.2)",
           occlusion_culling_options()},
          make_occlusion_culling,
          occlusion_culling_bench_preset(),
          {{"city", "city"}},
          {}};
}

}  // namespace nbsim::capture
