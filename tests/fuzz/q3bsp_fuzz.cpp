// Fuzz target: a Quake 3 level as `nbsim capture ... --scene q3bsp --bsp FILE` reads it
// (traces/capture/q3bsp.h read_bsp: the header, the lumps, faces, meshes, Bezier patches and the
// entity text), at a small patch tessellation. Anything but a map or an InputError with a reason is a
// finding: a crash, a hang, an allocation past what the bytes can describe. Seeds:
// tests/fuzz/corpus/fuzz_q3bsp/ (a room and a patch map written as the tests' BspWriter writes them).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "model/common/error.h"
#include "traces/capture/q3bsp.h"
// The reader's source, compiled into this target (the capture library it belongs to needs GL).
#include "traces/capture/q3bsp.cpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    nbsim::capture::BspOptions options;
    options.patch_segments = 2;
    const nbsim::capture::BspMap m = nbsim::capture::read_bsp(std::span<const std::uint8_t>(data, size), "fuzz.bsp", options);
    if (m.indices.size() % 3 != 0) std::abort();  // triangles, whole
    for (const std::uint32_t i : m.indices)
      if (i >= m.vertices.size()) std::abort();  // every index names a vertex
  } catch (const nbsim::InputError& e) {
    if (std::string(e.what()).empty()) std::abort();  // a refusal must say why
  }
  return 0;
}
