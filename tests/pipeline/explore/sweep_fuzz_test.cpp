// SweepFuzzTest: `nbsim explore --dry-run` on damaged copies of the sample sweep files. Whatever the
// damage (bytes deleted, inserted or replaced; a JSON value swapped for one of another type or out of
// range; a key dropped or added), the command either accepts the file (exit 0) or refuses it with
// exit 2 and a message on stderr: never a crash, a hang or another status. Seeded: the same damage
// every run.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;
using ojson = nlohmann::ordered_json;

constexpr int kDamagesPerFile = 12;

std::vector<fs::path> sample_sweeps() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(NBSIM_SOURCE_DIR) / "pipeline" / "sweeps"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string read_text(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// One byte deleted, inserted or replaced (printable, control or not UTF-8).
std::string damage_bytes(std::string text, std::mt19937& rng) {
  std::uniform_int_distribution<std::size_t> at(0, text.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255), kind(0, 2);
  const std::size_t i = at(rng);
  switch (kind(rng)) {
    case 0: text.erase(i, 1); break;
    case 1: text.insert(i, 1, static_cast<char>(byte(rng))); break;
    default: text[i] = static_cast<char>(byte(rng)); break;
  }
  return text;
}

// A value of a random type and size, including the awkward ones.
ojson odd_value(std::mt19937& rng) {
  switch (std::uniform_int_distribution<int>(0, 11)(rng)) {
    case 0: return nullptr;
    case 1: return true;
    case 2: return -1;
    case 3: return std::int64_t{1} << 62;
    case 4: return 1e308;
    case 5: return -0.5;
    case 6: return "";
    case 7: return "x.y";
    case 8: return ojson::array();
    case 9: return ojson::array({ojson::array({1})});
    case 10: return ojson::object();
    default: return ojson::object({{"cull.mode", "nb"}});
  }
}

// Every value of the document, as JSON pointers.
void pointers(const ojson& j, const nlohmann::json::json_pointer& at, std::vector<nlohmann::json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object())
    for (const auto& [k, v] : j.items()) pointers(v, at / k, out);
  else if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) pointers(j[i], at / i, out);
}

// One value replaced by an odd one, one key dropped, or an unknown key added, somewhere in the file.
std::string damage_json(const std::string& text, std::mt19937& rng) {
  ojson j = ojson::parse(text);
  std::vector<nlohmann::json::json_pointer> ps;
  pointers(j, nlohmann::json::json_pointer(), ps);
  const auto& p = ps[std::uniform_int_distribution<std::size_t>(1, ps.size() - 1)(rng)];
  switch (std::uniform_int_distribution<int>(0, 2)(rng)) {
    case 0: j[p] = odd_value(rng); break;
    case 1:
      if (!p.parent_pointer().empty() && j[p.parent_pointer()].is_object()) {
        j[p.parent_pointer()].erase(p.back());
        break;
      }
      j[p] = odd_value(rng);
      break;
    default:
      if (j[p].is_object()) j[p]["nbuffer.no_such_key"] = 1;
      else j[p] = odd_value(rng);
  }
  return j.dump(1);
}

TEST(SweepFuzzTest, DamagedSweepsAcceptedOrRefusedCleanly) {
  const fs::path cwd = fs::current_path();
  fs::current_path(NBSIM_SOURCE_DIR);  // sweep files name traces from the repository's root
  const fs::path dir = nbsim::testing::scratch_path("nbsim_sweep_fuzz", "");
  std::mt19937 rng(20261123);
  int runs = 0, refused = 0;
  for (const fs::path& file : sample_sweeps()) {
    const std::string text = read_text(file);
    for (int n = 0; n < kDamagesPerFile; ++n) {
      const std::string damaged = n % 2 ? damage_bytes(text, rng) : damage_json(text, rng);
      const fs::path f = dir / (file.stem().string() + "_" + std::to_string(n) + ".json");
      std::ofstream(f, std::ios::binary) << damaged;
      const fs::path out = dir / ("out_" + std::to_string(runs));
      const CliResult r = run_nbsim("explore " + f.string() + " --dry-run --out " + out.string());
      ++runs;
      ASSERT_TRUE(r.status == 0 || r.status == 2) << f << ": exit " << r.status << "\n" << r.err;
      if (r.status == 2) {
        ++refused;
        EXPECT_TRUE(has(r.err, "error")) << f << ": refused without a message: " << r.err;
        EXPECT_LT(r.err.size(), 2000u) << f << ": a message, not a dump";
      }
    }
  }
  fs::current_path(cwd);
  fs::remove_all(dir);
  EXPECT_GE(runs, 100);
  EXPECT_GT(refused, runs / 4) << "the damage should break most files";
}

}  // namespace
