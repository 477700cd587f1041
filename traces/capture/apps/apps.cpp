// The apps technique's renderer capture; see apps.h.
#include "traces/capture/apps/apps.h"

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <chrono>
#include <cstring>

#include "model/apps/roles.h"
#include "model/common/error.h"
#include "model/scene/visibility.h"
#include "traces/apitrace/raw.h"
#include "traces/capture/apps/convert.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/ground_truth.h"
#include "traces/capture/readback.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"

namespace nbsim::capture {

namespace {

// --as-program: draw the frames as a program that records nothing would (for apitrace to record).
const OptionSpec& as_program_option() {
  static const OptionSpec spec = choice_option(
      "as-program",
      "yes: draw each frame's draw calls as a program that records nothing would (no feedback, queries or ground truth) and "
      "mark each frame's end for apitrace (glDebugMessageInsert); the trace then holds no draws. For the check that "
      "`nbsim capture apitrace` of such a run gives the draws of a native capture",
      "no", {"no", "yes"});
  return spec;
}

class Apps final : public Technique {
 public:
  explicit Apps(const TechniqueSetup& s)
      : scene_(s.scene), width_(s.width), height_(s.height), projection_(s.projection), pass_(s.scene, false), target_(s.width, s.height),
        as_program_(s.options.text(as_program_option()) == "yes") {
    if (s.projection.reversed_z) throw InputError("the apps capture draws with depth func LESS; --reversed-z is not for it");
  }

  trace::Properties variant_properties() const override { return {}; }
  trace::Properties setting_properties() const override { return {{"apitrace", "none"}, {"app_frames", "none"}}; }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose) override {
    CapturedFrame out;
    scene::Frame& f = out.frame;
    const glm::mat4 view = view_matrix(pose);
    const glm::mat4 proj = projection_matrix(projection_, static_cast<double>(width_) / height_);
    const glm::mat4 view_proj = proj * view;
    scene::FrameBegin begin;
    begin.frame = index;
    std::memcpy(begin.view.data(), glm::value_ptr(view), 64);
    std::memcpy(begin.proj.data(), glm::value_ptr(proj), 64);
    begin.eye = {pose.eye.x, pose.eye.y, pose.eye.z};
    const scene::FrameView v = scene::FrameView::make(begin, width_, height_, projection_.near_m, 0.0, false, false);
    const std::vector<std::uint32_t> objects = scene::frustum_objects(scene_.scene, v);

    const auto t0 = std::chrono::steady_clock::now();
    glBindFramebuffer(GL_FRAMEBUFFER, target_.framebuffer());
    target_.clear_depth(false);
    if (as_program_) return render_as_program(index, begin, view_proj, objects, t0);
    recorder_.begin_frame(objects.size() + 16);
    pass_.begin(target_, view_proj, false, recorder_);
    for (const std::uint32_t o : objects) {
      scene::DrawRecord d;
      d.role = apps::kAppDrawRole;
      d.object = static_cast<std::int32_t>(o);
      d.state = depth_state(false, true, true);
      pass_.draw_object(recorder_, std::move(d), o);
    }
    glFinish();
    const double gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    scene::DepthSnapshot depth = read_depth(target_.framebuffer(), width_, height_, scene::DepthWhich::Final);
    std::vector<scene::DrawRecord> draws = recorder_.collect();

    // The frame as the interposer would have recorded it: one clear, then the draws.
    apitrace::RawFrame raw;
    raw.frame = index;
    apitrace::ClearHead clear{};
    clear.frame = index;
    clear.framebuffer = target_.framebuffer();
    clear.buffers = apitrace::kClearDepth;
    clear.flags = apitrace::kDepthMask;
    clear.scissor[2] = width_, clear.scissor[3] = height_;
    clear.stencil_write_mask = 0xFFFFFFFFu;
    clear.depth = 1.0;
    raw.clears.push_back(clear);
    for (std::size_t i = 0; i < draws.size(); ++i) {
      const scene::DrawRecord& d = draws[i];
      apitrace::RawDraw r;
      apitrace::DrawHead& h = r.head;
      h.frame = index;
      h.index = static_cast<std::uint32_t>(i);
      h.call = static_cast<std::uint32_t>(apitrace::DrawCall::ElementsBaseVertex);
      h.mode = GL_TRIANGLES;
      h.primitive = GL_TRIANGLES;
      h.vertices = static_cast<std::uint32_t>(d.clip_positions.size());
      h.flags = apitrace::kDepthTest | apitrace::kDepthMask | apitrace::kCullFace | apitrace::kFrontCcw;
      h.framebuffer = target_.framebuffer();
      h.target_width = width_, h.target_height = height_;
      h.viewport[2] = width_, h.viewport[3] = height_;
      h.scissor[2] = width_, h.scissor[3] = height_;
      h.depth_range[1] = 1.0;
      h.depth_func = GL_LESS;
      h.cull_mode = GL_BACK;
      h.polygon_mode = GL_FILL;
      h.point_size = 1.0f;
      h.depth_bits = 32;
      h.depth_float = 1;
      for (apitrace::StencilFaceRaw& s : h.stencil) s = {GL_ALWAYS, 0xFFFFFFFFu, 0xFFFFFFFFu, GL_KEEP, GL_KEEP, GL_KEEP, 0};
      h.samples_passed = d.gl.samples_passed;
      r.positions = d.clip_positions;
      raw.draws.push_back(std::move(r));
    }
    raw.end.frame = index;
    raw.end.draws = static_cast<std::uint32_t>(draws.size());
    raw.end.framebuffer = target_.framebuffer();
    raw.end.width = width_, raw.end.height = height_;
    raw.end.has_depth = 1;
    raw.depth = std::move(depth.texels);
    f = apitrace::to_frame(std::move(raw));
    f.begin = begin;
    f.end.gl_ms = gl_ms;
    for (std::size_t i = 0; i < draws.size(); ++i) {  // what the recorder knows beside the interposer's fields
      f.draws[i].object = draws[i].object;
      f.draws[i].gl = draws[i].gl;
    }
    f.truth = ground_truth(pass_, target_, recorder_, view_proj, false, objects);
    out.rendered_objects = objects;
    std::sort(out.rendered_objects->begin(), out.rendered_objects->end());
    return out;
  }

