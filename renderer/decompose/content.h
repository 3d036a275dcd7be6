// Non-empty content per block: the input of content-balanced k-d trees.
//
// Each rank counts the voxels of its own brick that the transfer function
// makes visible; the runtime sums the grids (an element-wise sum of
// `counts`, e.g. one MPI_Allreduce) and every rank then builds the same
// balanced tree. Bricks share their face nodes, so a brick counts a node
// only if it owns it half-open: lo <= n < hi on each axis, or n <= hi where
// the brick meets the grid's far edge (the rule the ray caster uses for
// samples). The counts of bricks that partition the grid then add up to
// the count of the whole volume, each voxel once.
#pragma once

#include <cstdint>

#include "../brick.h"
#include "../transfer.h"
#include "kd_tree.h"

namespace pvr::core {

class ThreadPool;

// A zero grid shaped for `grid`: ceil(cells / blockCells) blocks per axis,
// at least one (an axis without cells has one block). Node n falls in block
// min(n / blockCells, blocks - 1). Throws if a blockCells entry is < 1.
ContentGrid makeContentGrid(const GridGeometry& grid, IVec3 blockCells = {8, 8, 8});

// Counts the finite voxels of `brick` (owned half-open, see above) for
// which table.anyVisible(v, v): a value the transfer function gives
// non-zero opacity (conservatively, as macrocell skipping decides it).
// 8- and 16-bit data look each value up in a table built once per call.
// Layers of blocks spread over the pool's threads when one is given; the
// counts do not depend on it.
ContentGrid countContent(const Brick& brick, const TransferTable& table,
                         IVec3 blockCells = {8, 8, 8}, ThreadPool* pool = nullptr);

// sum += part, element by element. Throws if the two differ in shape.
void addContent(ContentGrid& sum, const ContentGrid& part);

// Throws pvr::Error unless `content` is shaped as makeContentGrid(grid, content.blockCells).
void checkContentGrid(const ContentGrid& content, const GridGeometry& grid);

std::uint64_t totalContent(const ContentGrid& content);

}  // namespace pvr::core
