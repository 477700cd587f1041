// A TIFF written byte by byte for tests: one directory of SHORT/LONG (or LONG8) entries and the
// pixel data, so that each test can break exactly one thing (an offset, a count, a tag) that a
// writer library would never let it break. Classic or BigTIFF, little- or big-endian.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace nbsim::testing {

class TiffBuilder {
 public:
  enum Type : std::uint16_t { kShort = 3, kLong = 4, kLong8 = 16 };

  // A float image (SampleFormat 3) of w x h pixels in one uncompressed strip holding `pixels`.
  TiffBuilder(int w, int h, std::vector<float> pixels) : pixels_(std::move(pixels)) {
    set(256, kLong, {static_cast<std::uint64_t>(w)});
    set(257, kLong, {static_cast<std::uint64_t>(h)});
    set(258, kShort, {32});
    set(259, kShort, {1});
    set(262, kShort, {1});
    set(277, kShort, {1});
    set(278, kLong, {static_cast<std::uint64_t>(h)});
    set(284, kShort, {1});
    set(339, kShort, {3});
    strips({{0, pixels_.size() * 4}});  // offsets relative to the pixel data; fixed in bytes()
  }

  TiffBuilder& big_endian(bool on = true) { big_endian_ = on; return *this; }
  TiffBuilder& bigtiff(bool on = true) { bigtiff_ = on; return *this; }
  TiffBuilder& set(std::uint16_t tag, Type type, std::vector<std::uint64_t> values) {
    entries_[tag] = {type, std::move(values), false};
    return *this;
  }
  TiffBuilder& erase(std::uint16_t tag) { entries_.erase(tag); return *this; }
  // An entry whose count is `count` while its values are written at byte `offset` as given
  // (nothing written there): the values may point anywhere.
  TiffBuilder& raw_entry(std::uint16_t tag, Type type, std::uint64_t count, std::uint64_t offset) {
    entries_[tag] = {type, {offset}, true, count};
    return *this;
  }
  // Strips (or tiles with `tiles`): (offset into the pixel data, byte count) each.
  TiffBuilder& strips(const std::vector<std::pair<std::uint64_t, std::uint64_t>>& s, bool tiles = false) {
    std::vector<std::uint64_t> offsets, counts;
    for (const auto& [o, c] : s) offsets.push_back(o), counts.push_back(c);
    erase(273).erase(279).erase(324).erase(325);
    set(tiles ? 324 : 273, kLong, offsets).set(tiles ? 325 : 279, kLong, counts);
    relative_ = tiles ? 324 : 273;
    return *this;
  }
  TiffBuilder& absolute_offsets() { relative_ = 0; return *this; }
  TiffBuilder& first_directory_at(std::uint64_t at) { ifd_at_ = at; return *this; }
  TiffBuilder& entry_count(std::uint64_t n) { entry_count_ = n; return *this; }

  std::vector<std::uint8_t> bytes() const {
    const std::uint64_t header = bigtiff_ ? 16 : 8, entry = bigtiff_ ? 20 : 12, count_bytes = bigtiff_ ? 8 : 2;
    const std::uint64_t inline_bytes = bigtiff_ ? 8 : 4;
    const std::uint64_t ifd = header;
    const std::uint64_t ifd_end = ifd + count_bytes + entries_.size() * entry + inline_bytes;
    // Out-of-line values after the directory, then the pixels.
    std::vector<std::uint8_t> extra;
    std::map<std::uint16_t, std::uint64_t> extra_at;
    for (const auto& [tag, e] : entries_) {
      if (e.raw || e.values.size() * size(e.type) <= inline_bytes) continue;
      extra_at[tag] = ifd_end + extra.size();
      for (std::uint64_t v : e.values) put(extra, v, size(e.type));
    }
    const std::uint64_t pixels_at = ifd_end + extra.size();
    std::vector<std::uint8_t> out;
    out.push_back(big_endian_ ? 'M' : 'I'), out.push_back(big_endian_ ? 'M' : 'I');
    put(out, bigtiff_ ? 43 : 42, 2);
    if (bigtiff_) put(out, 8, 2), put(out, 0, 2);
    put(out, ifd_at_ ? ifd_at_ : ifd, inline_bytes);
    put(out, entry_count_ ? entry_count_ : entries_.size(), count_bytes);
    for (const auto& [tag, e] : entries_) {
      put(out, tag, 2);
      put(out, e.type, 2);
      const std::uint64_t count = e.raw ? e.count : e.values.size();
      put(out, count, bigtiff_ ? 8 : 4);
      std::vector<std::uint8_t> field;
      if (e.raw) {
        put(field, e.values[0], inline_bytes);
      } else if (extra_at.contains(tag)) {
        put(field, extra_at.at(tag), inline_bytes);
      } else {
        for (std::uint64_t v : e.values) put(field, v + (tag == relative_ ? pixels_at : 0), size(e.type));
      }
      field.resize(static_cast<std::size_t>(inline_bytes), 0);
      out.insert(out.end(), field.begin(), field.end());
    }
    put(out, 0, inline_bytes);  // no next directory
    // Out-of-line values (offsets relative to the pixels are made absolute here).
    for (const auto& [tag, e] : entries_) {
      if (!extra_at.contains(tag)) continue;
      for (std::uint64_t v : e.values) put(out, v + (tag == relative_ ? pixels_at : 0), size(e.type));
    }
    for (float f : pixels_) {
      std::uint32_t u;
      std::memcpy(&u, &f, 4);
      put(out, u, 4);
    }
    return out;
  }

 private:
  struct Entry {
    Type type;
    std::vector<std::uint64_t> values;
    bool raw = false;
    std::uint64_t count = 0;
  };
  static std::uint64_t size(Type t) { return t == kShort ? 2 : t == kLong ? 4 : 8; }
  void put(std::vector<std::uint8_t>& out, std::uint64_t v, std::uint64_t n) const {
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::uint64_t shift = 8 * (big_endian_ ? n - 1 - i : i);
      out.push_back(static_cast<std::uint8_t>(v >> shift));
    }
  }

  std::vector<float> pixels_;
  std::map<std::uint16_t, Entry> entries_;
  bool big_endian_ = false, bigtiff_ = false;
  std::uint16_t relative_ = 273;
  std::uint64_t ifd_at_ = 0, entry_count_ = 0;
};

}  // namespace nbsim::testing
