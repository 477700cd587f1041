// Fuzz target: the configuration inputs, as `--config FILE` and `--set unit.field=value` read them
// (model/config/json_input.h within its limits, then model/config/schema.h) over the N-buffer and
// Hi-Z units' keys, then the units' own validation. The first byte picks the path: even, the rest
// is a config file's text; odd, each line of the rest is one --set assignment. Anything but an
// InputError for a bad input is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "model/config/schema.h"
#include "model/hiz/hiz_config.h"
#include "model/nbuffer/unit_core.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  nbsim::nbuffer::NBufferUnitConfig nbuffer;
  nbsim::HiZUnitConfig hiz;
  nbsim::config::Schema schema;
  nbsim::nbuffer::NBufferUnitConfig::describe(schema, nbuffer);
  nbsim::HiZUnitConfig::describe(schema, hiz);
  try {
    if (data[0] % 2 == 0) {
      schema.apply(nbsim::config::parse_input(text, "fuzz config"), "fuzz config");
    } else {
      std::size_t start = 0;
      while (start <= text.size()) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        schema.set(std::string(text.substr(start, end - start)));
        start = end + 1;
      }
    }
    nbuffer.validate();
    hiz.validate();
    (void)schema.values().dump();
  } catch (const nbsim::InputError&) {
    // refused cleanly
  }
  return 0;
}
