// Depth image files checked before OpenImageIO opens them; see image_precheck.h.
#include "io/image_precheck.h"

#include <fmt/format.h>

#include <array>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
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

// "1 row", "2 rows".
std::string count_of(std::uintmax_t n, std::string_view noun) { return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s"); }

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

// A tile is allocated whole by the readers: it stays within the image limits too.
std::string tile_refusal(std::string_view what, long long w, long long h, long long max_side, long long max_pixels) {
  if (w < 1 || h < 1) return fmt::format("is a damaged {}: it declares tiles of {}x{} pixels", what, w, h);
  if (w > max_side || h > max_side || w * h > max_pixels)
    return fmt::format("is a damaged {}: it declares tiles of {}x{} pixels, above the depth image limit of {} pixels a "
                       "side and {} pixels in all",
                       what, w, h, max_side, max_pixels);
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

// The bytes OpenEXR reads for a value of a fixed-size attribute type, whatever its declared size
// (so a declared size that differs leaves the reader somewhere else than the size says: the next
// attribute is then read from inside this one's value); 0 for a type of variable size.
std::uint32_t exr_fixed_size(std::string_view type) noexcept {
  static constexpr std::pair<std::string_view, std::uint32_t> kSizes[] = {
      {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1}, {"double", 8},
      {"envmap", 1}, {"float", 4}, {"int", 4}, {"keycode", 28}, {"lineOrder", 1}, {"m33f", 36}, {"m33d", 72},
      {"m44f", 64}, {"m44d", 128}, {"rational", 8}, {"tiledesc", 9}, {"timecode", 8}, {"v2i", 8}, {"v2f", 8},
      {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24}};
  for (const auto& [name, bytes] : kSizes)
    if (name == type) return bytes;
  return 0;
}

// OpenEXR: the headers' attributes (name, type, 32-bit size, value) each within the file
// (OpenEXR allocates an attribute's declared size), a fixed-size type's value of its size, the
// sizes a variable value declares inside it (a preview's pixels, a string vector's strings: OpenEXR
// allocates them), and the data window within the limits.
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
      if (const std::uint32_t fixed = exr_fixed_size(*type); fixed != 0 && static_cast<std::uint32_t>(size) != fixed)
        return fmt::format("is a damaged OpenEXR file: attribute '{}' at byte {} of type {} declares {} bytes, and a {} "
                           "holds {}",
                           printable(*name), at - 4, *type, size, *type, fixed);
      if (*type == "preview") {  // width, height (32 bits each), then 4 bytes a pixel
        const auto wh = f.read<8>(at);
        const std::uint64_t pw = wh && size >= 8 ? static_cast<std::uint32_t>(little_endian(wh->data())) : 0;
        const std::uint64_t ph = wh && size >= 8 ? static_cast<std::uint32_t>(little_endian(wh->data() + 4)) : 0;
        if (!wh || size < 8 || 8 + 4 * pw * ph != static_cast<std::uint64_t>(size))
          return fmt::format("is a damaged OpenEXR file: preview attribute '{}' at byte {} declares {} bytes, which do not hold "
                             "its {}x{} pixels",
                             printable(*name), at - 4, size, pw, ph);
      }
      if (*type == "chlist") {
        // OpenEXR reads a channel list by its structure, not its declared size: channels of a name
        // (up to 255 characters) and 16 bytes each, until an empty name. A list that ends elsewhere
        // than the declared size makes OpenEXR read the next attribute from another byte than this
        // walk (fuzz_depth_image in CI: a channel list running on into the next attributes, then a
        // 1.85 GB "attribute").
        const std::uintmax_t end = at + static_cast<std::uintmax_t>(size);
        std::uintmax_t pos = at;
        int channels = 0;
        for (;;) {
          const auto channel = pos < end ? f.cstring(pos, 255) : std::nullopt;
          if (!channel || pos + channel->size() + 1 > end)
            return fmt::format("is a damaged OpenEXR file: channel list attribute '{}' at byte {} declares {} bytes, and its "
                               "channel {} does not end inside them",
                               printable(*name), at - 4, size, channels);
          pos += channel->size() + 1;
          if (channel->empty()) break;
          pos += 16;  // pixel type, pLinear, reserved, x and y sampling
          ++channels;
        }
        if (pos != end)
          return fmt::format("is a damaged OpenEXR file: channel list attribute '{}' at byte {} declares {} bytes, and its "
                             "{} channels and end take {}",
                             printable(*name), at - 4, size, channels, pos - at);
      }
      if (*type == "stringvector") {  // strings of a 32-bit length each, within the value
        for (std::uintmax_t read = 0; read < static_cast<std::uintmax_t>(size);) {
          const auto len = f.read<4>(at + read);
          const std::int32_t n = len && read + 4 <= static_cast<std::uintmax_t>(size) ? little_endian(len->data()) : -1;
          if (n < 0 || read + 4 + static_cast<std::uintmax_t>(n) > static_cast<std::uintmax_t>(size))
            return fmt::format("is a damaged OpenEXR file: string vector attribute '{}' at byte {} holds a string that does "
                               "not fit its {} bytes",
                               printable(*name), at - 4, size);
          read += 4 + static_cast<std::uintmax_t>(n);
        }
      }
      if (*name == "dataWindow" && *type == "box2i" && size == 16) {
        const auto box = f.read<16>(at);
        if (!box) return "is a damaged OpenEXR file: its data window ends early";
        const long long x0 = little_endian(box->data()), y0 = little_endian(box->data() + 4);
        const long long x1 = little_endian(box->data() + 8), y1 = little_endian(box->data() + 12);
        if (std::string r = size_refusal("OpenEXR file", x1 - x0 + 1, y1 - y0 + 1, max_side, max_pixels); !r.empty()) return r;
        data_window = true;
      }
      if (*name == "tiles" && *type == "tiledesc" && size == 9) {  // OpenEXR allocates a tile's pixels
        const auto tiles = f.read<8>(at);
        if (!tiles) return "is a damaged OpenEXR file: its tile description ends early";
        const long long tw = static_cast<std::uint32_t>(little_endian(tiles->data()));
        const long long th = static_cast<std::uint32_t>(little_endian(tiles->data() + 4));
        if (std::string r = tile_refusal("OpenEXR file", tw, th, max_side, max_pixels); !r.empty()) return r;
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


// TIFF (classic and BigTIFF): the first directory, the one OpenImageIO reads. libtiff and
// OpenImageIO trust what a directory declares: a strip or tile past the end of the file is read as
// nothing and OpenImageIO hands back zeros without an error, and OpenImageIO sizes its read buffer
// by RowsPerStrip even when that is far more rows than the image has (fuzz_depth_image: a 230-byte
// file, 4 rows declared with 63008 rows a strip, cost a 2.98 GB buffer and read as zeros). So every
// tag's values, every strip or tile, and the buffer OpenImageIO will size from them are checked
// here against the file's length and the image limits.
class Tiff {
 public:
  Tiff(File& f, bool little, bool big) : f_(f), little_(little), big_(big) {}

  // The whole check; "" when the file may be opened.
  std::string check(long long max_side, long long max_pixels) {
    const std::uintmax_t first = big_ ? read_uint(8, 8).value_or(0) : read_uint(4, 4).value_or(0);
    if (big_) {
      const auto size = read_uint(4, 2), zero = read_uint(6, 2);
      if (!size || *size != 8 || !zero || *zero != 0)
        return "is a damaged BigTIFF: its header does not declare 8-byte offsets";
    }
    if (first < header_bytes() || first >= f_.bytes())
      return fmt::format("is a damaged TIFF: its first directory's offset {} is outside the {}-byte file", first,
                         f_.bytes());
    const std::uintmax_t count_bytes = big_ ? 8 : 2, entry_bytes = big_ ? 20 : 12;
    const auto entries = read_uint(first, count_bytes);
    if (!entries || *entries == 0 || *entries > (f_.bytes() - first) / entry_bytes + 1 ||
        first + count_bytes + *entries * entry_bytes > f_.bytes())
      return fmt::format("is a damaged TIFF: its first directory at byte {} declares {} entries, past the end of the "
                         "{}-byte file",
                         first, entries.value_or(0), f_.bytes());
    for (std::uintmax_t i = 0; i < *entries; ++i)
      if (std::string r = read_entry(first + count_bytes + i * entry_bytes); !r.empty()) return r;
    return check_layout(max_side, max_pixels);
  }

 private:
  // One directory entry: its values within the file, and the tags that lay the image out kept.
  struct Entry {
    std::uint16_t type = 0;
    std::uintmax_t count = 0;
    std::uintmax_t values_at = 0;  // where the values are (in the entry itself when they fit)
  };

  static constexpr std::uint16_t kImageWidth = 256, kImageLength = 257, kBitsPerSample = 258, kStripOffsets = 273,
                                 kSamplesPerPixel = 277, kRowsPerStrip = 278, kStripByteCounts = 279,
                                 kPlanarConfig = 284, kTileWidth = 322, kTileLength = 323, kTileOffsets = 324,
                                 kTileByteCounts = 325, kCompression = 259;

  // Bytes of one value of a TIFF field type; 0 for a type libtiff does not know (it skips the tag).
  static std::uintmax_t type_bytes(std::uint16_t type) {
    switch (type) {
      case 1: case 2: case 6: case 7: return 1;   // BYTE, ASCII, SBYTE, UNDEFINED
      case 3: case 8: return 2;                   // SHORT, SSHORT
      case 4: case 9: case 11: case 13: return 4; // LONG, SLONG, FLOAT, IFD
      case 5: case 10: case 12: case 16: case 17: case 18: return 8;  // (S)RATIONAL, DOUBLE, LONG8, SLONG8, IFD8
      default: return 0;
    }
  }
  static std::string tag_name(std::uint16_t tag) {
    switch (tag) {
      case kImageWidth: return "ImageWidth";
      case kImageLength: return "ImageLength";
      case kBitsPerSample: return "BitsPerSample";
      case kCompression: return "Compression";
      case kStripOffsets: return "StripOffsets";
      case kSamplesPerPixel: return "SamplesPerPixel";
      case kRowsPerStrip: return "RowsPerStrip";
      case kStripByteCounts: return "StripByteCounts";
      case kPlanarConfig: return "PlanarConfiguration";
      case kTileWidth: return "TileWidth";
      case kTileLength: return "TileLength";
      case kTileOffsets: return "TileOffsets";
      case kTileByteCounts: return "TileByteCounts";
      default: return fmt::format("tag {}", tag);
    }
  }

  std::uintmax_t header_bytes() const { return big_ ? 16 : 8; }

  // An unsigned integer of `bytes` (1, 2, 4 or 8) at `at`, in the file's byte order.
  std::optional<std::uintmax_t> read_uint(std::uintmax_t at, std::uintmax_t bytes) {
    const auto b = f_.read<8>(at);
    std::array<unsigned char, 8> v{};
    if (b) {
      v = *b;
    } else {  // fewer than 8 bytes left: read what the value needs
      if (at + bytes > f_.bytes()) return std::nullopt;
      for (std::uintmax_t i = 0; i < bytes; ++i) {
        const auto one = f_.read<1>(at + i);
        if (!one) return std::nullopt;
        v[static_cast<std::size_t>(i)] = (*one)[0];
      }
    }
    std::uintmax_t x = 0;
    for (std::uintmax_t i = 0; i < bytes; ++i) {
      const std::size_t k = static_cast<std::size_t>(little_ ? bytes - 1 - i : i);
      x = (x << 8) | v[k];
    }
    return x;
  }

  std::string read_entry(std::uintmax_t at) {
    const auto tag = read_uint(at, 2), type = read_uint(at + 2, 2);
    const auto count = read_uint(at + 4, big_ ? 8 : 4);
    if (!tag || !type || !count) return "is a damaged TIFF: its first directory ends early";
    const std::uintmax_t value_field = at + (big_ ? 12 : 8), inline_bytes = big_ ? 8 : 4;
    const std::uintmax_t unit = type_bytes(static_cast<std::uint16_t>(*type));
    if (unit == 0) return "";  // a type libtiff ignores, with a warning
    Entry e{static_cast<std::uint16_t>(*type), *count, value_field};
    if (*count > f_.bytes() / unit + 1 || *count * unit > inline_bytes) {
      const auto offset = read_uint(value_field, inline_bytes);
      if (!offset || *count > f_.bytes() / unit || *offset > f_.bytes() || *count * unit > f_.bytes() - *offset)
        return fmt::format("is a damaged TIFF: {} at byte {} declares {} values of {} bytes at offset {}, past the end "
                           "of the {}-byte file",
                           tag_name(static_cast<std::uint16_t>(*tag)), at, *count, unit, offset.value_or(0), f_.bytes());
      e.values_at = *offset;
    }
    entries_.emplace(static_cast<std::uint16_t>(*tag), e);  // libtiff keeps a tag's first entry
    return "";
  }

  // Value `i` of a tag as an unsigned integer (SHORT, LONG, LONG8 or BYTE), if the tag is there.
  std::optional<std::uintmax_t> value(std::uint16_t tag, std::uintmax_t i = 0) {
    const auto it = entries_.find(tag);
    if (it == entries_.end() || i >= it->second.count) return std::nullopt;
    const Entry& e = it->second;
    const std::uintmax_t unit = type_bytes(e.type);
    if (e.type != 1 && e.type != 3 && e.type != 4 && e.type != 16) return std::nullopt;
    return read_uint(e.values_at + i * unit, unit);
  }
  bool has(std::uint16_t tag) const { return entries_.contains(tag); }
  std::uintmax_t count(std::uint16_t tag) const {
    const auto it = entries_.find(tag);
    return it == entries_.end() ? 0 : it->second.count;
  }

  std::string check_layout(long long max_side, long long max_pixels) {
    const auto w = value(kImageWidth), h = value(kImageLength);
    if (!w || !h) return fmt::format("is a damaged TIFF: its first directory has no {}", w ? "ImageLength" : "ImageWidth");
    const auto clamp = [](std::uintmax_t v) { return static_cast<long long>(std::min<std::uintmax_t>(v, 1ull << 40)); };
    const long long width = clamp(*w), height = clamp(*h);
    if (std::string r = size_refusal("TIFF", width, height, max_side, max_pixels); !r.empty()) return r;
    const std::uintmax_t samples = value(kSamplesPerPixel).value_or(1), bits = value(kBitsPerSample).value_or(1);
    if (samples < 1 || samples > 64) return fmt::format("is a damaged TIFF: it declares {} samples a pixel", samples);
    if (bits < 1 || bits > 64) return fmt::format("is a damaged TIFF: it declares {} bits a sample", bits);
    const bool separate = value(kPlanarConfig).value_or(1) == 2;
    const std::uintmax_t planes = separate ? samples : 1, chunk_samples = separate ? 1 : samples;
    const bool uncompressed = value(kCompression).value_or(1) == 1;
    const auto uw = static_cast<std::uintmax_t>(width), uh = static_cast<std::uintmax_t>(height);
    // Bytes of `rows` rows of `cols` pixels of one chunk, as libtiff packs them (whole bytes a row).
    const auto chunk_bytes = [&](std::uintmax_t cols, std::uintmax_t rows) { return rows * ((cols * chunk_samples * bits + 7) / 8); };

    std::uintmax_t chunks = 0, offsets_tag = 0, counts_tag = 0;
    std::uintmax_t cols = uw, rows = 0;  // one chunk's size
    if (has(kTileWidth) || has(kTileLength)) {
      const auto tw = value(kTileWidth), tl = value(kTileLength);
      if (!tw || !tl || *tw == 0 || *tl == 0)
        return "is a damaged TIFF: it declares tiles without a TileWidth and a TileLength of at least 1";
      if (std::string r = tile_refusal("TIFF", clamp(*tw), clamp(*tl), max_side, max_pixels); !r.empty()) return r;
      chunks = ((uw + *tw - 1) / *tw) * ((uh + *tl - 1) / *tl) * planes;
      offsets_tag = kTileOffsets, counts_tag = kTileByteCounts, cols = *tw, rows = *tl;
    } else {
      const std::uintmax_t rps = value(kRowsPerStrip).value_or(0xFFFFFFFFu);
      if (rps == 0) return "is a damaged TIFF: it declares 0 RowsPerStrip";
      // OpenImageIO reads converted scanlines in chunks of whole strips as RowsPerStrip declares
      // them (values below 2^31; larger ones it ignores), so a RowsPerStrip above the image's rows
      // costs that many rows of buffer, each row as OpenImageIO holds it in memory: every sample
      // in 1, 2, 4 or 8 bytes (a 1-bit sample takes a byte; fuzz_depth_image found the file's
      // packed bits underestimating it eightfold).
      const std::uintmax_t sample_bytes = bits <= 8 ? 1 : bits <= 16 ? 2 : bits <= 32 ? 4 : 8;
      const std::uintmax_t row_bytes = uw * samples * sample_bytes;
      if (rps > uh && rps < 0x80000000u && rps * row_bytes > kMaxReadBufferBytes)
        return fmt::format("declares RowsPerStrip {} for an image of {} rows: reading it would take a buffer of {} "
                           "rows of {} bytes ({} MiB, above the {} MiB limit)",
                           rps, uh, rps, row_bytes, (rps * row_bytes) >> 20, kMaxReadBufferBytes >> 20);
      rows = std::min(rps, uh);
      chunks = ((uh + rows - 1) / rows) * planes;
      offsets_tag = kStripOffsets, counts_tag = kStripByteCounts;
    }
    const std::string offsets_name = tag_name(static_cast<std::uint16_t>(offsets_tag));
    const std::string counts_name = tag_name(static_cast<std::uint16_t>(counts_tag));
    const std::string kind = offsets_tag == kTileOffsets ? "tile" : "strip";
    if (count(static_cast<std::uint16_t>(offsets_tag)) < chunks || count(static_cast<std::uint16_t>(counts_tag)) < chunks)
      return fmt::format("is a damaged TIFF: its {}x{} image needs {}, and it declares {} {} and {} {}", width,
                         height, count_of(chunks, kind), count(static_cast<std::uint16_t>(offsets_tag)), offsets_name,
                         count(static_cast<std::uint16_t>(counts_tag)), counts_name);
    for (std::uintmax_t i = 0; i < chunks; ++i) {
      const auto offset = value(static_cast<std::uint16_t>(offsets_tag), i);
      const auto bytes = value(static_cast<std::uint16_t>(counts_tag), i);
      if (!offset || !bytes)
        return fmt::format("is a damaged TIFF: {} or {} is not of an integer type", offsets_name, counts_name);
      if (*offset > f_.bytes() || *bytes > f_.bytes() - *offset)
        return fmt::format("is a damaged TIFF: {} {} declares {} bytes at offset {} ({} {}, {} {}), past the end of the "
                           "{}-byte file",
                           kind, i, *bytes, *offset, offsets_name, i, counts_name, i, f_.bytes());
      // An uncompressed chunk holds every row it covers (the last strip may be shorter).
      const std::uintmax_t in_plane = i % (chunks / planes);
      const std::uintmax_t chunk_rows =
          offsets_tag == kStripOffsets ? std::min(rows, uh - std::min(uh, in_plane * rows)) : rows;
      const std::uintmax_t need = chunk_bytes(cols, chunk_rows);
      if (uncompressed && *bytes < need)
        return fmt::format("is a damaged TIFF: uncompressed {} {} holds {} bytes ({} {}), fewer than the {} bytes of its {}",
                           kind, i, *bytes, counts_name, i, need, count_of(chunk_rows, "row"));
    }
    return "";
  }

  File& f_;
  bool little_;
  bool big_;
  std::map<std::uint16_t, Entry> entries_;
};
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
  const bool tiff_le = starts(std::string_view("II*\0", 4)) || starts(std::string_view("II+\0", 4));
  const bool tiff_be = starts(std::string_view("MM\0*", 4)) || starts(std::string_view("MM\0+", 4));
  if (tiff_le || tiff_be) {
    Tiff tiff(f, tiff_le, magic && ((*magic)[2] == '+' || (*magic)[3] == '+'));
    return {"tif", tiff.check(max_side, max_pixels)};
  }
  const auto head = f.read<3>(0);
  if (head && (*head)[0] == 'P' && ((*head)[1] == 'f' || (*head)[1] == 'F') && std::isspace((*head)[2]))
    return {"pfm", ""};
  return {"", f.bytes() == 0 ? "cannot be read: the file is empty"
                             : "cannot be read: it is not a depth image format nbsim reads (OpenEXR, TIFF, PNG or PFM, "
                               "recognised by their first bytes)"};
}

}  // namespace nbsim::io
