// NBufferCliTest: `nbsim nbuffer ...` exit statuses and messages.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>

namespace {

struct CliResult {
  int status = -1;
  std::string out;  // stdout and stderr together
};

CliResult nbsim(const std::string& args) {
  CliResult r;
  const std::string cmd = std::string(NBSIM_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

// --help works on the nbuffer query command and exits 0.
TEST(NBufferCliTest, HelpExitsZero) {
  const CliResult r = nbsim("nbuffer query --help");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--rect"), std::string::npos) << r.out;
}

}  // namespace
