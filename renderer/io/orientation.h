// A file's orientation in the space its header names (NRRD "space
// directions", NIfTI qform/sform), and the source that shows its voxels on
// an axis-aligned grid of that space.
//
// A scan stored with flipped or permuted axes (radiological left-right,
// slices from head to foot, sagittal slices) is a signed permutation of the
// space's axes: reading the voxels in the other order gives an axis-aligned
// grid in the scanner's frame, exactly. A truly oblique scan (index axes
// rotated against the space's) is shown on the nearest axes and says by how
// many degrees it is off in describe(), which status shows; the renderer's
// grid is axis-aligned (ARCHITECTURE.md, "Grid").
#pragma once

#include <array>
#include <memory>
#include <string_view>

#include "../grid.h"
#include "volume_io.h"

namespace pvr::core {

// Index to space: the position of node (i, j, k) is origin + i * axes[0] +
// j * axes[1] + k * axes[2].
struct IndexFrame {
  std::array<Vec3, 3> axes{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  Vec3 origin{0, 0, 0};
};

struct Orientation {
  std::array<int, 3> fileAxis{0, 1, 2};  // space axis w shows the file's index axis fileAxis[w] ...
  std::array<bool, 3> flipped{};          // ... read from its last node to its first
  double obliqueDegrees = 0;              // the largest angle between an index axis and its space axis
  GridGeometry grid;                      // the axis-aligned grid in space
  // True when the voxels must be read in another order than the file's.
  bool reorders() const;
};

// The orientation of a file of `dims` nodes with `frame`. Throws
// pvr::Error(kBadFile) naming `where` when an axis has zero or non-finite
// length or two index axes lie nearest the same space axis.
Orientation orientationOf(const IndexFrame& frame, IVec3 dims, std::string_view where);

// `inner`, whose grid is the file's index grid, shown on `o.grid`: boxes
// map to the file's, voxels are transposed and flipped after each read.
// Its caveat() is obliqueWarning(o). Returns inner itself when nothing
// reorders and the file is not oblique.
std::unique_ptr<VolumeSource> reoriented(std::unique_ptr<VolumeSource> inner, const Orientation& o);

// " (oblique by 12.3 degrees: shown on the nearest axes)", or "".
std::string obliqueNote(const Orientation& o);

// The warning the catalog, `list status` and `:s info` give for an oblique
// file: "oblique orientation (12.3 degrees off the axes): rendered
// axis-aligned on the nearest signed axes", or "" when it is not oblique.
std::string obliqueWarning(const Orientation& o);

}  // namespace pvr::core
