// Small shared definitions of model/common.
#include "model/common/depth.h"
#include "model/common/error.h"
#include "model/common/storage.h"

#include <cstdio>
#include <cstdlib>

namespace nbsim {

std::string_view to_string(FarOp op) noexcept { return op == FarOp::Max ? "max" : "min"; }

std::string_view to_string(StorageFormat f) noexcept {
  return f == StorageFormat::F32 ? "f32" : f == StorageFormat::U24 ? "u24" : "u16";
}

std::optional<StorageFormat> parse_storage_format(std::string_view s) noexcept {
  if (s == "f32") return StorageFormat::F32;
  if (s == "u24") return StorageFormat::U24;
  if (s == "u16") return StorageFormat::U16;
  return std::nullopt;
}

DepthImage::DepthImage(int w, int h, float fill)
    : width(w), height(h), texels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}

void panic(const char* file, int line, const char* condition, const std::string& message) {
  std::fprintf(stderr, "nbsim: internal error (a bug, please report it) at %s:%d: %s: %s\n", file, line,
               condition, message.c_str());
  std::abort();
}

}  // namespace nbsim
