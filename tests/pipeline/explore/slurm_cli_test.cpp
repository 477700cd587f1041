// SlurmCliTest: `nbsim explore --engine slurm` against a real one-node Slurm cluster (munged,
// slurmctld, slurmd started by the CTest fixture SlurmCluster: scripts/slurm-cluster, SLURM_CONF
// in the environment). A sweep's merged results equal a local run's (host time aside) and resume
// across engines; a failing point is recorded with the replay's own message; Ctrl-C cancels the
// array and records the cancelled tasks; a task cancelled from outside is recorded; a controller
// that dies mid-run ends the wait after --cluster-timeout with the tasks recorded, and a later run
// finishes them; no sbatch, a controller that does not answer, an SLURM_CONF that does not parse
// and a partition sbatch refuses exit 2 before anything runs.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <netinet/in.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "tests/common/run_nbsim.h"
#include "tests/pipeline/explore/read_csv.h"

extern "C" char** environ;

namespace {

namespace fs = std::filesystem;
using nbsim::testing::shell_output;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::read_csv;
using nbsim::testing::run_nbsim;
using nbsim::testing::run_nbsim_env;

const std::string kSample = (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string();

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_slurm", name); }

fs::path write_sweep(const std::string& name, const nlohmann::json& j) {
  const fs::path f = scratch(name);
  std::ofstream(f) << j.dump(2);
  return f;
}

std::string slurm_conf() {
  const char* c = std::getenv("SLURM_CONF");
  return c ? c : "";
}

// Every test needs the fixture's cluster: say so plainly when it is missing.
class SlurmCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(slurm_conf().empty()) << "SLURM_CONF is not set: run these tests through ctest (fixture SlurmCluster)";
    ASSERT_TRUE(fs::exists(slurm_conf())) << slurm_conf();
  }
};

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  return {std::istreambuf_iterator<char>(in), {}};
}


// The array job ids one explore run submitted (OUT/slurm/*.jobs).
std::vector<std::string> submitted_jobs(const fs::path& out) {
  std::vector<std::string> jobs;
  if (!fs::exists(out / "slurm")) return jobs;
  for (const auto& e : fs::directory_iterator(out / "slurm"))
    if (e.path().extension() == ".jobs") {
      std::ifstream in(e.path());
      for (std::string line; std::getline(in, line);)
        if (!line.empty()) jobs.push_back(line);
    }
  return jobs;
}

// results.csv without the columns that measure the host's time.
std::vector<std::map<std::string, std::string>> rows_without_host_time(const fs::path& csv) {
  auto rows = read_csv(csv);
  for (auto& r : rows) {
    r.erase("host_seconds");
    r.erase("cycles_per_host_second");
  }
  return rows;
}

// `nbsim explore ...` started in the background, its output in files.
struct Background {
  pid_t pid = -1;
  fs::path out_file, err_file;

