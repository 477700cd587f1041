// GL's eight comparison functions as a table: whether each passes when the incoming value is below,
// equal to or above the stored one. The depth test (incoming fragment depth against the stored
// depth) and the stencil test (the reference against the stored value, GL: "LESS passes if ref <
// stored") use the same functions, so both suites check against this one table.
#pragma once

#include <array>

#include "model/raster/depth_test.h"

namespace nbsim::raster::testing {

struct CompareRow {
  DepthFunc f;
  bool below, equal, above;
};

inline constexpr std::array<CompareRow, 8> kCompareFuncs = {{
    {DepthFunc::Never, false, false, false},
    {DepthFunc::Less, true, false, false},
    {DepthFunc::Equal, false, true, false},
    {DepthFunc::Lequal, true, true, false},
    {DepthFunc::Greater, false, false, true},
    {DepthFunc::NotEqual, true, false, true},
    {DepthFunc::Gequal, false, true, true},
    {DepthFunc::Always, true, true, true},
}};

}  // namespace nbsim::raster::testing
