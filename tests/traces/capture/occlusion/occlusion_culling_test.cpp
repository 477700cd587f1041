// OcclusionCullingOptionsTest: the occlusion-culling technique's options (traces/capture/occlusion/)
// without GL: its row in the technique table declares them, --mode offers exactly the model's test
// modes (model/scene/frame.h's names, which the trace's test_mode and the replay's cull.mode share)
// and refuses another technique's mode. The captures themselves are CaptureTest's
// (tests/traces/capture/capture_test.cpp).
#include "traces/capture/occlusion/occlusion_culling.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/scene/frame.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {
namespace {

const OptionSpec& option(const std::string& name) {
  for (const OptionSpec& o : occlusion_culling_options())
    if (o.name == name) return o;
  throw std::runtime_error("no option --" + name);
}

TEST(OcclusionCullingOptionsTest, ModeOffersTheModelsTestModes) {
  const TechniqueRow& row = find_technique("occlusion_culling");
  std::vector<std::string> declared, row_declared;
  for (const OptionSpec& o : occlusion_culling_options()) declared.push_back(o.name);
  for (const OptionSpec& o : row.info.options) row_declared.push_back(o.name);
  EXPECT_EQ(row_declared, declared) << "the table's row declares the technique's options";
  EXPECT_EQ(declared, (std::vector<std::string>{"mode", "levels-every", "covering", "align"}));

  const OptionSpec& mode = option("mode");
  EXPECT_EQ(mode.kind, OptionSpec::Kind::Choice);
  EXPECT_EQ(mode.choices, std::vector<std::string>(scene::kTestModeNames.begin(), scene::kTestModeNames.end()));
  for (const std::string& m : mode.choices) {
    ASSERT_TRUE(scene::parse_test_mode(m).has_value()) << m;
    EXPECT_EQ(scene::to_string(*scene::parse_test_mode(m)), m);
  }
  EXPECT_EQ(mode.default_value, "nb_hier");
  const OptionValues particles_mode = {{"mode", "hiz"}};
  try {
    particles_mode.text(mode);
    ADD_FAILURE() << "--mode hiz (a particles mode) was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--mode"), std::string::npos) << e.what();
  }
  EXPECT_EQ(OptionValues{}.integer(option("levels-every")), 10) << "the GLSL N-buffer levels every 10th frame";
}

}  // namespace
}  // namespace nbsim::capture
