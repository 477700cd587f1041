// libnbsim_oiio.so: nbsim's image files through OpenImageIO; see oiio_backend.h.
#include "pipeline/io/oiio_backend.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <exception>

namespace nbsim::io::backend {
namespace {

namespace OIIO = OIIO_NAMESPACE;

std::string read(const std::string& path, FloatImage& image) try {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return fmt::format("cannot be read: {}", OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  image.width = spec.width;
  image.height = spec.height;
  image.depth = spec.depth;
  image.channels = spec.nchannels;
  image.pixels.clear();
  if (spec.nchannels != 1 || spec.depth > 1 || spec.width < 1 || spec.height < 1) return "";
  image.pixels.resize(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height));
  if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    return fmt::format("cannot be read: {}", in->geterror());
  in->close();
  return "";
} catch (const std::exception& e) {
  return fmt::format("cannot be read: {}", e.what());
}

std::string write(const std::string& path, int width, int height, int channels, PixelType type, const void* data,
                  bool depth_channel) try {
  const OIIO::TypeDesc format = type == PixelType::Float    ? OIIO::TypeDesc::FLOAT
                                : type == PixelType::UInt16 ? OIIO::TypeDesc::UINT16
                                                            : OIIO::TypeDesc::UINT8;
  OIIO::ImageSpec spec(width, height, channels, format);
  if (depth_channel) {
    spec.channelnames = {"Z"};
    spec.attribute("compression", "zip");
  }
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return OIIO::geterror();
  if (!out->open(path, spec) || !out->write_image(spec.format, data) || !out->close()) return out->geterror();
  return "";
} catch (const std::exception& e) {
  return e.what();
}

const Table kTable = {kAbiVersion, OIIO_VERSION_STRING, &read, &write};

}  // namespace
}  // namespace nbsim::io::backend

extern "C" const nbsim::io::backend::Table* nbsim_image_io_backend() { return &nbsim::io::backend::kTable; }
