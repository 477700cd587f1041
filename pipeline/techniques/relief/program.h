// The relief technique's frame program (pipeline/sim/programs.h): its row of program_table().
#pragma once

#include "pipeline/sim/programs.h"

namespace nbsim::pipeline {

ProgramRow relief_program();

}  // namespace nbsim::pipeline
