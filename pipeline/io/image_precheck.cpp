// Depth image files checked before OpenImageIO opens them; see image_precheck.h.
#include "pipeline/io/image_precheck.h"

#include <fmt/format.h>

#include <array>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string_view>

namespace nbsim::io {

namespace {

constexpr std::array<unsigned char, 8> kPngMagic = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
constexpr std::array<unsigned char, 4> kExrMagic = {0x76, 0x2F, 0x31, 0x01};

// The file, read through one stream, with its length.
class File {
 public:
  explicit File(const std::string& path) : in_(path, std::ios::binary) {
    std::error_code ec;
    bytes_ = std::filesystem::file_size(path, ec);
    if (ec) bytes_ = 0;
  }
  std::uintmax_t bytes() const { return bytes_; }
  // `n` bytes at `at`, or nothing when the file ends first.
  template <std::size_t N>
  std::optional<std::array<unsigned char, N>> read(std::uintmax_t at) {
    std::array<unsigned char, N> b{};
    if (at + N > bytes_) return std::nullopt;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(at));
    in_.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(N));
    if (in_.gcount() != static_cast<std::streamsize>(N)) return std::nullopt;
    return b;
  }
  // A NUL-terminated string at `at` of at most `max` characters; nothing when it is longer or the
  // file ends first.
  std::optional<std::string> cstring(std::uintmax_t at, std::size_t max) {
    std::string s;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(at));
    for (std::size_t i = 0; i <= max; ++i) {
      const int c = in_.get();
      if (c == std::char_traits<char>::eof()) return std::nullopt;
      if (c == 0) return s;
      s += static_cast<char>(c);
    }
    return std::nullopt;
  }

 private:
  std::ifstream in_;
  std::uintmax_t bytes_ = 0;
};

std::uint32_t big_endian(const unsigned char* b) {
  return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | std::uint32_t{b[3]};
}
std::int32_t little_endian(const unsigned char* b) {
  return static_cast<std::int32_t>(std::uint32_t{b[0]} | (std::uint32_t{b[1]} << 8) | (std::uint32_t{b[2]} << 16) |
                                   (std::uint32_t{b[3]} << 24));
}

std::string printable(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 40)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return s.size() > 40 ? out + "..." : out;
}

std::string size_refusal(std::string_view what, long long w, long long h, long long max_side, long long max_pixels) {
  if (w < 1 || h < 1) return fmt::format("is a damaged {}: it declares {}x{} pixels", what, w, h);
  if (w > max_side || h > max_side || w * h > max_pixels)
    return fmt::format("declares {}x{} pixels, above the depth image limit of {} pixels a side and {} pixels in all "
                       "(refused before reading any pixel)",
                       w, h, max_side, max_pixels);
  return "";
}

// PNG: IHDR first, every chunk within the file (libpng allocates a chunk's declared length).
std::string check_png(File& f, long long max_side, long long max_pixels) {
  std::uintmax_t at = 8;
  for (int chunk = 0;; ++chunk) {
    const auto head = f.read<8>(at);
    if (!head) return "";  // a file that ends without IEND: libpng says so
    const std::uintmax_t length = big_endian(head->data());
    std::string type;
    for (int i = 4; i < 8; ++i) type += static_cast<char>((*head)[static_cast<std::size_t>(i)]);
    if (length > 0x7FFFFFFFu || at + 12 + length > f.bytes())
      return fmt::format("is a damaged PNG: chunk {} ('{}') at byte {} declares {} bytes of data, past the end of the "
                         "{}-byte file",
                         chunk, printable(type), at, length, f.bytes());
    if (chunk == 0) {
      const auto ihdr = f.read<8>(at + 8);
      if (type != "IHDR" || length != 13 || !ihdr) return "is a damaged PNG: its first chunk is not a 13-byte IHDR";
      if (std::string r = size_refusal("PNG", big_endian(ihdr->data()), big_endian(ihdr->data() + 4), max_side, max_pixels);
          !r.empty())
        return r;
    }
    if (type == "IEND") return "";
    at += 12 + length;
  }
}

