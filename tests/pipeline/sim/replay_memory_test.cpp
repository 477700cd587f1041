// ReplayMemoryTest: long traces in bounded memory. `nbsim replay`, `nbsim trace verify` and `nbsim
// trace info` run as children on a short and a long trace made by `nbsim trace repeat` from one
// small capture; the long run's peak RSS (wait4's ru_maxrss) must not exceed the short run's by
// more than a bound that any per-frame growth would pass.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::run_nbsim;

// This process's scratch folder (nbsim_replay_memory_<pid>/), or a file in it.
fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_replay_memory", name); }

// Runs nbsim with `args` (stdout and stderr to /dev/null) and returns its peak resident set in
// KiB, or -1 when it could not run or did not exit 0.
long peak_rss_kib(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string exe = NBSIM_EXE;
  argv.push_back(exe.data());
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int status = 0;
  struct rusage ru {};
  if (::wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return ru.ru_maxrss;  // KiB on Linux
}

// The smaller peak of two runs: a run's peak varies by a few hundred KiB with where the kernel and
// the allocator put things; the smaller of two is the steadier figure for both traces alike.
long steady_peak_kib(const std::vector<std::string>& args) {
  const long a = peak_rss_kib(args), b = peak_rss_kib(args);
  return a < 0 || b < 0 ? -1 : std::min(a, b);
}

// Frames of the short and the long trace. The short one is long enough that everything a replay
// sets up once (SystemC, the units, buffers, the allocator's arenas) is in its peak.
constexpr int kShortFrames = 100;
constexpr int kLongFrames = 10000;

// The bound on the long run's extra peak, KiB. Measured on this project's machines (Release): the
// two peaks differ by less than 0.4 MiB either way (about 17.7 MiB each, replay 0.2 ms a frame). A
// frame of the 64x64 capture decodes to about 60 KiB (two 16 KiB depth images, the ID buffer, the draws), so
// keeping anything of a frame's size adds 9,900 x 60 KiB = 580 MiB; keeping run.json's per-frame
// objects in memory as nlohmann::ordered_json (what replay did before it streamed them, about
// 580 bytes a frame) added 5.5 MiB (17.7 MiB at 100 frames, 23.2 MiB at 10,000). 2 MiB fails any
// growth above about 210 bytes a frame (2 MiB / 9,900 frames) and is five times the noise.
constexpr long kBoundKib = 2048;

class ReplayMemoryTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
#if defined(__SANITIZE_ADDRESS__)
    return;  // AddressSanitizer's quarantine holds freed memory: peaks grow with allocations, not with what is kept
#endif
    const fs::path one = scratch("tiny.nbt");
    const CliResult c = run_nbsim("capture occlusion_culling --scene city --size 64x64 --frames 4 --objects 60 --levels-every 0 -o " +
                                  one.string());
    ASSERT_EQ(c.status, 0) << c.err;
    for (const int n : {kShortFrames, kLongFrames}) {
      const CliResult r = run_nbsim("trace repeat " + one.string() + " --frames " + std::to_string(n) + " -o " + trace(n).string());
      ASSERT_EQ(r.status, 0) << r.err;
    }
  }
  void SetUp() override {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "peak RSS under AddressSanitizer grows with every allocation (its quarantine)";
#endif
    ASSERT_TRUE(fs::exists(trace(kLongFrames))) << "the suite's traces were not written";
  }
  // The long trace is 45 MB: not left behind.
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(scratch("x").parent_path(), ec);
  }
  static fs::path trace(int frames) { return scratch("long_" + std::to_string(frames) + ".nbt"); }

  // Peaks of `command` on the short and the long trace; `extra` follows the trace argument.
  static std::pair<long, long> peaks(const std::string& command, const std::vector<std::string>& extra = {}) {
    std::pair<long, long> p;
    for (const int n : {kShortFrames, kLongFrames}) {
      std::vector<std::string> args;
      for (std::size_t i = 0, j; i < command.size(); i = j + 1) {
        j = command.find(' ', i);
        if (j == std::string::npos) j = command.size();
        args.push_back(command.substr(i, j - i));
      }
      args.push_back(trace(n).string());
      for (const std::string& e : extra) args.push_back(e == "OUT" ? scratch("out_" + std::to_string(n)).string() : e);
      (n == kShortFrames ? p.first : p.second) = steady_peak_kib(args);
    }
    return p;
  }
};

// A replay of 10,000 frames (with run.json and the CSV files) peaks within 2 MiB of one of 100.
TEST_F(ReplayMemoryTest, ReplayPeakDoesNotGrowWithFrames) {
  const auto [short_kib, long_kib] = peaks("replay", {"--out", "OUT"});
  ASSERT_GT(short_kib, 0) << "nbsim replay failed on the short trace";
  ASSERT_GT(long_kib, 0) << "nbsim replay failed on the long trace";
  // The long run really replayed every frame, and wrote each one's values.
  std::ifstream in(scratch("out_" + std::to_string(kLongFrames)) / "run.json");
  const auto run = nlohmann::json::parse(in);
  ASSERT_EQ(run["summary"]["frames"].get<int>(), kLongFrames);
  ASSERT_EQ(run["frames"].size(), static_cast<std::size_t>(kLongFrames));
  EXPECT_LT(long_kib - short_kib, kBoundKib) << "replay's peak RSS grows with the frame count: " << short_kib << " KiB at "
                                              << kShortFrames << " frames, " << long_kib << " KiB at " << kLongFrames;
}

// `nbsim trace verify` and `nbsim trace info` (text and JSON) stream as well.
TEST_F(ReplayMemoryTest, VerifyAndInfoPeaksDoNotGrowWithFrames) {
  for (const char* command : {"trace verify", "trace info", "trace info --json"}) {
    const auto [short_kib, long_kib] = peaks(command);
    ASSERT_GT(short_kib, 0) << command << " failed";
    ASSERT_GT(long_kib, 0) << command << " failed";
    EXPECT_LT(long_kib - short_kib, kBoundKib) << command << "'s peak RSS grows with the frame count: " << short_kib
                                                << " KiB at " << kShortFrames << " frames, " << long_kib << " KiB at "
                                                << kLongFrames;
  }
}

}  // namespace
