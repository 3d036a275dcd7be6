// A ray in a brick's index space for tests that call the per-ray kernels
// (renderer/raycast/kernel.h) with rays of their own making.
#pragma once

#include "raycast/kernel.h"

namespace pvr::core {

// A ray from its origin and step, invStep as raySetup makes it (0 where
// the step is 0); no lighting vectors.
inline RaySetup rayOf(const double origin[3], const double step[3]) {
  RaySetup r{};
  for (int a = 0; a < 3; ++a) {
    r.origin[a] = origin[a];
    r.step[a] = step[a];
    r.invStep[a] = step[a] != 0 ? 1.0 / step[a] : 0.0;
  }
  return r;
}

}  // namespace pvr::core
