// Fuzz target: a sweep file as `nbsim explore` reads it (pipeline/explore/sweep.h): the text
// within the JSON limits, the sweep's structure, its point count (refused above the limit before
// anything is built), and the expanded points. Traces and config keys are not opened or checked
// here (they are files and the schema: other targets). Anything but an InputError is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "pipeline/explore/sweep.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const nlohmann::ordered_json j = nbsim::config::parse_input_ordered(text, "fuzz sweep", true);
    const nbsim::explore::SweepSpec spec = nbsim::explore::parse_sweep(j, "fuzz sweep");
    const auto points = nbsim::explore::expand(spec);
    (void)nbsim::explore::parameter_keys(spec);
    (void)points.size();
  } catch (const nbsim::InputError&) {
    // refused cleanly
  }
  return 0;
}
