// The ID-buffer ground truth; see ground_truth.h.
#include "traces/capture/ground_truth.h"

#include "model/common/error.h"

namespace nbsim::capture {

scene::GroundTruth ground_truth(const ScenePass& pass, const RenderTarget& target, DrawRecorder& recorder,
                                const glm::mat4& view_proj, bool reversed, const std::vector<std::uint32_t>& order) {
  const int w = target.width(), h = target.height();
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer());
  const GLuint clear_id[4] = {0, 0, 0, 0};
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // clears obey the write masks
  target.clear_depth(reversed);
  glClearNamedFramebufferuiv(target.framebuffer(), GL_COLOR, 0, clear_id);
  pass.begin(target, view_proj, reversed, recorder);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  pass.draw_ids(order, recorder.scratch_slot());

  std::vector<std::uint32_t> ids(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer());
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, ids.data());
  scene::GroundTruth t;
  t.visible_pixels.assign(pass.scene().objects.size(), 0);
  t.id_width = w;
  t.id_height = h;
  t.ids.resize(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const std::uint32_t id = ids[i];
    t.ids[i] = static_cast<std::int32_t>(id) - 1;  // -1 where no object
    if (id == 0) continue;
    ++t.covered_pixels;
    NBSIM_CHECK(id - 1 < t.visible_pixels.size(), "ID buffer holds an id past the scene");
    ++t.visible_pixels[id - 1];
  }
  glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  return t;
}

}  // namespace nbsim::capture
