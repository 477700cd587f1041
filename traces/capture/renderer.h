// The capture renderer: a headless GL context on Mesa (llvmpipe) and one technique from the
// technique table (technique.h) made on it for a scene. It renders one frame at a time into the
// records the trace stores; capture.h streams them into a file.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "traces/capture/camera.h"
#include "traces/capture/plugin.h"
#include "traces/capture/scenes.h"
#include "traces/capture/technique.h"
#include "traces/gl/context.h"

namespace nbsim::capture {

struct RendererOptions {
  std::string technique = default_technique();
  int width = 512;
  int height = 512;
  Projection projection;
  OptionValues options;  // the technique's options by name (others are ignored here)
};

class Renderer {
 public:
  // Throws InputError for an unknown technique or a bad option value.
  Renderer(const CaptureScene& scene, const RendererOptions& options);
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders frame `index` (0, 1, ... in order) from `pose`.
  CapturedFrame render(std::uint32_t index, const CameraPose& pose) { return technique_->render(index, pose); }

  const TechniqueRow& row() const noexcept { return *row_; }
  const Technique& technique() const noexcept { return *technique_; }
  const gl::ContextInfo& gl_info() const noexcept { return context_.info(); }

 private:
  const TechniqueRow* row_;
  gl::Context context_;  // made before the technique, current while it lives
  std::unique_ptr<Technique> technique_;
};

}  // namespace nbsim::capture
