// `nbsim info`: versions of nbsim and of every library it runs on, and (with --gl) the headless GL
// renderer Mesa gives us. The first thing to attach to a bug report.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <zstd.h>
#include <zlib.h>

#include <systemc>

#include "pipeline/cli/command.h"
#include "model/common/error.h"
#include "io/image_io.h"
#include "traces/gl/context.h"

#include <glm/detail/setup.hpp>

namespace nbsim::cli {

void add_info_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("info", "Print nbsim's version and the versions of its libraries (JSON)");
  auto gl = std::make_shared<bool>(false);
  cmd->add_flag("--gl", *gl, "Also create a headless GL context on Mesa and report its renderer");
  cmd->callback([&action, gl] {
    action = [gl] {
      nlohmann::ordered_json j;
      j["nbsim"] = NBSIM_VERSION;
      j["systemc"] = sc_core::sc_release();
      try {
        j["openimageio"] = io::openimageio_version();
      } catch (const InputError& e) {
        j["openimageio"] = std::string("unavailable: ") + e.what();
      }
      j["fmt"] = fmt::format("{}.{}.{}", FMT_VERSION / 10000, FMT_VERSION / 100 % 100, FMT_VERSION % 100);
      j["nlohmann_json"] = fmt::format("{}.{}.{}", NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR,
                                       NLOHMANN_JSON_VERSION_PATCH);
      j["glm"] = fmt::format("0.{}.{}.{}", GLM_VERSION / 100 % 10, GLM_VERSION / 10 % 10, GLM_VERSION % 10);
      j["zstd"] = ZSTD_versionString();
      j["zlib"] = zlibVersion();
      j["compiler"] = __VERSION__;
      if (*gl) {
        const gl::Context ctx;
        j["gl_vendor"] = ctx.info().vendor;
        j["gl_renderer"] = ctx.info().renderer;
        j["gl_version"] = ctx.info().version;
        j["glsl_version"] = ctx.info().glsl_version;
        j["egl_version"] = ctx.info().egl_version;
      }
      fmt::print("{}\n", j.dump(2));
      return 0;
    };
  });
}

}  // namespace nbsim::cli
