// LdiTable1CliTest: `nbsim ldi table1` from the outside: the rows of Table 1 with the parity test's
// accuracy on llvmpipe (JSON and the --out folder the report reads), and bad arguments refused with
// exit 2 before any GL work or output. The times are printed by the command, never asserted.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

using testing::CliResult;
using testing::run_nbsim;

TEST(LdiTable1CliTest, RowsPerShapeAndSide) {
  const std::filesystem::path out = nbsim::testing::scratch_path("nbsim_ldi_cli", "table1");
  std::filesystem::remove_all(out);
  const CliResult r = run_nbsim("ldi table1 --shapes sphere,nested:2 --sizes 32,48 --points 300 --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 4u);
  std::ifstream f(out / "ldi.json");
  EXPECT_EQ(nlohmann::json::parse(f), rows) << "the --out file holds the printed rows";
  EXPECT_TRUE(std::filesystem::exists(out / "ldi.csv"));
  for (const auto& row : rows) {
    const bool sphere = row.at("shape") == "sphere";
    EXPECT_EQ(row.at("vertices"), sphere ? 994 : 2 * 15 * 24 + 4) << row.dump();  // nested: 2 spheres of 15 rings x 24 + 2 poles
    EXPECT_EQ(row.at("layers"), sphere ? 2 : 4) << "d of a sphere and of two nested shells";
    EXPECT_EQ(row.at("d_min"), row.at("layers")) << "the chosen direction has the smallest d";
    EXPECT_EQ(row.at("readers_disagree"), 0) << "compression is lossless";
    EXPECT_EQ(row.at("gl_parity_mismatches"), 0) << "the model's parity test on GL's LDI is GL's, fetches included";
    EXPECT_EQ(row.at("misclassified_layers"), row.at("misclassified_ranges"));
    EXPECT_EQ(row.at("points"), 300);
    EXPECT_EQ(row.at("uniform_points"), 300);
    EXPECT_EQ(row.at("classified").get<int>() + row.at("near_surface").get<int>(), 300);
    EXPECT_GT(row.at("m_crop").get<double>(), 0.0);
    EXPECT_NEAR(row.at("c_ratio").get<double>(), row.at("m_comp").get<double>() / row.at("m_crop").get<double>(), 1e-12);
    EXPECT_EQ(row.at("paper_c_ratio").is_null(), !sphere) << "the paper's sphere row sits beside ours";
    // a sphere's test reads its texel's first layer, and the second when the point lies behind the first
    if (sphere) {
      EXPECT_LE(row.at("fetches_per_test_layers").get<double>(), 2.0);
    }
  }
  std::filesystem::remove_all(out);
}

TEST(LdiTable1CliTest, BadArgumentsAreRefused) {
  const std::filesystem::path open = nbsim::testing::scratch_path("nbsim_ldi_cli", "open.obj");
  std::ofstream(open) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";  // a tetrahedron missing a face
  struct Row {
    std::string args, says;
  };
  const Row rows[] = {
      {"--grid 0x8", "--grid '0x8'"},
      {"--shapes teapot", "teapot"},
      {"--shapes nested:x", "'nested:x' is not NAME or NAME:INTEGER"},
      {"--shapes sphere --sizes 0", "--sizes: 0"},
      {"--shapes nested:9 --max-layers 4", "max"},
      {"--shapes sphere --epsilon 2", "--epsilon 2"},
      {"--shapes sphere --mesh " + open.string(), "not closed"},
      {"--shapes sphere --mesh /nonexistent.ply", "no such file"},
  };
  for (const Row& row : rows) {
    const CliResult r = run_nbsim("ldi table1 --sizes 16 --points 10 " + row.args);
    EXPECT_EQ(r.status, 2) << row.args << ": " << r.err;
    EXPECT_NE(r.err.find(row.says), std::string::npos) << row.args << ": " << r.err;
  }
  std::filesystem::remove(open);
  EXPECT_EQ(run_nbsim("ldi table1 --help").status, 0);
  EXPECT_EQ(run_nbsim("ldi").status, 2) << "a subcommand is required";
}

}  // namespace
}  // namespace nbsim
