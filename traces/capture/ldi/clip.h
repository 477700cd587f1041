// The LDI applications in a scene (Trapp & Doellner, section 3.3): `nbsim capture ldi --application
// clip|lens`. One to four closed volumes (--volumes) stand in the capture's scene; each is built
// once, in frame 0, into an LDI on GL (viewpoint selection, peel, crop, compression: build.h) and
// recorded as an LdiVolume record (LDIV). Every frame, the observer follows the camera path and the
// objects in its frustum are drawn front to back with shaders/ldi/clip.frag, which runs the
// volumetric parity test on every fragment with --reader:
//  - clip: a fragment inside any volume is discarded (the paper's pixel-precise clipping);
//  - lens: the same context pass, then a focus pass that draws the objects near a volume again,
//    flattened to --lens-height of their height, keeping only the fragments inside a volume (a 3D
//    lens showing another version of the scene inside it, by clipping and a second pass).
// The frame's LdiClip record (LDIC) holds the test's uniforms, GL's per-draw answers and the final
// depth buffer's checksum (traces/format/ldi/ldi_chunk.h); the model is model/ldi/clip.h.
#pragma once

#include <memory>
#include <vector>

#include "model/mesh/mesh.h"
#include "traces/capture/ldi/build.h"
#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

// --application, --volumes, --reader, --lens-height.
const std::vector<OptionSpec>& ldi_application_options();
// True when the options ask for an application (clip or lens), which draws the scene.
bool ldi_application_chosen(const OptionValues& o);
// What the ldi row's options already gave: the shape of the automatic volumes (--shape or --mesh,
// closed), the LDI build settings and the reference's epsilon.
struct LdiShapeInput {
  mesh::TriMesh mesh;
  std::string shape;
  LdiBuildConfig config;
  double epsilon = 1e-5;
};
// The application technique (the ldi row's factory calls it when ldi_application_chosen). Checks
// every option here (InputError), the volumes' placement in frame 0.
std::unique_ptr<Technique> make_ldi_application(const TechniqueSetup& setup, LdiShapeInput input);

}  // namespace nbsim::capture