  explicit Background(const std::vector<std::string>& args, const std::string& name) {
    out_file = scratch(name + ".stdout"), err_file = scratch(name + ".stderr");
    std::vector<std::string> argv = {NBSIM_EXE};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (posix_spawn(&pid, NBSIM_EXE, &fa, nullptr, cargv.data(), environ) != 0) pid = -1;
    posix_spawn_file_actions_destroy(&fa);
  }
  // The exit status, or -1 when it did not end within `seconds` (it is then killed).
  int wait(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    int status = 0;
    while (std::chrono::steady_clock::now() < end) {
      if (waitpid(pid, &status, WNOHANG) == pid) {
        pid = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    pid = -1;
    return -1;
  }
  ~Background() {
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
};

template <class Pred>
bool wait_until(Pred pred, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return pred();
}

// The states squeue lists for a job's tasks that have not ended ("" when none).
std::string active_tasks(const std::string& job) {
  const std::string all = shell_output("squeue -h -t all -r -j " + job + " -o '%i %T' 2>/dev/null");
  std::string active;
  std::istringstream in(all);
  for (std::string line; std::getline(in, line);)
    if (has(line, "PENDING") || has(line, "RUNNING") || has(line, "COMPLETING") || has(line, "CONFIGURING")) active += line + "\n";
  return active;
}

// The sample sweep through the cluster: the same rows and values as a local run, host time aside;
// resume works across engines both ways.
TEST_F(SlurmCliTest, SweepEqualsLocalRun) {
  nlohmann::json sweep = {{"traces", {kSample}}, {"axes", nlohmann::json::object()}};
  sweep["axes"]["cull.mode"] = {"nb", "nb_hier"};
  sweep["axes"]["nbuffer.format"] = {"f32", "u16"};
  sweep["axes"]["nbuffer.resolution_divisor"] = {1, 2};
  const fs::path f = write_sweep("equal.json", sweep);
  const fs::path slurm_out = scratch("equal_slurm"), local_out = scratch("equal_local");
  CliResult r = run_nbsim("explore " + f.string() + " --out " + slurm_out.string() + " --engine slurm --poll-seconds 0.3");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "8 points (0 of them references): 8 run, 0 resumed, 0 failed")) << r.out;
  // The test cluster's MaxArraySize is 5: eight points are two arrays, of five and three tasks.
  EXPECT_TRUE(has(r.out, "on Slurm (array jobs ")) << r.out;
  ASSERT_EQ(submitted_jobs(slurm_out).size(), 2u);
  r = run_nbsim("explore " + f.string() + " --out " + local_out.string() + " --jobs 2");
  ASSERT_EQ(r.status, 0) << r.out << r.err;

  const auto a = rows_without_host_time(slurm_out / "results.csv"), b = rows_without_host_time(local_out / "results.csv");
  ASSERT_EQ(a.size(), 8u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].at("status"), "ok") << a[i].at("error");
    EXPECT_EQ(a[i], b[i]) << "row " << i << " differs between the Slurm and the local run";
  }
  // Each task's log is kept beside the points.
  EXPECT_TRUE(has(read_text(slurm_out / "slurm" / (submitted_jobs(slurm_out)[0] + "_0.out")), "ran; wrote")) << "task log";

  // Resume: nothing is submitted again, and the local engine takes the Slurm run's points as done.
  r = run_nbsim("explore " + f.string() + " --out " + slurm_out.string() + " --engine slurm --poll-seconds 0.3");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "0 run, 8 resumed, 0 failed")) << r.out;
  EXPECT_TRUE(has(r.out, "nothing to submit")) << r.out;
  r = run_nbsim("explore " + f.string() + " --out " + slurm_out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "0 run, 8 resumed, 0 failed")) << r.out;
  // And the other way: a point dropped from the local folder is the only one the cluster runs.
  fs::remove_all(local_out / "points" / b[3].at("point_id"));
  r = run_nbsim("explore " + f.string() + " --out " + local_out.string() + " --engine slurm --poll-seconds 0.3");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "1 run, 7 resumed, 0 failed")) << r.out;
  EXPECT_EQ(rows_without_host_time(local_out / "results.csv"), a);
}

// The front search through the cluster: each round is an array of its points; it runs the same
// points as the local search and gives the same rows.
TEST_F(SlurmCliTest, FrontSearchEqualsLocal) {
  nlohmann::json sweep = {{"traces", {kSample}}, {"set", {{"cull.mode", "nb_hier"}}}, {"axes", nlohmann::json::object()}};
  sweep["axes"]["nbuffer.resolution_divisor"] = {1, 2, 4};
  sweep["axes"]["nbuffer.update_policy"] = {"eager", "on_demand"};
  const fs::path f = write_sweep("front.json", sweep);
  const fs::path slurm_out = scratch("front_slurm"), local_out = scratch("front_local");
  CliResult r = run_nbsim("explore " + f.string() + " --out " + slurm_out.string() +
                          " --engine slurm --poll-seconds 0.3 --search front --search-start 2");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "front search: ")) << r.out;
  r = run_nbsim("explore " + f.string() + " --out " + local_out.string() + " --jobs 2 --search front --search-start 2");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(rows_without_host_time(slurm_out / "results.csv"), rows_without_host_time(local_out / "results.csv"));
}

// A point whose replay fails on the node is recorded with the replay's own message, as a local
// run records it; the other point completes; exit status 1.
TEST_F(SlurmCliTest, FailingPointRecorded) {
  const fs::path corrupt = scratch("corrupt.nbt");
  fs::copy_file(kSample, corrupt, fs::copy_options::overwrite_existing);
  fs::resize_file(corrupt, fs::file_size(corrupt) / 2);
  const nlohmann::json sweep = {{"traces", {kSample, corrupt.string()}},
                                {"points", {{{"cull.mode", "nb_hier"}, {"trace", kSample}}, {{"cull.mode", "nb_hier"}, {"trace", corrupt.string()}}}}};
  const fs::path f = write_sweep("failing.json", sweep);
  const fs::path slurm_out = scratch("failing_slurm"), local_out = scratch("failing_local");
  CliResult r = run_nbsim("explore " + f.string() + " --out " + slurm_out.string() + " --engine slurm --poll-seconds 0.3");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "2 points (0 of them references): 2 run, 0 resumed, 1 failed")) << r.out;
  EXPECT_TRUE(has(r.out, "failed: ")) << r.out;
  r = run_nbsim("explore " + f.string() + " --out " + local_out.string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const auto a = rows_without_host_time(slurm_out / "results.csv"), b = rows_without_host_time(local_out / "results.csv");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].at("status"), "ok");
  EXPECT_EQ(a[1].at("status"), "failed");
  EXPECT_FALSE(a[1].at("error").empty());
  EXPECT_EQ(a, b) << "the failure reads as it does locally";
}

