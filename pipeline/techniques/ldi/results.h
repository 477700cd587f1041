// The ldi technique's declared results (pipeline/techniques/results.h): its row of technique_results().
#pragma once

#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

TechniqueResults ldi_results();

}  // namespace nbsim::techniques
