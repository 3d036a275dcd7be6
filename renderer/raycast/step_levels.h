// Quality chosen by error: the step of each region, from a target PSNR.
//
// With sampling.target_psnr set, a ray is marched at one of kStepLevels
// steps, h * 2^l for level l, where the fine step h is the scene's step / 8
// (level 3 is the scene's own step). The level is chosen per macrocell from
// an error model: point sampling's error over a macrocell crossing grows
// with the square of the step where the integrand is smooth, and linearly
// where the transfer function changes faster than the step resolves
// (StepLevels::choose). A ray takes one level per block of kLevelBlock fine
// samples, aligned to the global sample index, so that every brick that
// holds part of a block takes the same samples in it (cast_ray_levels.h).
//
// A block reads the level at its middle, and the levels are eroded (each
// macrocell takes the finest within a block's reach), so that level holds
// along the whole block. Middles lie up to half a block outside the
// brick's owned box, so the field covers an extended layout of macrocells,
// whose value ranges come from the stored voxels: the brick needs
// levelGhostLayers() beyond its owned box (ghostLayers(), raycaster.h).
#pragma once

#include <cstdint>
#include <vector>

#include "../brick.h"
#include "../scene.h"
#include "../thread_pool.h"
#include "../transfer.h"

namespace pvr::core {

inline constexpr int kStepLevels = 7;        // h, 2h, ..., 64h
inline constexpr int kSceneStepLevel = 3;    // the scene's step is level 3: h = step / 8
inline constexpr int kLevelBlockShift = kStepLevels - 1;
inline constexpr std::int64_t kLevelBlock = std::int64_t(1) << kLevelBlockShift;  // fine samples per block

// The fine step h of a scene step.
inline double fineStep(double sceneStep) { return sceneStep / double(1 << kSceneStepLevel); }

// Node layers the level field reads beyond a brick's owned box at this
// scene step: half a block's length and the erosion's reach, rounded up,
// plus a macrocell and the layer around it that its value range includes.
int levelGhostLayers(const GridGeometry& grid, double sceneStep);

class StepLevels {
 public:
  // The value ranges of the macrocells within reach of the brick's owned
  // box (see the header comment), over the pool's threads when one is
  // given. Throws Error kInternal when the brick stores less than
  // levelGhostLayers(grid, sceneStep) beyond its owned box.
  StepLevels(const Brick& brick, double sceneStep, ThreadPool* pool = nullptr);

  // Picks every macrocell's level for the transfer function (resolved) and
  // the target (dB, > 0): the coarsest whose modelled error (levelError)
  // stays within the target's share of a macrocell, then the finest of
  // those within a block's reach. `shadingShare` is the
  // part of a sample's colour that shading varies (diffuse + specular; 0
  // unshaded).
  void choose(const TransferFunctionSpec& tf, double targetPsnr, double shadingShare);

  // Levels, count.x fastest; macrocell g (global index) is at
  // ((g.z - first.z) * count.y + g.y - first.y) * count.x + g.x - first.x.
  const std::uint8_t* levels() const { return levels_.data(); }
  IVec3 first() const { return first_; }
  IVec3 count() const { return count_; }
  // Macrocells of the whole domain per axis: positions clamp into them.
  IVec3 domainCount() const { return domainCount_; }
  double sceneStep() const { return sceneStep_; }

 private:
  const Brick& brick_;
  double sceneStep_ = 0;
  IVec3 first_, count_, domainCount_;
  std::int64_t spread_ = 0;       // the erosion's radius in macrocells
  std::vector<float> min_, max_;  // value range per macrocell (min > max: no finite node)
  std::vector<std::uint8_t> levels_;
};

// The modelled error of one macrocell crossing at a step of `steps` voxels
// for an integrand (per voxel of path) that varies by `variation` over the
// macrocell's value range and by at most `slope` per table entry across
// `entries` table entries of range: point sampling of a piecewise-linear
// integrand errs by at most step^2 / 8 times its slope changes, which add
// up to twice its steepest slope along the ray (the data's range crossed in
// a macrocell's 4 voxels); never more than half a step of the whole
// variation (a jump the step does not resolve). Exposed for tests.
double levelError(double steps, double variation, double slope, double entries);

// The error budget of one macrocell crossing for a target PSNR in dB.
double levelBudget(double targetPsnr);

}  // namespace pvr::core
