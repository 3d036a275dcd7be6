// WorldRegion: the part of space one brick of a several-volume scene owns.
//
// A scene of several volumes is decomposed over the union of their domains
// (decompose/union_regions.h); each brick owns a world-space box of it and
// holds, of every volume, the nodes around that box. A sample or a piece
// of a ray belongs to the brick whose region holds its position (for a
// piece, its midpoint): half-open boxes, lo <= x < hi on every axis, so
// the regions of one decomposition partition space and every brick
// decides alike. Faces on the outside of the union are infinite, so a
// position rounded a hair outside the union still has an owner.
#pragma once

#include <limits>

#include "vec.h"

namespace pvr::core {

struct WorldRegion {
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();
  Vec3 lo{-kInfinity, -kInfinity, -kInfinity};
  Vec3 hi{kInfinity, kInfinity, kInfinity};

  // All of space: the whole scene in one brick.
  bool unbounded() const {
    for (int a = 0; a < 3; ++a)
      if (lo[a] != -kInfinity || hi[a] != kInfinity) return false;
    return true;
  }
  bool contains(const Vec3& x) const {
    for (int a = 0; a < 3; ++a)
      if (!(x[a] >= lo[a] && x[a] < hi[a])) return false;
    return true;
  }
};

}  // namespace pvr::core
