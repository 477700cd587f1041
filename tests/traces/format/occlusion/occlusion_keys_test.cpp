// OcclusionKeysTest: the occlusion-culling technique's header keys (traces/format/occlusion/occlusion_keys.h),
// read typed from a trace of that technique and refused when malformed.
#include <gtest/gtest.h>

#include <string>

#include "model/common/error.h"
#include "model/scene/frame.h"
#include "tests/traces/format/sample_trace.h"
#include "traces/format/occlusion/occlusion_keys.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

// Every test mode the model knows is a valid test_mode and reads back as written; a name it does
// not know is refused naming the key, the value and the choices; the key is registered with the
// technique's others.
TEST(OcclusionKeysTest, TestModeIsOneOfTheModelsModes) {
  for (std::string_view mode : nbsim::scene::kTestModeNames) {
    const TraceReader t(header_only({{"technique", "occlusion_culling"}, {"test_mode", std::string(mode)}}), "h.nbtrace");
    EXPECT_EQ(t.header().text("test_mode"), mode);
  }
  try {
    TraceReader t(header_only({{"technique", "occlusion_culling"}, {"test_mode", "hier"}}), "h.nbtrace");
    ADD_FAILURE() << "test_mode 'hier' was accepted";
  } catch (const nbsim::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("header property 'test_mode' is 'hier': expected one of oq, oq_hier, nb, nb_hier, none"),
              std::string::npos)
        << e.what();
  }
  bool registered = false;
  for (const HeaderKeySpec& k : technique_header_keys()) registered |= k.technique == "occlusion_culling" && k.name == "test_mode";
  EXPECT_TRUE(registered);
  EXPECT_EQ(occlusion_culling_header_keys().size(), 1u);
}

}  // namespace
