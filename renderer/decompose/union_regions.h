// Decomposing a scene of several volumes over the union of their domains.
//
// The k-d tree (kd_tree.h) splits a grid by node planes; over several
// volumes it splits unionGrid(), a grid laid over the union box whose
// spacing on each axis is the finest of the volumes' there, so planes can
// fall as finely as the finest data needs. Each leaf is a rank's region
// (regionOf), and visibility order and every compositing strategy take the
// tree as for one volume. A rank holds, of each volume, the nodes
// volumeBoxFor() names: those around its region that the ray caster reads
// for the pieces of rays it owns (may be none).
#pragma once

#include <vector>

#include "../grid.h"
#include "../region.h"
#include "kd_tree.h"

namespace pvr::core {

// A grid over the union of the grids' domains. Throws pvr::Error for an
// empty list.
GridGeometry unionGrid(const std::vector<GridGeometry>& grids);

// The world box of `rank`'s leaf of a tree built over unionGrid(), its
// faces on the union's outside made infinite (region.h).
WorldRegion regionOf(const KdTree& tree, int rank);

// The nodes of `grid` a brick owning `region` reads at this step: every
// node within one step of the region (a volume's sample stands for a
// stretch up to a step away from it, mix_kernel.h) plus three layers for
// gradients and rounding, clipped to the grid; empty (NodeBox::empty())
// when the volume lies farther away than that.
NodeBox volumeBoxFor(const GridGeometry& grid, const WorldRegion& region, double step);

// The nodes of `grid` whose positions lie in `region` (half-open, as the
// ray caster's ownership): the regions of one tree partition each
// volume's nodes, so counting these counts every node once. May be empty.
NodeBox nodesIn(const GridGeometry& grid, const WorldRegion& region);

}  // namespace pvr::core