// Ctrl-C while the array runs: the array is cancelled (no task of it is left pending or running),
// the points done are kept, the others are recorded as cancelled, and the exit status is 130.
TEST_F(SlurmCliTest, CtrlCCancelsTheArray) {
  nlohmann::json sweep = {{"traces", {kSample}}, {"axes", nlohmann::json::object()}};
  sweep["axes"]["cull.mode"] = {"nb_hier"};
  sweep["axes"]["nbuffer.lookup_latency_cycles"] = {1, 2, 3, 4, 5, 6, 7, 8};
  const fs::path f = write_sweep("cancel.json", sweep), out = scratch("cancel");
  Background b({"explore", f.string(), "--out", out.string(), "--engine", "slurm", "--max-running", "1", "--poll-seconds", "0.3"},
               "cancel");
  ASSERT_GT(b.pid, 0);
  // Once the first point is done, the others are still pending behind --max-running 1.
  const bool one_done = wait_until(
      [&] {
        if (!fs::exists(out / "points")) return false;
        for (const auto& e : fs::directory_iterator(out / "points"))
          if (fs::exists(e.path() / "run.json")) return true;
        return false;
      },
      120);
  ASSERT_TRUE(one_done) << read_text(b.err_file);
  // --max-running 1 holds across the two arrays (MaxArraySize 5): the second waits for the first.
  const auto before = submitted_jobs(out);
  ASSERT_EQ(before.size(), 2u);
  EXPECT_TRUE(has(shell_output("squeue -h -j " + before[1] + " -o %E"), "afterany:" + before[0]));
  kill(b.pid, SIGINT);
  const int status = b.wait(120);
  const std::string text = read_text(b.out_file);
  EXPECT_EQ(status, 130) << text << read_text(b.err_file);
  EXPECT_TRUE(has(text, "explore: cancelled")) << text;
  const auto jobs = submitted_jobs(out);
  ASSERT_EQ(jobs.size(), 2u) << "eight points, MaxArraySize 5";
  for (const auto& job : jobs) EXPECT_EQ(active_tasks(job), "") << "scancel left tasks of array " << job;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 8u);
  int ok = 0, cancelled = 0;
  for (const auto& row : rows) {
    if (row.at("status") == "ok") ++ok;
    else if (row.at("status") == "failed" && has(row.at("error"), "cancelled")) ++cancelled;
    else ADD_FAILURE() << row.at("status") << ": " << row.at("error");
  }
  EXPECT_GE(ok, 1);
  EXPECT_GE(cancelled, 1);
  // Running again resumes: only the cancelled points run.
  const CliResult r = run_nbsim("explore " + f.string() + " --out " + out.string() + " --engine slurm --poll-seconds 0.3");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, std::to_string(8 - ok) + " run, " + std::to_string(ok) + " resumed, 0 failed")) << r.out;
}

// A task cancelled from outside (scancel by the user or an administrator) is recorded as failed
// with Slurm's state; the wait ends with exit status 1.
TEST_F(SlurmCliTest, CancelledFromOutsideRecorded) {
  const fs::path f = write_sweep("held.json", {{"traces", {kSample}}, {"axes", {{"cull.mode", {"nb", "nb_hier"}}}}});
  const fs::path out = scratch("held");
  // --hold keeps the tasks pending, so that the cancel surely comes first.
  Background b({"explore", f.string(), "--out", out.string(), "--engine", "slurm", "--sbatch-arg=--hold", "--poll-seconds", "0.3"}, "held");
  ASSERT_GT(b.pid, 0);
  ASSERT_TRUE(wait_until([&] { return !submitted_jobs(out).empty(); }, 60)) << read_text(b.err_file);
  const std::string job = submitted_jobs(out)[0];
  shell_output("scancel " + job);
  const int status = b.wait(120);
  EXPECT_EQ(status, 1) << read_text(b.out_file) << read_text(b.err_file);
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_TRUE(has(row.at("error"), "Slurm task " + job + "_")) << row.at("error");
    EXPECT_TRUE(has(row.at("error"), "ended CANCELLED")) << row.at("error");
  }
}

