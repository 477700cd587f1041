// Image reading and writing through the OpenImageIO backend, loaded on first use; see image_io.h
// and oiio_backend.h (why the backend is a separate library).
#include "io/image_io.h"

#include <dlfcn.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <string>

#include "model/common/error.h"
#include "io/oiio_backend.h"

namespace nbsim::io {

namespace {

constexpr const char* kBackendFile = "libnbsim_oiio.so";

// Where the backend may be: $NBSIM_IMAGE_IO alone when set (a file); else next to the running
// executable, then where this build put it.
std::vector<std::filesystem::path> backend_candidates() {
  std::vector<std::filesystem::path> c;
  if (const char* env = std::getenv("NBSIM_IMAGE_IO"); env && *env) return {std::filesystem::path(env)};
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) c.push_back(self.parent_path() / kBackendFile);
#ifdef NBSIM_IMAGE_IO_BUILD_PATH
  c.emplace_back(NBSIM_IMAGE_IO_BUILD_PATH);
#endif
  return c;
}

const backend::Table& load_backend() {
  static const backend::Table* table = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::string tried;
    for (const auto& path : backend_candidates()) {
      if (!std::filesystem::exists(path)) {
        tried += fmt::format("\n  {}: no such file", path.string());
        continue;
      }
      void* lib = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!lib) {
        tried += fmt::format("\n  {}: {}", path.string(), dlerror());
        continue;
      }
      const auto entry = reinterpret_cast<const backend::Table* (*)()>(dlsym(lib, "nbsim_image_io_backend"));
      const backend::Table* t = entry ? entry() : nullptr;
      if (!t || t->abi != backend::kAbiVersion) {
        tried += fmt::format("\n  {}: not an nbsim image backend of ABI {}", path.string(), backend::kAbiVersion);
        continue;
      }
      table = t;  // the library stays loaded for the life of the process
      return;
    }
    failure = fmt::format("image files need nbsim's OpenImageIO backend ({}), which could not be loaded "
                          "(NBSIM_IMAGE_IO names it; tried):{}",
                          kBackendFile, tried);
  });
  if (!table) throw InputError(failure);
  return *table;
}

template <typename T>
std::vector<T> flip_rows(const std::vector<T>& src, int width, int height, int channels) {
  std::vector<T> dst(src.size());
  const std::size_t row = static_cast<std::size_t>(width) * static_cast<std::size_t>(channels);
  for (int y = 0; y < height; ++y)
    std::copy_n(src.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y)), row,
                dst.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(height - 1 - y)));
  return dst;
}

void write(const std::filesystem::path& file, int width, int height, int channels, backend::PixelType type,
           const void* data, bool depth_channel) {
  const std::string name = file.string();
  const std::string error = load_backend().write(name, width, height, channels, type, data, depth_channel);
  if (!error.empty()) throw InputError(fmt::format("cannot write '{}': {}", name, error));
}

}  // namespace

std::string openimageio_version() { return load_backend().openimageio_version; }

namespace {

// A single-channel 2D image, y up, every value as read; `what` names the file's kind in messages.
DepthImage read_single_channel(const std::filesystem::path& file, const char* what, bool depth_range) {
  const std::string name = file.string();
  if (!std::filesystem::exists(file)) throw InputError(fmt::format("{} '{}' does not exist", what, name));
  backend::FloatImage in;
  if (const std::string error = load_backend().read(name, in); !error.empty())
    throw InputError(fmt::format("{} '{}' {}", what, name, error));
  if (in.channels != 1)
    throw InputError(fmt::format("{} '{}' has {} channels; it must have exactly one", what, name, in.channels));
  if (in.width < 1 || in.height < 1 || in.depth > 1)
    throw InputError(fmt::format("{} '{}' is not a 2D image of at least 1x1 pixels", what, name));
  const int w = in.width, h = in.height;
  DepthImage img(w, h, 0.0f);
  for (int r = 0; r < h; ++r) {
    const int y = h - 1 - r;
    for (int x = 0; x < w; ++x) {
      const float v = in.pixels[static_cast<std::size_t>(r) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      if (depth_range && (!std::isfinite(v) || v < 0.0f || v > 1.0f)) {
        const char* kind = std::isnan(v) ? "NaN" : std::isinf(v) ? "an infinite depth" : "a depth outside [0, 1]";
        throw InputError(fmt::format("{} '{}' holds {} ({}) at pixel ({}, {}) (y up; file row {}, column {})", what, name, kind, v, x,
                                     y, r, x));
      }
      img.at(x, y) = v;
    }
  }
  return img;
}

}  // namespace

DepthImage read_depth(const std::filesystem::path& file) { return read_single_channel(file, "depth file", true); }

DepthImage read_values(const std::filesystem::path& file) { return read_single_channel(file, "image file", false); }

void write_depth(const DepthImage& image, const std::filesystem::path& file) {
  write(file, image.width, image.height, 1, backend::PixelType::Float,
        flip_rows(image.texels, image.width, image.height, 1).data(), true);
}

void write_preview(const DepthImage& image, const std::filesystem::path& file, float lo, float hi) {
  std::vector<std::uint16_t> px(image.size());
  const float span = hi - lo;
  for (std::size_t i = 0; i < px.size(); ++i) {
    const float t = span > 0.0f ? std::clamp((image.texels[i] - lo) / span, 0.0f, 1.0f) : 0.5f;
    px[i] = static_cast<std::uint16_t>(std::lround(t * 65535.0f));
  }
  write(file, image.width, image.height, 1, backend::PixelType::UInt16, flip_rows(px, image.width, image.height, 1).data(),
        false);
}

void write_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb, const std::filesystem::path& file) {
  NBSIM_CHECK(rgb.size() == static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, "RGB buffer size mismatch");
  write(file, width, height, 3, backend::PixelType::UInt8, flip_rows(rgb, width, height, 3).data(), false);
}

}  // namespace nbsim::io
