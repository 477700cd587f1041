// The shadows technique's declared results (pipeline/techniques/results.h): its row of technique_results().
#pragma once

#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

TechniqueResults shadows_results();

}  // namespace nbsim::techniques
