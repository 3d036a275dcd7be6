// A whole volume's KernelParams with pre-integration on, set up as the
// renderer sets them up per frame, for tests that call the kernels directly.
#pragma once

#include <cstdint>
#include <vector>

#include "camera.h"
#include "raycast/kernel.h"

#include "raycast/kernel_setup.h"
#include "raycast/macrocells.h"
#include "transfer.h"

namespace pvr::core {

class PreintegratedKernel {
 public:
  PreintegratedKernel(const Brick& volume, const TransferFunctionSpec& tf, const RenderOptions& options)
      : macrocells_(volume), table_(tf, options.step), preintegrated_(tf),
        specular_(specularTable(options.shading.shininess)) {
    macrocells_.classify(table_, false);
    setBrick(params_, volume, macrocells_);
    setTables(params_, table_, &preintegrated_, options.step);
    setOptions(params_, options, specular_.data());
  }
  PreintegratedKernel(const PreintegratedKernel&) = delete;
  PreintegratedKernel& operator=(const PreintegratedKernel&) = delete;

  const KernelParams& params() const { return params_; }

  // f(ray, first, last) for every pixel's ray with samples [first, last]
  // in the volume, lit from one fixed direction.
  template <typename F>
  void forEachRay(const Camera& camera, const GridGeometry& grid, double step, F f) const {
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        const RaySetup ray = raySetup(camera.ray(x, y), grid, step, normalize(Vec3{0.2, 0.4, -1}));
        std::int64_t first, last;
        if (kernel::sampleRange(params_, ray, first, last)) f(ray, first, last);
      }
  }

 private:
  MacrocellGrid macrocells_;
  TransferTable table_;
  PreintegratedTable preintegrated_;
  std::vector<float> specular_;
  KernelParams params_;
};

}  // namespace pvr::core
