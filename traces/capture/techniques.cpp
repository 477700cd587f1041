// The technique table (technique.h): the row of each technique of the registration list
// (cmake/NbsimTechniques.cmake), each defined in its folder traces/capture/<name>/.
#include "traces/capture/technique.h"

namespace nbsim::capture {

const std::vector<TechniqueRow>& technique_table() {
#define NBSIM_TECHNIQUE_ROW(name) name##_technique(),
  static const std::vector<TechniqueRow> table = {NBSIM_EACH_TECHNIQUE(NBSIM_TECHNIQUE_ROW)};
#undef NBSIM_TECHNIQUE_ROW
  return table;
}

const std::string& default_technique() { return technique_table().front().info.name; }

const TechniqueRow& find_technique(std::string_view name) { return find_row(technique_table(), name, "technique"); }

}  // namespace nbsim::capture
