// The preprocessing of main before issue 11, kept here only as the
// benchmark's baseline (and to check that the new passes agree with it):
// a per-voxel value range in double, float macrocell bounds updated per
// voxel (up to 8 macrocells each), visibility in a byte array beside a
// 26-neighbour chamfer distance field, and content counts that ask the
// transfer table about every voxel.
#pragma once

#include <cstdint>
#include <vector>

#include "brick.h"
#include "decompose/content.h"
#include "transfer.h"

namespace pvr::bench {

struct OldMacrocells {
  core::MacrocellLayout layout;
  std::vector<float> min, max;
  std::vector<std::uint8_t> visible, distance;
};

core::ValueRange oldValueRange(const core::Brick& brick);
OldMacrocells oldMacrocellBounds(const core::Brick& brick);
void oldClassify(OldMacrocells& m, const core::TransferTable& table);
core::ContentGrid oldCountContent(const core::Brick& brick, const core::TransferTable& table);

}  // namespace pvr::bench
