// nbsim: the one command-line entry point. Wires the subcommand modules and maps failures to exit
// statuses (0 success, 2 bad usage or bad input, 1 other failures).
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string_view>
#include <vector>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "pipeline/cli/command.h"
#include "io/output_folder.h"

namespace nbsim::cli {

namespace {

bool parse_int(std::string_view s, int& out) {
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, out);
  return ec == std::errc() && p == end && !s.empty();
}

// When parsing fails because a command needs a subcommand, name the word that was not one
// (CLI11 only says "A subcommand is required").
std::string unknown_subcommand(CLI::App& app, int argc, char** argv) {
  CLI::App* cur = &app;
  std::string path = app.get_name();
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.empty() || arg[0] == '-') continue;
    const auto subs = cur->get_subcommands([&](CLI::App* a) { return a->get_name() == arg; });
    if (!subs.empty()) {
      cur = subs.front();
      path += " " + arg;
      continue;
    }
    if (cur->get_require_subcommand_min() == 0) return {};
    std::string names;
    for (CLI::App* a : cur->get_subcommands([](CLI::App*) { return true; })) names += (names.empty() ? "" : ", ") + a->get_name();
    return fmt::format("unknown command '{}' for '{}'; expected one of: {}", arg, path, names);
  }
  return {};
}

}  // namespace

Rect parse_rect(const std::string& text) {
  std::vector<std::string_view> parts;
  std::string_view rest(text);
  for (std::size_t comma; (comma = rest.find(',')) != std::string_view::npos; rest.remove_prefix(comma + 1))
    parts.push_back(rest.substr(0, comma));
  parts.push_back(rest);
  int v[4] = {};
  if (parts.size() != 4 || !parse_int(parts[0], v[0]) || !parse_int(parts[1], v[1]) || !parse_int(parts[2], v[2]) ||
      !parse_int(parts[3], v[3]))
    throw InputError(fmt::format("bad rectangle '{}': expected X,Y,W,H with four integers", text));
  if (v[2] < 1 || v[3] < 1)
    throw InputError(fmt::format("empty rectangle '{}': width and height must be at least 1", text));
  return {v[0], v[1], v[2], v[3]};
}

std::pair<int, int> parse_size(const std::string& text, const std::string& option) {
  const auto x = text.find('x');
  int w = 0, h = 0;
  if (x == std::string::npos || !parse_int(std::string_view(text).substr(0, x), w) ||
      !parse_int(std::string_view(text).substr(x + 1), h) || w < 1 || h < 1)
    throw InputError(fmt::format("bad {} '{}': expected WxH with positive integers, e.g. 512x512", option, text));
  return {w, h};
}

double tidy(float v) {
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  *p = '\0';
  return std::strtod(buf, nullptr);
}

}  // namespace nbsim::cli

int main(int argc, char** argv) {
  using namespace nbsim;
  CLI::App app{"nbsim: a cycle-approximate GPU pipeline model with an N-buffer depth-query unit", "nbsim"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "nbsim " NBSIM_VERSION);
  cli::Action action;
  cli::add_nbuffer_commands(app, action);
  cli::add_bench_commands(app, action);
  cli::add_info_command(app, action);
  cli::add_capture_command(app, action);
  cli::add_model_commands(app, action);
  cli::add_explore_command(app, action);
  cli::add_report_command(app, action);
  // Each technique's own commands (pipeline/techniques/<name>/), in the registration list's order.
#define NBSIM_TECHNIQUE_COMMANDS(name) cli::add_##name##_commands(app, action);
  NBSIM_EACH_TECHNIQUE(NBSIM_TECHNIQUE_COMMANDS)
#undef NBSIM_TECHNIQUE_COMMANDS
  cli::add_trace_commands(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (const std::string what = cli::unknown_subcommand(app, argc, argv); !what.empty()) {
      std::fprintf(stderr, "nbsim: error: %s\nRun with --help for more information.\n", what.c_str());
      return 2;
    }
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "nbsim: error: %s\n", e.what());
    return 2;
  }
  // A refused or failed command removes the output folders it created (io/output_folder.h);
  // exit 1 from the command itself is a result (counters that differ, sweep points that failed)
  // and keeps them.
  const auto failed = [](int status) {
    io::remove_created_output_folders();
    return status;
  };
  try {
    const int status = action ? action() : 0;
    return status == 2 ? failed(status) : status;
  } catch (const InputError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "nbsim: error: %s\n", e.what());
    return failed(2);
  } catch (const nlohmann::json::exception& e) {
    // The JSON nbsim reads is the user's (configs, sweeps, run outputs given back to it): a value
    // the JSON library refuses is bad input, never an internal failure. The message is cut.
    std::fflush(stdout);
    std::fprintf(stderr, "nbsim: error: bad JSON input: %s\n", nbsim::config::excerpt_text(e.what(), 400).c_str());
    return failed(2);
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "nbsim: failed: %s\n", e.what());
    return failed(1);
  }
}
