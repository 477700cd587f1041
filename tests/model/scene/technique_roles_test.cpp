// The draw roles' table (model/scene/technique_roles.h): the core roles, then each technique's of
// the registration list, every value named once, and the largest value the trace format accepts.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "model/scene/technique_roles.h"

namespace nbsim::scene {
namespace {

TEST(TechniqueRolesTest, EveryRoleUpToTheLargestHasOneName) {
  std::set<std::string> names;
  for (unsigned v = 0; v <= kMaxDrawRole; ++v) {
    const std::string name(to_string(static_cast<DrawRole>(v)));
    EXPECT_FALSE(name.empty() || name == "?") << "role " << v << " has no name";
    EXPECT_TRUE(names.insert(name).second) << "role " << v << " repeats the name '" << name << "'";
  }
  EXPECT_EQ(names.size(), kFirstTechniqueRole + kTechniqueRoles.size());
}

TEST(TechniqueRolesTest, TechniqueRolesFollowTheCoreOnesInListOrder) {
  ASSERT_FALSE(kTechniqueRoles.empty());
  for (std::size_t i = 0; i < kTechniqueRoles.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(kTechniqueRoles[i].role), kFirstTechniqueRole + i);
    EXPECT_EQ(to_string(kTechniqueRoles[i].role), kTechniqueRoles[i].name);
  }
  EXPECT_EQ(kMaxDrawRole, static_cast<unsigned>(kTechniqueRoles.back().role));
}

TEST(TechniqueRolesTest, AValueAboveTheLargestHasNoName) {
  EXPECT_EQ(to_string(static_cast<DrawRole>(kMaxDrawRole + 1)), "?");
}

}  // namespace
}  // namespace nbsim::scene
