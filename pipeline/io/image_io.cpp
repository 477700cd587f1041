// OpenImageIO-backed image reading and writing; see image_io.h.
#include "pipeline/io/image_io.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "model/common/error.h"

namespace nbsim::io {

namespace OIIO = OIIO_NAMESPACE;

DepthImage read_depth(const std::filesystem::path& file) {
  const std::string name = file.string();
  if (!std::filesystem::exists(file)) throw InputError(fmt::format("depth file '{}' does not exist", name));
  auto in = OIIO::ImageInput::open(name);
  if (!in) throw InputError(fmt::format("depth file '{}' cannot be read: {}", name, OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels != 1)
    throw InputError(fmt::format("depth file '{}' has {} channels; a depth image has exactly one", name, spec.nchannels));
  if (spec.width < 1 || spec.height < 1 || spec.depth > 1)
    throw InputError(fmt::format("depth file '{}' is not a 2D image of at least 1x1 pixels", name));
  const int w = spec.width, h = spec.height;
  std::vector<float> rows(static_cast<std::size_t>(w) * h);
  if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, rows.data()))
    throw InputError(fmt::format("depth file '{}' cannot be read: {}", name, in->geterror()));
  in->close();

  DepthImage img(w, h, 0.0f);
  for (int r = 0; r < h; ++r) {
    const int y = h - 1 - r;
    for (int x = 0; x < w; ++x) {
      const float v = rows[static_cast<std::size_t>(r) * w + x];
      if (!std::isfinite(v) || v < 0.0f || v > 1.0f) {
        const char* what = std::isnan(v) ? "NaN" : std::isinf(v) ? "an infinite depth" : "a depth outside [0, 1]";
        throw InputError(fmt::format("depth file '{}' holds {} ({}) at pixel ({}, {}) (y up; file row {}, column {})",
                                     name, what, v, x, y, r, x));
      }
      img.at(x, y) = v;
    }
  }
  return img;
}

namespace {

template <typename T>
std::vector<T> flip_rows(const std::vector<T>& src, int width, int height, int channels) {
  std::vector<T> dst(src.size());
  const std::size_t row = static_cast<std::size_t>(width) * channels;
  for (int y = 0; y < height; ++y)
    std::copy_n(src.begin() + static_cast<std::ptrdiff_t>(row * y), row,
                dst.begin() + static_cast<std::ptrdiff_t>(row * (height - 1 - y)));
  return dst;
}

void write(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* data) {
  const std::string name = file.string();
  auto out = OIIO::ImageOutput::create(name);
  if (!out) throw InputError(fmt::format("cannot write '{}': {}", name, OIIO::geterror()));
  if (!out->open(name, spec) || !out->write_image(spec.format, data) || !out->close())
    throw InputError(fmt::format("cannot write '{}': {}", name, out->geterror()));
}

}  // namespace

void write_depth(const DepthImage& image, const std::filesystem::path& file) {
  OIIO::ImageSpec spec(image.width, image.height, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Z"};
  spec.attribute("compression", "zip");
  write(file, spec, flip_rows(image.texels, image.width, image.height, 1).data());
}

void write_preview(const DepthImage& image, const std::filesystem::path& file, float lo, float hi) {
  std::vector<std::uint16_t> px(image.size());
  const float span = hi - lo;
  for (std::size_t i = 0; i < px.size(); ++i) {
    const float t = span > 0.0f ? std::clamp((image.texels[i] - lo) / span, 0.0f, 1.0f) : 0.5f;
    px[i] = static_cast<std::uint16_t>(std::lround(t * 65535.0f));
  }
  OIIO::ImageSpec spec(image.width, image.height, 1, OIIO::TypeDesc::UINT16);
  write(file, spec, flip_rows(px, image.width, image.height, 1).data());
}

void write_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb, const std::filesystem::path& file) {
  NBSIM_CHECK(rgb.size() == static_cast<std::size_t>(width) * height * 3, "RGB buffer size mismatch");
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  write(file, spec, flip_rows(rgb, width, height, 3).data());
}

}  // namespace nbsim::io
