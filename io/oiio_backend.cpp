// libnbsim_oiio.so: nbsim's image files through OpenImageIO; see oiio_backend.h.
#include "io/oiio_backend.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <cctype>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string_view>

#include "io/image_precheck.h"

namespace nbsim::io::backend {
namespace {

namespace OIIO = OIIO_NAMESPACE;

// OpenImageIO's message, or `fallback` when it gives none (its readers do not all say why), or the
// message completed by `fallback` when it stops at a colon (libtiff passes on zlib's empty message:
// fuzz_depth_image found "ZLib error: ").
std::string reason(std::string error, std::string_view fallback) {
  while (!error.empty() && std::isspace(static_cast<unsigned char>(error.back()))) error.pop_back();
  if (error.empty()) return std::string(fallback);
  if (error.back() == ':') return error + " " + std::string(fallback);
  return error;
}

// The byte where a PFM's pixels start, 0 when the file is not a PFM (OpenImageIO reads PFM with
// its PNM reader, so the magic tells): the header is four whitespace-separated tokens ("Pf" or
// "PF", width, height, scale) and one whitespace byte.
std::uintmax_t pfm_pixels_offset(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::string head(256, '\0');
  f.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(f.gcount()));
  if (head.size() < 3 || head[0] != 'P' || (head[1] != 'f' && head[1] != 'F')) return 0;
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  std::size_t i = 0;
  for (int token = 0; token < 4; ++token) {
    while (i < head.size() && space(head[i])) ++i;
    if (i == head.size()) return 0;
    while (i < head.size() && !space(head[i])) ++i;
  }
  return i < head.size() ? i + 1 : 0;
}

std::string read(const std::string& path, FloatImage& image) try {
  // The format by its magic bytes and the declared sizes checked first (image_precheck.h says why);
  // then only that format's reader opens the file.
  const ImagePrecheck pre = precheck_depth_file(path, kMaxDepthSide, kMaxDepthPixels);
  if (!pre.refusal.empty()) return pre.refusal;
  auto in = OIIO::ImageInput::create(pre.format);
  if (!in) return fmt::format("cannot be read: {}", reason(OIIO::geterror(), "OpenImageIO has no reader for it"));
  OIIO::ImageSpec opened;
  if (!in->open(path, opened))
    return fmt::format("cannot be read: {}", reason(in->geterror(), "OpenImageIO cannot read its header"));
  const OIIO::ImageSpec& spec = in->spec();
  image.width = spec.width;
  image.height = spec.height;
  image.depth = spec.depth;
  image.channels = spec.nchannels;
  image.pixels.clear();
  if (spec.nchannels != 1 || spec.depth > 1 || spec.width < 1 || spec.height < 1) return "";
  const long long w = spec.width, h = spec.height;
  if (w > kMaxDepthSide || h > kMaxDepthSide || w * h > kMaxDepthPixels)
    return fmt::format("declares {}x{} pixels, above the depth image limit of {} pixels a side and {} pixels in all "
                       "(refused before reading any pixel)",
                       w, h, kMaxDepthSide, kMaxDepthPixels);
  // An uncompressed format must hold every pixel its header declares: a short file is refused
  // here, with the sizes, instead of by a decoder that may not say why.
  if (const std::uintmax_t offset = pfm_pixels_offset(path); offset != 0) {
    std::error_code ec;
    const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
    const std::uintmax_t pixel_bytes = static_cast<std::uintmax_t>(w * h) * 4u;
    if (!ec && file_bytes < offset + pixel_bytes)
      return fmt::format("is a PFM of {} bytes, too short for the {}-byte header and the {}x{} float pixels ({} bytes) "
                         "it declares (the pixel data is truncated)",
                         file_bytes, offset, w, h, pixel_bytes);
  }
  image.pixels.resize(static_cast<std::size_t>(w * h));
  // OpenImageIO's TIFF reader records a strip it fails to read as an error but still returns true
  // (the pixels stay as they were: zeros), so its error state is checked too.
  const bool decoded = in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, image.pixels.data());
  if (!decoded || in->has_error()) {
    image.pixels.clear();
    return fmt::format("cannot be read: {}",
                       reason(in->geterror(), "OpenImageIO cannot decode its pixel data (a truncated or damaged file?)"));
  }
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
