// The capture side of the technique seam (docs/adding-a-technique.md, "The renderer side"): a
// technique is a class that owns its GL resources and passes and renders one frame at a
// time into a frame record, built from the shared pieces (gl_program.h, draw_recorder.h,
// scene_pass.h, render_target.h, readback.h, ground_truth.h). Techniques are chosen by name from
// one table (techniques.cpp), a row per technique of the registration list: the name, a one-line
// description, the options the technique reads and its factory. The header's "technique" property is the row's name.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "model/scene/frame.h"
#include "nbsim/technique_list.h"
#include "traces/capture/camera.h"
#include "traces/capture/plugin.h"
#include "traces/capture/scenes.h"
#include "traces/format/records.h"

namespace nbsim::capture {

// What a technique is made with. The GL context is current while it is made and used.
struct TechniqueSetup {
  const CaptureScene& scene;  // outlives the technique
  int width = 0, height = 0;  // viewport, pixels
  Projection projection;      // reversed_z picks the depth convention
  const OptionValues& options;  // its options (declared in its row); read them while constructing
};

// One rendered frame: the records the trace stores, in scene::Frame (begin, draws with index ==
// position, depth images, N-buffer levels, ground truth, end), and the objects the technique drew.
struct CapturedFrame {
  scene::Frame frame;
  // For techniques that cull objects: every object they drew, sorted. The capture checks that
  // each object the ground truth sees is among them (a conservative technique culls none).
  std::optional<std::vector<std::uint32_t>> rendered_objects;
  // Counts the technique reports for the frame by name (e.g. culled, popping), summed
  // over the capture into CaptureSummary::technique_counts and printed by `nbsim capture`.
  std::vector<std::pair<std::string, std::uint64_t>> counts;
};

class Technique {
 public:
  virtual ~Technique() = default;

  // Header properties the technique adds. The header is: GL and depth convention, "technique" =
  // the row's name, variant_properties(), the scene's, the camera path's and the projection's,
  // setting_properties(), the tool's, in this order.
  virtual trace::Properties variant_properties() const = 0;   // what the technique is (e.g. test_mode)
  virtual trace::Properties setting_properties() const = 0;   // how it is tuned (e.g. nearest_margin)
  // The header's "depth_format": the GL format of the depth buffer the technique renders into.
  virtual std::string depth_format() const { return "DEPTH_COMPONENT32F"; }

  // Renders frame `index` (0, 1, ... in order) from `pose`.
  virtual CapturedFrame render(std::uint32_t index, const CameraPose& pose) = 0;
};

// What `nbsim bench replay --technique NAME` captures unless told otherwise: a workload that runs
// the technique's GL passes and its model program. The bench's own --scene, --path, --size and
// capture options override these.
struct BenchPreset {
  std::string scene = "city", path = "walk", size = "512x512";
  OptionValues options;     // capture options the preset sets (the rest keep their defaults)
  std::string mode_option;  // the capture option the bench's --mode sets ("": --mode is refused)
  // Model config keys the bench's replay sets (unit.field=value) before the user's --set: what makes
  // the replay model the technique's whole frame.
  std::vector<std::string> replay_sets;
};

// Another name of a technique's capture with its scene fixed: `nbsim capture ALIAS ...` is
// `nbsim capture TECHNIQUE --scene SCENE ...`, kept where recorded command lines use the old name.
struct CaptureAlias {
  std::string name;
  std::string scene;
};

struct TechniqueRow {
  PluginInfo info;
  // Throws InputError on bad option values.
  std::function<std::unique_ptr<Technique>(const TechniqueSetup&)> make;
  BenchPreset bench;
  std::vector<CaptureAlias> aliases;
  // Whether a capture with these options draws the scene and follows the camera path: null, or an
  // empty answer, when it does; otherwise why not (for the message that refuses --scene or --path).
  // A capture that draws no scene builds none: TechniqueSetup::scene is empty, the poses are the
  // default pose, and the header's scene and path are "none".
  std::function<std::string(const OptionValues&)> no_scene;
};

// Each technique of the registration list (cmake/NbsimTechniques.cmake) defines its row,
// TechniqueRow <name>_technique(), in its folder traces/capture/<name>/.
#define NBSIM_DECLARE_TECHNIQUE_ROW(name) TechniqueRow name##_technique();
NBSIM_EACH_TECHNIQUE(NBSIM_DECLARE_TECHNIQUE_ROW)
#undef NBSIM_DECLARE_TECHNIQUE_ROW

// The rows in the registration list's order (techniques.cpp); the first is the default technique.
const std::vector<TechniqueRow>& technique_table();
// The name of the table's first row: what a capture or bench runs when no technique is named.
const std::string& default_technique();
// Throws InputError listing the known techniques.
const TechniqueRow& find_technique(std::string_view name);

}  // namespace nbsim::capture
