// The capture renderer; see renderer.h.
#include "traces/capture/renderer.h"

namespace nbsim::capture {

Renderer::Renderer(const CaptureScene& scene, const RendererOptions& options)
    : row_(&find_technique(options.technique)),
      technique_(row_->make(TechniqueSetup{scene, options.width, options.height, options.projection, options.options})) {}

}  // namespace nbsim::capture
