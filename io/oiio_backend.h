// The boundary between nbsim and its OpenImageIO backend, libnbsim_oiio.so.
//
// Debian's OpenImageIO pulls in about 260 shared libraries (OpenCV, GDCM, FFmpeg, ...), and loading
// them costs about 0.37 s at every process start, against 0.01 s without them. Most nbsim runs (a
// replay, and every child replay of `nbsim explore` and `nbsim table2`) read and write no image, so
// the `nbsim` executable does not link OpenImageIO: image_io.cpp loads this backend with dlopen the
// first time an image is read or written. The boundary carries plain buffers and strings only, no
// exceptions: a call returns "" on success, or the message.
#pragma once

#include <string>
#include <vector>

namespace nbsim::io::backend {

inline constexpr int kAbiVersion = 1;

// The largest depth image read (docs/limits.md), checked against the file's header before any
// pixel is allocated: a side of at most 16384 pixels (the trace format's image limit) and at most
// 4096 x 4096 pixels in all (64 MiB of floats; `nbsim capture` renders at most 4096x4096). Tunable.
inline constexpr long long kMaxDepthSide = 16384;
inline constexpr long long kMaxDepthPixels = 4096LL * 4096LL;

// An image as the file holds it: rows top-down, channels interleaved, as floats.
struct FloatImage {
  int width = 0;
  int height = 0;
  int depth = 1;     // > 1: a volume, which nbsim refuses
  int channels = 0;
  std::vector<float> pixels;  // read only for a 2D single-channel image; empty otherwise
};

enum class PixelType : int { Float = 0, UInt16 = 1, UInt8 = 2 };

struct Table {
  int abi = kAbiVersion;
  const char* openimageio_version = "";
  // Opens `path`, fills `image`; reads the pixels when the image is 2D with one channel, within
  // kMaxDepthSide and kMaxDepthPixels, and (an uncompressed PFM) the file holds all of them.
  // Every refusal says why.
  std::string (*read)(const std::string& path, FloatImage& image) = nullptr;
  // Writes top-down `data` (width x height x channels of `type`); `depth_channel` names the single
  // channel "Z" and asks for zip compression (EXR).
  std::string (*write)(const std::string& path, int width, int height, int channels, PixelType type, const void* data,
                       bool depth_channel) = nullptr;
};

}  // namespace nbsim::io::backend

// The backend's one exported symbol.
extern "C" const nbsim::io::backend::Table* nbsim_image_io_backend();
