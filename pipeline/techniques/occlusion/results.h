// The occlusion_culling technique's declared results (pipeline/techniques/results.h): its row of technique_results().
#pragma once

#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

TechniqueResults occlusion_culling_results();

}  // namespace nbsim::techniques
