// Small shared definitions of model/common.
#include "model/common/depth.h"
#include "model/common/error.h"
#include "model/common/names.h"
#include "model/common/storage.h"

#include <cstdio>
#include <cstdlib>

namespace nbsim {

std::string_view to_string(FarOp op) noexcept { return enum_name(kFarOpNames, op); }

std::string_view to_string(StorageFormat f) noexcept { return enum_name(kStorageFormatNames, f); }

std::optional<StorageFormat> parse_storage_format(std::string_view s) noexcept {
  return parse_enum_name<StorageFormat>(kStorageFormatNames, s);
}

DepthImage::DepthImage(int w, int h, float fill)
    : width(w), height(h), texels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}

void panic(const char* file, int line, const char* condition, const std::string& message) {
  std::fprintf(stderr, "nbsim: internal error (a bug, please report it) at %s:%d: %s: %s\n", file, line,
               condition, message.c_str());
  std::abort();
}

}  // namespace nbsim
