// The occlusion_culling technique's frame program (pipeline/sim/programs.h): its row of program_table().
#pragma once

#include "pipeline/sim/programs.h"

namespace nbsim::pipeline {

ProgramRow occlusion_culling_program();

}  // namespace nbsim::pipeline
