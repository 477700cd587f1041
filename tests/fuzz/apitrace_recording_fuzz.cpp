// Fuzz target: the interposer's recording as `nbsim capture apitrace` reads it back
// (traces/capture/apps/recording.h RawReader): every frame read until the end or an InputError.
// Anything else is a finding: a crash, a hang, an allocation past the file's size, or an empty
// reason. Seeds: recordings written by tests/fuzz/corpus/fuzz_apitrace_recording/.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "model/common/error.h"
#include "traces/capture/apps/recording.h"
// The reader's source, compiled into this target (the capture library it belongs to needs GL).
#include "traces/capture/apps/recording.cpp"

namespace {

std::filesystem::path scratch() {
  const std::filesystem::path dir = std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
  return dir / ("nbsim_fuzz_recording_" + std::to_string(::getpid()) + ".raw");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file = scratch();
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) std::abort();
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    nbsim::apitrace::RawReader reader(file);
    while (reader.next()) {
    }
  } catch (const nbsim::InputError& e) {
    if (std::string(e.what()).empty()) std::abort();  // a refusal must say why
  }
  return 0;
}
