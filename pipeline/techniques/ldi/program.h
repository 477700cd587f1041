// The ldi technique's frame program (pipeline/sim/programs.h): its row of program_table().
#pragma once

#include "pipeline/sim/programs.h"

namespace nbsim::pipeline {

ProgramRow ldi_program();

}  // namespace nbsim::pipeline
