// Little-endian field encoding for trace payloads (traces/FORMAT.md "Conventions"): Out appends
// fields, In reads them with every read bounds-checked and every count checked against the bytes
// left before anything is allocated. Used by the record codec and the technique chunks' codec.
#pragma once

#include <fmt/format.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "traces/format/records.h"

namespace nbsim::trace::bytes {

static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559, "floats are IEEE-754 binary32");
static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559, "doubles are IEEE-754 binary64");

inline constexpr bool kLittleHost = std::endian::native == std::endian::little;

// Appends little-endian fields to a payload.
class Out {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void count(std::size_t n) {
    NBSIM_CHECK(n <= std::numeric_limits<std::uint32_t>::max(), "a vector of more than 2^32-1 elements");
    u32(static_cast<std::uint32_t>(n));
  }
  void str(const std::string& s) {
    count(s.size());
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  // 4-byte elements (float, int32, uint32) without a count.
  template <class T>
  void words(const std::vector<T>& v) {
    static_assert(sizeof(T) == 4);
    if constexpr (kLittleHost) {
      const std::size_t at = bytes_.size();
      bytes_.resize(at + 4 * v.size());
      if (!v.empty()) std::memcpy(bytes_.data() + at, v.data(), 4 * v.size());
    } else {
      for (const T& x : v) u32(std::bit_cast<std::uint32_t>(x));
    }
  }
  template <class T>
  void counted_words(const std::vector<T>& v) {
    count(v.size());
    words(v);
  }
  // Bytes without a count.
  void raw(const std::vector<std::uint8_t>& v) { bytes_.insert(bytes_.end(), v.begin(), v.end()); }
  void aabbs(const std::vector<Aabb>& v) {
    count(v.size());
    for (const Aabb& b : v) {
      for (float x : b.lo) f32(x);
      for (float x : b.hi) f32(x);
    }
  }
  void reserve(std::size_t n) { bytes_.reserve(n); }
  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

// Reads little-endian fields from a payload; every read is bounds-checked, and counts are checked
// against the bytes left before anything is allocated.
class In {
 public:
  explicit In(std::span<const std::uint8_t> p) : p_(p) {}

  std::size_t left() const { return p_.size() - pos_; }

  std::uint8_t u8(const char* field) {
    need(1, field);
    return p_[pos_++];
  }
  bool boolean(const char* field) {
    const std::uint8_t v = u8(field);
    if (v > 1) throw InputError(fmt::format("field '{}' is {}, not 0 or 1", field, v));
    return v == 1;
  }
  std::uint32_t u32(const char* field) {
    need(4, field);
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p_[pos_++]) << (8 * i);
    return v;
  }
  std::uint64_t u64(const char* field) {
    need(8, field);
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p_[pos_++]) << (8 * i);
    return v;
  }
  std::int32_t i32(const char* field) { return static_cast<std::int32_t>(u32(field)); }
  float f32(const char* field) { return std::bit_cast<float>(u32(field)); }
  double f64(const char* field) { return std::bit_cast<double>(u64(field)); }

  // An enum stored as one byte with values 0..max.
  template <class E>
  E enumeration(const char* field, E max) {
    const std::uint8_t v = u8(field);
    if (v > static_cast<std::uint8_t>(max))
      throw InputError(fmt::format("field '{}' is {}, outside the valid values 0..{}", field, v,
                                   static_cast<unsigned>(max)));
    return static_cast<E>(v);
  }

  // A u32 element count whose elements (elem_bytes each) must fit in the bytes left.
  std::size_t count(std::size_t elem_bytes, const char* field) {
    const std::uint32_t n = u32(field);
    if (n > left() / elem_bytes)
      throw InputError(fmt::format("field '{}' counts {} elements of {} bytes, but only {} payload bytes are left "
                                   "(it decodes short)", field, n, elem_bytes, left()));
    return n;
  }
  std::string str(std::size_t max_bytes, const char* field) {
    const std::size_t n = count(1, field);
    if (n > max_bytes)
      throw InputError(fmt::format("field '{}' is a string of {} bytes, above the limit of {}", field, n, max_bytes));
    std::string s(reinterpret_cast<const char*>(p_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  // n 4-byte elements without a count (n already checked against left() by the caller or here).
  template <class T>
  void words(std::vector<T>& v, std::size_t n, const char* field) {
    static_assert(sizeof(T) == 4);
    if (n > left() / 4)
      throw InputError(fmt::format("field '{}' needs {} elements of 4 bytes, but only {} payload bytes are left "
                                   "(it decodes short)", field, n, left()));
    v.resize(n);
    if constexpr (kLittleHost) {
      if (n) std::memcpy(v.data(), p_.data() + pos_, 4 * n);
      pos_ += 4 * n;
    } else {
      for (T& x : v) x = std::bit_cast<T>(u32(field));
    }
  }
  template <class T>
  void counted_words(std::vector<T>& v, const char* field) {
    words(v, count(4, field), field);
  }
  // n bytes without a count.
  void raw(std::vector<std::uint8_t>& v, std::uint64_t n, const char* field) {
    if (n > left())
      throw InputError(fmt::format("field '{}' needs {} bytes, but only {} payload bytes are left (it decodes short)", field,
                                   n, left()));
    v.assign(p_.begin() + static_cast<std::ptrdiff_t>(pos_), p_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += static_cast<std::size_t>(n);
  }
  void aabbs(std::vector<Aabb>& v, const char* field) {
    v.resize(count(24, field));
    for (Aabb& b : v) {
      for (float& x : b.lo) x = f32(field);
      for (float& x : b.hi) x = f32(field);
    }
  }
  // The whole payload must be used: bytes left over mean a damaged or mismatched record.
  void finish() const {
    if (pos_ != p_.size())
      throw InputError(fmt::format("{} bytes are left over after the last field (the payload of {} bytes decodes long)",
                                   p_.size() - pos_, p_.size()));
  }

 private:
  void need(std::size_t n, const char* field) const {
    if (left() < n)
      throw InputError(fmt::format("the payload of {} bytes ends at byte {} while reading field '{}' (it decodes short)",
                                   p_.size(), pos_, field));
  }

  std::span<const std::uint8_t> p_;
  std::size_t pos_ = 0;
};

}  // namespace nbsim::trace::bytes
