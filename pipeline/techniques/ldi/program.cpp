// The ldi technique's frame program; see program.h.
#include "pipeline/techniques/ldi/program.h"

#include "model/ldi/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Layered depth images (Trapp & Doellner): the peel replayed at the LDI's size (LDIL) with its own
// depth buffer and the strict compare against the previous layer, the model's LDI cropped and
// compressed and compared with GL's, and the parity test at GL's test points (LDIT).
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("an ldi trace peels and tests its own shape");
  Program p;
  auto unit = std::make_unique<ldi::LdiUnit>("ldi", c.registry, c.config.ldi, c.memory, c.config.depth.fused_interpolation);
  p.frames = unit.get();
  p.unit = std::move(unit);
  return p;
}

}  // namespace

ProgramRow ldi_program() {
  return {"ldi",
          "layered depth images and the volumetric parity test: GL's peel passes replayed at the LDI's size with the strict "
          "compare against the previous layer, the model's LDI, crop and compressed texture compared with GL's, and the parity "
          "test (uncompressed and compressed) at GL's test points against GL's answers and the exact reference",
          build};
}

}  // namespace nbsim::pipeline
