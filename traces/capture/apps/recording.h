// Reading the interposer's recording (traces/apitrace/raw.h) back, one frame at a time: every
// record checked against the layout (sizes, enum values, draw and frame order, finite positions
// are not required: a draw with a NaN position is kept and flagged by the model), and an
// InputError naming the file, the byte offset and the problem for anything else. A recording
// without its end marker is refused: the replay that wrote it stopped early.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "traces/apitrace/raw.h"

namespace nbsim::apitrace {

struct RawDraw {
  DrawHead head{};
  std::vector<std::array<float, 4>> positions;  // clip x, y, z, w; three a triangle, two a line, one a point
  // The depth the draw changed, when the interposer recorded it (raw.h DeltaHead).
  bool has_delta = false;
  DeltaHead delta{};
  std::vector<std::uint32_t> delta_pixels;
  std::vector<float> delta_depths;
};

struct RawUnhandled {
  std::string name;
  std::uint32_t first_draw = 0, count = 0;
};

struct RawFrame {
  std::uint32_t frame = 0;
  std::vector<RawDraw> draws;         // draws[i].head.index == i
  std::vector<ClearHead> clears;      // in call order (index: the next draw's)
  std::vector<RawUnhandled> unhandled;
  FrameHead end{};
  std::vector<float> depth;           // end.width * end.height when end.has_depth
};

class RawReader {
 public:
  // Opens the recording and checks its head. InputError when it cannot be read or is not one.
  explicit RawReader(const std::filesystem::path& file);
  ~RawReader();
  RawReader(const RawReader&) = delete;
  RawReader& operator=(const RawReader&) = delete;

  const FileHead& head() const noexcept { return head_; }
  const std::vector<std::string>& notes() const noexcept { return notes_; }
  // The next frame, or nullopt after the last (the end marker read). InputError on damage.
  std::optional<RawFrame> next();

 private:
  [[noreturn]] void fail(const std::string& what) const;
  bool read_bytes(void* out, std::size_t n);
  void read_exact(void* out, std::size_t n, const char* what);

  std::string name_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  FileHead head_{};
  std::vector<std::string> notes_;
  bool ended_ = false;
  std::optional<std::uint32_t> last_frame_;
};

}  // namespace nbsim::apitrace