// OpenEXR: the headers' attributes (name, type, 32-bit size, value) each within the file
// (OpenEXR allocates an attribute's declared size), and the data window within the limits.
std::string check_exr(File& f, long long max_side, long long max_pixels) {
  const auto version = f.read<4>(4);
  if (!version) return "is a damaged OpenEXR file: it ends inside its version field";
  const std::uint32_t flags = static_cast<std::uint32_t>(little_endian(version->data()));
  const bool multipart = (flags & 0x1000u) != 0;
  const std::size_t max_name = (flags & 0x400u) ? 255 : 31;
  std::uintmax_t at = 8;
  for (int part = 0;; ++part) {
    bool data_window = false;
    for (int attribute = 0;; ++attribute) {
      const auto name = f.cstring(at, max_name);
      if (!name) return fmt::format("is a damaged OpenEXR file: attribute {} of header {} at byte {} has no name of at most {} characters", attribute, part, at, max_name);
      at += name->size() + 1;
      if (name->empty()) break;  // the header's end
      const auto type = f.cstring(at, max_name);
      if (!type) return fmt::format("is a damaged OpenEXR file: attribute '{}' at byte {} has no type name", printable(*name), at);
      at += type->size() + 1;
      const auto size_field = f.read<4>(at);
      if (!size_field) return fmt::format("is a damaged OpenEXR file: attribute '{}' ends before its size", printable(*name));
      const std::int32_t size = little_endian(size_field->data());
      at += 4;
      if (size < 0 || at + static_cast<std::uintmax_t>(size) > f.bytes())
        return fmt::format("is a damaged OpenEXR file: attribute '{}' at byte {} declares {} bytes, past the end of the "
                           "{}-byte file",
                           printable(*name), at - 4, size, f.bytes());
      if (*name == "dataWindow" && *type == "box2i" && size == 16) {
        const auto box = f.read<16>(at);
        if (!box) return "is a damaged OpenEXR file: its data window ends early";
        const long long x0 = little_endian(box->data()), y0 = little_endian(box->data() + 4);
        const long long x1 = little_endian(box->data() + 8), y1 = little_endian(box->data() + 12);
        if (std::string r = size_refusal("OpenEXR file", x1 - x0 + 1, y1 - y0 + 1, max_side, max_pixels); !r.empty()) return r;
        data_window = true;
      }
      at += static_cast<std::uintmax_t>(size);
    }
    if (!data_window) return fmt::format("is a damaged OpenEXR file: header {} has no data window", part);
    if (!multipart) return "";
    const auto next = f.read<1>(at);
    if (!next) return "is a damaged OpenEXR file: it ends inside its headers";
    if ((*next)[0] == 0) return "";  // the empty header that ends a multi-part file's headers
  }
}

}  // namespace

ImagePrecheck precheck_depth_file(const std::string& path, long long max_side, long long max_pixels) {
  File f(path);
  const auto magic = f.read<8>(0);
  const auto starts = [&](auto bytes) {
    if (!magic) return false;
    for (std::size_t i = 0; i < bytes.size(); ++i)
      if ((*magic)[i] != static_cast<unsigned char>(bytes[i])) return false;
    return true;
  };
  if (starts(kPngMagic)) return {"png", check_png(f, max_side, max_pixels)};
  if (starts(kExrMagic)) return {"exr", check_exr(f, max_side, max_pixels)};
  if (starts(std::string_view("II*\0", 4)) || starts(std::string_view("MM\0*", 4)) ||
      starts(std::string_view("II+\0", 4)) || starts(std::string_view("MM\0+", 4)))
    return {"tif", ""};
  const auto head = f.read<3>(0);
  if (head && (*head)[0] == 'P' && ((*head)[1] == 'f' || (*head)[1] == 'F') && std::isspace((*head)[2]))
    return {"pfm", ""};
  return {"", f.bytes() == 0 ? "cannot be read: the file is empty"
                             : "cannot be read: it is not a depth image format nbsim reads (OpenEXR, TIFF, PNG or PFM, "
                               "recognised by their first bytes)"};
}

}  // namespace nbsim::io
