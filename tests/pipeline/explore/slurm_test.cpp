// SlurmPiecesTest: the parts of the Slurm engine that need no cluster: squeue lines, final states,
// the array spec, sbatch's answer, shell quoting and the batch script each array task runs (run
// with sh, an array task id and `echo` standing in for nbsim). slurm_cli_test.cpp runs the whole
// engine against a real one-node cluster.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "pipeline/explore/slurm.h"
#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::shell_output;
using namespace nbsim::explore;


TEST(SlurmPiecesTest, SqueueLines) {
  auto s = parse_squeue_line("1234_17 RUNNING None");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->job, "1234");
  EXPECT_EQ(s->task, 17u);
  EXPECT_EQ(s->state, "RUNNING");
  EXPECT_EQ(s->reason, "None");
  s = parse_squeue_line("9_0 PENDING JobArrayTaskLimit");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->reason, "JobArrayTaskLimit");
  s = parse_squeue_line("9_3 CANCELLED by 0 None");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->state, "CANCELLED");
  for (const char* bad : {"", "1234 RUNNING None", "1234_[0-9%2] PENDING None", "_3 RUNNING", "12_x RUNNING", "12_", "12_3",
                          "12_99999999999999999999 RUNNING None"})
    EXPECT_FALSE(parse_squeue_line(bad)) << bad;
}

TEST(SlurmPiecesTest, FinalStates) {
  for (const char* s : {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "OUT_OF_MEMORY", "NODE_FAIL", "PREEMPTED", "CANCELLED by 0"})
    EXPECT_TRUE(is_final_state(s)) << s;
  for (const char* s : {"PENDING", "RUNNING", "COMPLETING", "CONFIGURING", "SUSPENDED", "REQUEUED", ""})
    EXPECT_FALSE(is_final_state(s)) << s;
}

TEST(SlurmPiecesTest, ArraySpecAndSbatchAnswer) {
  EXPECT_EQ(array_spec(1, 0), "0-0");
  EXPECT_EQ(array_spec(12, 0), "0-11");
  EXPECT_EQ(array_spec(12, 3), "0-11%3");
  EXPECT_EQ(parse_sbatch_id("4711\n"), "4711");
  EXPECT_EQ(parse_sbatch_id("4711;cluster\n"), "4711");
  EXPECT_EQ(parse_sbatch_id(""), "");
  EXPECT_EQ(parse_sbatch_id("sbatch: error: invalid partition"), "");
}

// Quoted text comes back unchanged through sh, whatever it holds.
TEST(SlurmPiecesTest, ShellQuoteRoundTrips) {
  for (const std::string text : {"plain", "two words", "it's", "''", "$HOME `id` \\ \" ; & | *", "/path/with spaces/x.nbt", ""})
    EXPECT_EQ(shell_output("printf %s " + shell_quote(text)), text) << text;
}

// The batch script picks line offset + task id + 1 of the task list and passes the point's id,
// the absolute paths and the extra arguments; a task beyond the list fails with a message.
TEST(SlurmPiecesTest, BatchScriptPicksItsPoint) {
  const fs::path dir = nbsim::testing::scratch_dir("nbsim_slurm_pieces");
  fs::create_directories(dir / "a dir");
  const fs::path tasks = dir / "a dir" / "x.tasks", script = dir / "x.sh";
  std::ofstream(tasks) << "aaaa\nbbbb\ncccc\ndddd\n";
  std::ofstream(script) << batch_script(tasks, "/bin/echo", dir / "sweep's.json", dir / "out", {"--max-points", "7"});
  EXPECT_EQ(shell_output("SLURM_ARRAY_TASK_ID=1 sh " + shell_quote(script.string()) + " 2"),
            "explore " + (dir / "sweep's.json").string() + " --out " + (dir / "out").string() + " --point dddd --max-points 7\n");
  EXPECT_EQ(shell_output("SLURM_ARRAY_TASK_ID=0 sh " + shell_quote(script.string()) + " 0 2>&1"),
            "explore " + (dir / "sweep's.json").string() + " --out " + (dir / "out").string() + " --point aaaa --max-points 7\n");
  EXPECT_NE(shell_output("SLURM_ARRAY_TASK_ID=4 sh " + shell_quote(script.string()) + " 0 2>&1; echo status=$?").find("no point on line 5"),
            std::string::npos);
  EXPECT_NE(shell_output("sh " + shell_quote(script.string()) + " 0 2>&1; echo status=$?").find("not a Slurm array task"), std::string::npos);
  fs::remove_all(dir);
}

TEST(SlurmPiecesTest, NodeLocalPathsNoted) {
  if (fs::exists("/dev/shm")) {
    const auto notes = node_local_paths({"/dev/shm"});
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("tmpfs"), std::string::npos) << notes[0];
  }
  EXPECT_TRUE(node_local_paths({"/nonexistent/path"}).empty()) << "a path that cannot be looked at gives no note";
}

}  // namespace
