// Fuzz target: the trace reader (traces/format/reader.h) on arbitrary bytes, as `nbsim trace
// verify` and replay read a file: the preamble, every chunk (framing, CRC-32, zstd, each record's
// decoder in version 1 and 2, technique chunks), the typed header and the per-frame rules. A
// damaged input must end in an InputError; anything else (a crash, a sanitizer report, an
// exception of another type, a timeout, an allocation past libFuzzer's limit) is a finding.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "model/common/error.h"
#include "traces/format/reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    nbsim::trace::FrameReader frames(nbsim::trace::TraceReader(std::vector<std::uint8_t>(data, data + size), "fuzz input"));
    std::size_t draws = 0;
    while (const auto frame = frames.next()) draws += frame->draws.size();
    (void)draws;
  } catch (const nbsim::InputError&) {
    // refused cleanly: what a damaged trace must get
  }
  return 0;
}
