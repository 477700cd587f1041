// For tests of technique chunks: a decoded record's vector field by name (a test failure, and an
// empty vector, when the record has none).
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "model/scene/frame.h"

namespace nbsim::testing {

template <class T>
const std::vector<T>& field(const scene::TechniqueRecord& r, const std::string& name) {
  for (const auto& f : r.fields)
    if (f.name == name) return std::get<std::vector<T>>(f.value);
  static const std::vector<T> none;
  ADD_FAILURE() << "no field " << name;
  return none;
}

}  // namespace nbsim::testing
