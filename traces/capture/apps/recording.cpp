// Reading the interposer's recording; see recording.h.
#include "traces/capture/apps/recording.h"

#include <fmt/format.h>

#include <cstring>
#include <system_error>

#include "model/common/error.h"

namespace nbsim::apitrace {

namespace {

constexpr std::int32_t kMaxSide = 16384;  // the trace format's viewport limit

std::uint32_t vertices_per(std::uint32_t primitive) {
  switch (primitive) {
    case 0x0000: return 1;  // GL_POINTS
    case 0x0001: return 2;  // GL_LINES
    case 0x0004: return 3;  // GL_TRIANGLES
    default: return 0;
  }
}

bool side_ok(std::int32_t v) { return v >= 0 && v <= kMaxSide; }

}  // namespace

RawReader::RawReader(const std::filesystem::path& file) : name_(file.string()) {
  file_ = std::fopen(name_.c_str(), "rb");
  if (!file_) throw InputError(fmt::format("cannot read the recording '{}'", name_));
  try {  // a constructor that throws runs no destructor: the file is closed here
    if (!read_bytes(&head_, sizeof head_) || std::memcmp(head_.magic, kRawMagic, sizeof head_.magic) != 0)
      fail("not an nbsim interposer recording (no NBSIMIP1 head)");
    if (head_.version != kRawVersion) fail(fmt::format("recording version {}, this nbsim reads version {}", head_.version, kRawVersion));
    if (head_.first_frame > head_.last_frame) fail(fmt::format("frame range {}:{} is empty", head_.first_frame, head_.last_frame));
  } catch (...) {
    std::fclose(file_);
    file_ = nullptr;
    throw;
  }
}

RawReader::~RawReader() {
  if (file_) std::fclose(file_);
}

void RawReader::fail(const std::string& what) const {
  throw InputError(fmt::format("recording '{}', byte {}: {}", name_, offset_, what));
}

bool RawReader::read_bytes(void* out, std::size_t n) {
  if (n == 0) return true;
  const std::size_t got = std::fread(out, 1, n, file_);
  offset_ += got;
  return got == n;
}

void RawReader::read_exact(void* out, std::size_t n, const char* what) {
  if (!read_bytes(out, n)) fail(fmt::format("the file ends inside a {} record", what));
}

std::optional<RawFrame> RawReader::next() {
  if (ended_) return std::nullopt;
  RawFrame f;
  bool started = false;
  const auto begin = [&](std::uint32_t frame, const char* what) {
    if (!started) {
      if (last_frame_ && frame <= *last_frame_) fail(fmt::format("a {} record of frame {} after frame {}", what, frame, *last_frame_));
      if (frame < head_.first_frame || frame > head_.last_frame)
        fail(fmt::format("a {} record of frame {}, outside the recorded frames {}:{}", what, frame, head_.first_frame, head_.last_frame));
      f.frame = frame;
      started = true;
    } else if (frame != f.frame) {
      fail(fmt::format("a {} record of frame {} inside frame {}", what, frame, f.frame));
    }
  };
  for (;;) {
    RecordHead r{};
    if (!read_bytes(&r, sizeof r)) {
      if (std::feof(file_))
        fail("the recording ends before its end marker: the replay that wrote it stopped early (crashed, killed or out of disk)");
      fail("read error");
    }
    switch (static_cast<RawType>(r.type)) {
      case RawType::Draw: {
        RawDraw d;
        if (r.bytes < sizeof d.head) fail(fmt::format("a draw record of {} bytes, shorter than its head", r.bytes));
        read_exact(&d.head, sizeof d.head, "draw");
        begin(d.head.frame, "draw");
        if (d.head.index != f.draws.size()) fail(fmt::format("frame {}: draw {} where draw {} comes next", f.frame, d.head.index, f.draws.size()));
        if (d.head.call >= static_cast<std::uint32_t>(DrawCall::Count)) fail(fmt::format("frame {}, draw {}: unknown draw call {}", f.frame, d.head.index, d.head.call));
        if (d.head.skipped > static_cast<std::uint32_t>(Skip::Indirect))
          fail(fmt::format("frame {}, draw {}: unknown skip reason {}", f.frame, d.head.index, d.head.skipped));
        const std::uint64_t expect = sizeof d.head + 16ull * d.head.vertices;
        if (r.bytes != expect) fail(fmt::format("frame {}, draw {}: {} bytes for {} vertices (expected {})", f.frame, d.head.index, r.bytes, d.head.vertices, expect));
        if (d.head.vertices > 0) {
          const std::uint32_t per = vertices_per(d.head.primitive);
          if (per == 0 || d.head.vertices % per != 0 || d.head.skipped != 0)
            fail(fmt::format("frame {}, draw {}: {} vertices of primitive 0x{:x}", f.frame, d.head.index, d.head.vertices, d.head.primitive));
        }
        if (!side_ok(d.head.target_width) || !side_ok(d.head.target_height))
          fail(fmt::format("frame {}, draw {}: render target {}x{}", f.frame, d.head.index, d.head.target_width, d.head.target_height));
        d.positions.resize(d.head.vertices);
        read_exact(d.positions.data(), 16ull * d.head.vertices, "draw");
        f.draws.push_back(std::move(d));
        break;
      }
      case RawType::Delta: {
        DeltaHead h{};
        if (r.bytes < sizeof h) fail(fmt::format("a depth change record of {} bytes, shorter than its head", r.bytes));
        read_exact(&h, sizeof h, "depth change");
        begin(h.frame, "depth change");
        if (f.draws.empty() || h.index + 1 != f.draws.size() || f.draws.back().has_delta)
          fail(fmt::format("frame {}: a depth change of draw {} that does not follow it", f.frame, h.index));
        if (h.width <= 0 || h.height <= 0 || !side_ok(h.width) || !side_ok(h.height))
          fail(fmt::format("frame {}, draw {}: a depth change of a {}x{} target", f.frame, h.index, h.width, h.height));
        const std::uint64_t area = static_cast<std::uint64_t>(h.width) * static_cast<std::uint64_t>(h.height);
        if (h.pixels > area || r.bytes != sizeof h + 8ull * h.pixels)
          fail(fmt::format("frame {}, draw {}: a depth change of {} pixels in {} bytes", f.frame, h.index, h.pixels, r.bytes));
        RawDraw& d = f.draws.back();
        d.has_delta = true;
        d.delta = h;
        d.delta_pixels.resize(h.pixels);
        d.delta_depths.resize(h.pixels);
        read_exact(d.delta_pixels.data(), 4ull * h.pixels, "depth change");
        read_exact(d.delta_depths.data(), 4ull * h.pixels, "depth change");
        for (std::size_t i = 0; i < d.delta_pixels.size(); ++i) {
          if (d.delta_pixels[i] >= area || (i > 0 && d.delta_pixels[i] <= d.delta_pixels[i - 1]))
            fail(fmt::format("frame {}, draw {}: depth change pixel {} out of order or outside the target", f.frame, h.index, d.delta_pixels[i]));
        }
        break;
      }
      case RawType::Clear: {
        ClearHead c{};
        if (r.bytes != sizeof c) fail(fmt::format("a clear record of {} bytes (expected {})", r.bytes, sizeof c));
        read_exact(&c, sizeof c, "clear");
        begin(c.frame, "clear");
        if (c.index != f.draws.size()) fail(fmt::format("frame {}: a clear before draw {} after {} draws", f.frame, c.index, f.draws.size()));
        if (c.buffers == 0 || (c.buffers & ~3u) != 0) fail(fmt::format("frame {}: a clear of buffers {}", f.frame, c.buffers));
        f.clears.push_back(c);
        break;
      }
      case RawType::Unhandled: {
        UnhandledHead u{};
        if (r.bytes < sizeof u) fail(fmt::format("an unhandled-feature record of {} bytes", r.bytes));
        read_exact(&u, sizeof u, "unhandled feature");
        begin(u.frame, "unhandled feature");
        if (u.name_bytes > 256 || r.bytes != sizeof u + u.name_bytes) fail("an unhandled-feature record whose name does not fit");
        RawUnhandled x;
        x.name.resize(u.name_bytes);
        read_exact(x.name.data(), u.name_bytes, "unhandled feature");
        x.first_draw = u.index;
        x.count = u.count;
        f.unhandled.push_back(std::move(x));
        break;
      }
      case RawType::Note: {
        if (r.bytes > 4096) fail(fmt::format("a note of {} bytes", r.bytes));
        std::string text(r.bytes, '\0');
        read_exact(text.data(), r.bytes, "note");
        notes_.push_back(std::move(text));
        break;
      }
      case RawType::Frame: {
        FrameHead h{};
        if (r.bytes < sizeof h) fail(fmt::format("a frame record of {} bytes, shorter than its head", r.bytes));
        read_exact(&h, sizeof h, "frame");
        begin(h.frame, "frame");
        if (h.draws != f.draws.size()) fail(fmt::format("frame {} ends after {} draws, but {} were recorded", f.frame, h.draws, f.draws.size()));
        if (!side_ok(h.width) || !side_ok(h.height)) fail(fmt::format("frame {}: a {}x{} render target", f.frame, h.width, h.height));
        const std::uint64_t pixels = h.has_depth ? static_cast<std::uint64_t>(h.width) * static_cast<std::uint64_t>(h.height) : 0;
        if (h.has_depth > 1 || r.bytes != sizeof h + 4 * pixels)
          fail(fmt::format("frame {}: a frame record of {} bytes for a {}x{} depth image", f.frame, r.bytes, h.width, h.height));
        f.end = h;
        f.depth.resize(pixels);
        read_exact(f.depth.data(), 4 * pixels, "frame");
        last_frame_ = f.frame;
        return f;
      }
      case RawType::End: {
        if (r.bytes != 0) fail("an end marker with a payload");
        if (started) fail(fmt::format("the recording ends inside frame {}", f.frame));
        ended_ = true;
        return std::nullopt;
      }
      default: fail(fmt::format("unknown record type {}", r.type));
    }
  }
}

}  // namespace nbsim::apitrace