// A second cluster of its own (the fixture's must live on): its controller is killed while the
// tasks wait, squeue fails, and after --cluster-timeout the wait ends with exit status 1 and every
// task recorded with what happened. A later run on a live cluster runs those points and finishes.
TEST_F(SlurmCliTest, ControllerLostMidRun) {
  const fs::path cluster = scratch("lost_cluster");
  const std::string script = std::string(NBSIM_SOURCE_DIR) + "/scripts/slurm-cluster";
  const std::string started =
      shell_output("NBSIM_SLURM_MESSAGE_TIMEOUT=2 bash " + script + " start " + cluster.string() + " 2>&1; echo status=$?");
  struct StopCluster {
    std::string cmd;
    ~StopCluster() { shell_output(cmd); }
  } stop{"bash " + script + " stop " + cluster.string() + " 2>&1"};
  ASSERT_TRUE(has(started, "status=0")) << started;
  const std::string fixture_conf = slurm_conf();
  ASSERT_EQ(setenv("SLURM_CONF", (cluster / "slurm.conf").c_str(), 1), 0);

  const fs::path f = write_sweep("lost.json", {{"traces", {kSample}}, {"axes", {{"cull.mode", {"nb", "nb_hier"}}}}});
  const fs::path out = scratch("lost");
  // --hold keeps the tasks pending: the controller dies with both of them waiting.
  Background b({"explore", f.string(), "--out", out.string(), "--engine", "slurm", "--sbatch-arg=--hold", "--poll-seconds", "0.3",
                "--cluster-timeout", "2"},
               "lost");
  ASSERT_GT(b.pid, 0);
  ASSERT_TRUE(wait_until([&] { return !submitted_jobs(out).empty(); }, 60)) << read_text(b.err_file);
  const std::string pid = read_text(cluster / "slurmctld.pid");
  ASSERT_FALSE(pid.empty());
  kill(std::stoi(pid), SIGKILL);
  const int status = b.wait(120);
  const std::string text = read_text(b.out_file) + read_text(b.err_file);
  EXPECT_EQ(status, 1) << text;
  const std::string job = submitted_jobs(out)[0];
  auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u) << text;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "failed");
    EXPECT_TRUE(has(row.at("error"), "squeue did not answer for 2 s while Slurm task " + job + "_")) << row.at("error");
    EXPECT_TRUE(has(row.at("error"), "--collect")) << row.at("error");
  }

  // The fixture's cluster stands for the controller come back: the recorded points run again.
  ASSERT_EQ(setenv("SLURM_CONF", fixture_conf.c_str(), 1), 0);
  const CliResult r = run_nbsim("explore " + f.string() + " --out " + out.string() + " --engine slurm --poll-seconds 0.3");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "2 run, 0 resumed, 0 failed")) << r.out;
  rows = read_csv(out / "results.csv");
  for (const auto& row : rows) EXPECT_EQ(row.at("status"), "ok") << row.at("error");
}

// A free TCP port on the loopback (nothing listens on it once this returns).
int unused_port() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  close(s);
  return ntohs(a.sin_port);
}

// Problems with the cluster exit 2 with a message naming them, before any point runs.
TEST_F(SlurmCliTest, ClusterProblemsExit2) {
  const fs::path f = write_sweep("problems.json", {{"traces", {kSample}}, {"axes", {{"cull.mode", {"nb"}}}}});
  const fs::path garbage = scratch("garbage.conf"), down = scratch("down.conf");
  std::ofstream(garbage) << "this is = not a slurm.conf =\n";
  {
    // The cluster's own configuration with the controller on a port where nothing listens.
    std::string conf = read_text(slurm_conf());
    conf = std::regex_replace(conf, std::regex("SlurmctldPort=[0-9]+"), "SlurmctldPort=" + std::to_string(unused_port()));
    conf = std::regex_replace(conf, std::regex("MessageTimeout=[0-9]+"), "MessageTimeout=2");
    std::ofstream(down) << conf;
  }
  struct Case {
    std::string env, args, message;
  };
  const std::vector<Case> cases = {
      {"PATH=/nonexistent ", "", "'sbatch' is not in PATH"},
      {"SLURM_CONF=" + scratch("missing.conf").string() + " ", "", "SLURM_CONF names"},
      {"SLURM_CONF=" + garbage.string() + " ", "", "does not parse"},
      {"SLURM_CONF=" + down.string() + " ", "", "does not answer"},
      {"", " --partition no_such_partition", "sbatch refused the array"},
  };
  for (const auto& c : cases) {
    const fs::path out = scratch("problem_out");
    fs::remove_all(out);
    const CliResult r = run_nbsim_env(c.env, "explore " + f.string() + " --out " + out.string() + " --engine slurm" + c.args);
    EXPECT_EQ(r.status, 2) << c.env << c.args << ": " << r.out << r.err;
    EXPECT_TRUE(has(r.err, c.message)) << c.env << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out / "points") && !fs::is_empty(out / "points") &&
                 fs::exists(fs::directory_iterator(out / "points")->path() / "run.json"))
        << "nothing ran";
  }
}

}  // namespace