 private:
  // The same draws with nothing recorded, and the frame's end marked for apitrace.
  CapturedFrame render_as_program(std::uint32_t index, const scene::FrameBegin& begin, const glm::mat4& view_proj,
                                  const std::vector<std::uint32_t>& objects, std::chrono::steady_clock::time_point t0) {
    recorder_.begin_frame(0);
    pass_.begin(target_, view_proj, false, recorder_);
    glDepthMask(GL_TRUE);
    pass_.draw_ids(objects, recorder_.scratch_slot());
    glDebugMessageInsert(GL_DEBUG_SOURCE_APPLICATION, GL_DEBUG_TYPE_MARKER, 0, GL_DEBUG_SEVERITY_NOTIFICATION, -1, apitrace::kFrameMarker);
    glFinish();
    CapturedFrame out;
    apitrace::RawFrame raw;
    raw.frame = index;
    raw.end.frame = index;
    raw.end.framebuffer = target_.framebuffer();
    raw.end.width = width_, raw.end.height = height_;
    out.frame = apitrace::to_frame(std::move(raw));
    out.frame.begin = begin;
    out.frame.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return out;
  }

  const CaptureScene& scene_;
  int width_, height_;
  Projection projection_;
  ScenePass pass_;
  RenderTarget target_;
  DrawRecorder recorder_;
  bool as_program_;
};

}  // namespace

const std::vector<OptionSpec>& apps_options() {
  static const std::vector<OptionSpec> options = {as_program_option()};
  return options;
}

std::unique_ptr<Technique> make_apps(const TechniqueSetup& setup) { return std::make_unique<Apps>(setup); }

// This technique's row of the capture's table (technique.h).
TechniqueRow apps_technique() {
  return {{"apps",
           "A program's draw calls as the model replays a real application's (nbsim capture apitrace): the scene drawn with no "
           "culling, every object in the frustum one draw call, with the records an apitrace recording has",
           apps_options()},
          make_apps,
          {"city", "walk", "512x512", {}, "", {}},
          {},
          {}};
}

}  // namespace nbsim::capture
