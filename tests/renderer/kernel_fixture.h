// Kernel parameters (renderer/raycast/kernel.h) for tests that call the
// per-ray kernels directly: one brick, one transfer function, one set of
// render options, with the tables they point to kept alive beside them.
#pragma once

#include <vector>

#include "raycast/kernel_setup.h"
#include "raycast/macrocells.h"
#include "transfer.h"

namespace pvr::core {

// Skipping off (every macrocell visible) unless `skip`.
struct KernelFixture {
  MacrocellGrid macrocells;
  TransferTable table;
  std::vector<float> specular;
  KernelParams p;
  KernelFixture(const Brick& volume, const TransferFunctionSpec& tf, const RenderOptions& o, bool skip = false)
      : macrocells(volume), table(tf, o.step), specular(specularTable(o.shading.shininess)) {
    macrocells.classify(table, skip);
    setBrick(p, volume, macrocells);
    setTables(p, table, nullptr, o.step);
    setOptions(p, o, specular.data());
  }
};

}  // namespace pvr::core
