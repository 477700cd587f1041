// Fuzz target: the depth-image loader (io/image_io.h read_depth, through the OpenImageIO
// backend), as `nbuffer build/query --depth FILE` reads a file. The first byte picks the file's
// extension (OpenImageIO picks its reader by extension first, then by content): .pfm, .exr, .tif,
// .png; the rest is the file. Anything but a DepthImage or an InputError naming the reason is a
// finding: a crash, a hang, an allocation past the declared-size limit, or an empty reason.
#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "model/common/error.h"
#include "io/image_io.h"

namespace {

constexpr std::array<const char*, 4> kExtensions = {".pfm", ".exr", ".tif", ".png"};

// One scratch file a process and extension, in memory where the machine has /dev/shm.
std::filesystem::path scratch(const char* extension) {
  const std::filesystem::path dir = std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
  return dir / ("nbsim_fuzz_depth_" + std::to_string(::getpid()) + extension);
}

}  // namespace

// Loads the OpenImageIO backend (about 260 libraries, seconds under ASan's slow unwinding) once,
// before the first input, so that its start-up does not count against an input's time limit.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  (void)nbsim::io::openimageio_version();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::filesystem::path file = scratch(kExtensions[data[0] % kExtensions.size()]);
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data) + 1, static_cast<std::streamsize>(size - 1));
  }
  try {
    const nbsim::DepthImage image = nbsim::io::read_depth(file);
    if (image.width < 1 || image.height < 1 || image.texels.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) std::abort();
  } catch (const nbsim::InputError& e) {
    // Refused: the message must say why, not end with an empty reason.
    const std::string what = e.what();
    if (what.empty() || what.back() == ' ' || what.back() == ':') {
      std::fprintf(stderr, "refusal without a reason: '%s'\n", what.c_str());
      std::abort();
    }
  }
  std::error_code ec;
  std::filesystem::remove(file, ec);
  return 0;
}
