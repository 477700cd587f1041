// From the interposer's recording (recording.h) to an nbsim trace of technique apps: per recorded
// frame, a FrameBegin (no camera: a program's matrices are its own), every draw call as a DRAW
// record of role app_draw (clip positions of captured triangles; depth, cull and stencil state;
// GL's samples passed; the discard and fragment-depth flags the interposer found in the fragment
// shader's source), the frame's AppDraws, AppClears and AppFrame records, an AppDepthChange record
// for every draw the interposer recorded one for, and the depth image "final" of the render target
// the frame's draws passed the most samples in. Written under a temporary name and renamed when
// whole: a failure leaves no trace behind.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>

#include "model/scene/frame.h"
#include "traces/capture/apps/recording.h"

namespace nbsim::apitrace {

// One recorded frame as the trace stores it (the records above, in that order). Moves the frame's
// positions and depth.
scene::Frame to_frame(RawFrame&& f);

// The header's depth_format for a depth buffer of `bits` (float or not).
std::string depth_format_name(std::uint32_t bits, bool is_float);

struct ConvertOptions {
  std::string apitrace;      // the apitrace trace's file name (header "apitrace")
  std::string command_line;  // the command that recorded it (header "command_line")
};

struct ConvertSummary {
  std::uint32_t frames = 0;
  std::uint64_t draws = 0, captured = 0, vertices = 0, depth_changes = 0, clears = 0, bytes = 0;
  std::array<std::uint64_t, 7> skipped{};    // draws by raw.h Skip (index 0: captured)
  std::map<std::string, std::uint64_t> unhandled;  // GL features met and not captured, with their counts
  std::string renderer;
};

// Throws InputError naming the recording's problem (recording.h) or the trace's (a frame above the
// format's limits).
ConvertSummary convert_recording(const std::filesystem::path& recording, const std::filesystem::path& out, const ConvertOptions& options,
                                 const std::function<void(std::uint32_t frames)>& progress = {});

}  // namespace nbsim::apitrace
