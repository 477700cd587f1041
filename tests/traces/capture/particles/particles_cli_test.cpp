// ParticlesCliTest: `nbsim capture particles` from the outside: bad counts, sizes, modes, level caps
// and emitters exit 2 naming the problem before any file is written; a capture's `trace info
// --json` shows the PRTC record; replay and compare run it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

// Bad arguments exit 2 with a message naming them, and write nothing.
TEST(ParticlesCliTest, BadArgumentsExitTwo) {
  const fs::path out = testing::scratch_path("nbsim_particles_cli_bad", "never.nbt");
  testing::expect_refused("capture particles --size 32x24 --frames 1 --objects 100 ",
                          {{"--particles 0", "--particles 0 is out of range (1 to 500000)"},
                           {"--particles 500001", "--particles 500001 is out of range"},
                           {"--particles many", "--particles 'many' is not an integer"},
                           {"--sprite 32", "--sprite '32' is not one of 16, 24, atten"},
                           {"--mode zbuffer", "--mode 'zbuffer' is not one of none, center, nb, hiz"},
                           {"--level-cap 13", "--level-cap 13 is out of range (0 to 12)"},
                           {"--emitters 100:100,99999:5", "emitter 2 at x 99999 m, z 5 m is outside the scene"},
                           {"--emitters=-1:5", "emitter 1 at x -1 m, z 5 m is outside the scene"},
                           {"--emitters 10,20", "'10' is not a ground position X:Z"},
                           {"--test-mode nb", "--test-mode"}},
                          " -o " + out.string(), out);
  fs::remove_all(out.parent_path());
}

// A capture prints its particle counts, `trace info --json` lists the PRTC record of every frame
// and `trace dump --records` decodes it; replay and compare run the particles program.
TEST(ParticlesCliTest, InfoShowsTheRecordAndReplays) {
  const fs::path out = testing::scratch_path("nbsim_particles_cli", "p.nbt");
  const CliResult c = run_nbsim("capture particles --size 64x48 --frames 2 --objects 300 --particles 300 --mode center -o " +
                                out.string());
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_TRUE(has(c.out, "particles 600, particles_visible")) << c.out;
  const CliResult info = run_nbsim("trace info " + out.string() + " --json");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_TRUE(has(info.out, "\"technique_records\": [\n        \"PRTC\"")) << info.out;
  EXPECT_TRUE(has(info.out, "\"technique\": \"particles\"")) << info.out;
  const CliResult dump = run_nbsim("trace dump " + out.string() + " --frame 1 --records");
  ASSERT_EQ(dump.status, 0) << dump.err;
  EXPECT_TRUE(has(dump.out, "PRTC ParticleCulling")) << dump.out;
  EXPECT_TRUE(has(dump.out, "reference_samples: 300 elements")) << dump.out;
  EXPECT_TRUE(has(dump.out, "role: 8 (particles)")) << dump.out;
  const fs::path dir = out.parent_path() / "replay";
  for (const std::string& cmd : {"replay " + out.string() + " --out " + dir.string(), "compare " + out.string()}) {
    const CliResult r = run_nbsim(cmd);
    EXPECT_EQ(r.status, 0) << cmd << ": " << r.out << r.err;
  }
  EXPECT_TRUE(fs::exists(dir / "run.json")) << "the particles program replays the capture (model/particles/)";
  fs::remove_all(out.parent_path());
}

}  // namespace
}  // namespace nbsim
