// Quality chosen by error (sampling.target_psnr, raycast/step_levels.h):
// the target is met against a fine reference on a procedural scene and on
// real volumes, with fewer samples than the finest step would take.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include "io/volume_io.h"
#include "raycast/raycaster.h"
#include "raycast/step_levels.h"
#include "reference.h"
#include "scene.h"
#include "scene_volume.h"
#include "test_files.h"

namespace pvr::core {

namespace {

namespace fs = std::filesystem;


// Renders an example scene at `side` x `side` pixels with the target, and
// its reference (dt = a 32nd of a voxel); returns the PSNR and the samples
// taken against those of the finest level everywhere.
struct Outcome {
  double psnr = 0;
  std::uint64_t samples = 0, finestSamples = 0;
  double finestPsnr = 0;
};
Outcome renderAtTarget(const std::string& sceneFile, double target, int side) {
  Scene scene = loadSceneFile(sceneFile);
  scene.image.width = scene.image.height = side;
  const auto source = openSceneVolume(scene.volumes.front().source);
  resolveDefaults(scene, source->grid());
  const Brick volume = source->readAll();
  const Camera camera(scene.camera, side, side);
  ReferenceOptions ro;
  ro.step = volume.grid().minSpacing() / 32;
  ro.shading = scene.shading;
  const Image reference = renderReference(ReferenceVolume(volume), scene.volumes.front().transfer, camera, ro, pool());

  RenderOptions o = renderOptionsFor(scene);
  o.targetPsnr = target;
  o.preintegrated = false;  // the phantom's scene asks for it; the target chooses plain steps
  BrickRenderer r(volume);
  r.classify(scene.volumes.front().transfer, o);
  RenderStats stats;
  Outcome out;
  out.psnr = compareImages(r.render(camera, o, pool(), &stats).toFullFrame(), reference).psnr;
  out.samples = stats.samples;
  RenderOptions finest = renderOptionsFor(scene);
  finest.step = fineStep(o.step);
  finest.preintegrated = false;
  BrickRenderer f(volume);
  f.classify(scene.volumes.front().transfer, finest);
  out.finestPsnr = compareImages(f.render(camera, finest, pool(), &stats).toFullFrame(), reference).psnr;
  out.finestSamples = stats.samples;
  return out;
}

std::string exampleScene(const std::string& name) {
  return (test::kSourceRoot / "examples" / "scenes" / name).string();
}

}  // namespace

// The target is a bound on the image's RMSE (PSNR with peak 1): met on the
// Shepp-Logan phantom (jumps), and on three real volumes, shaded, where
// the lighting varies with the gradient.
TEST_CASE("a target PSNR is met against a fine reference", "[levels]") {
  for (const char* name : {"default.json", "mri_head.json", "water_density.json", "orbital_oxirane.json"}) {
    const std::string file = exampleScene(name);
    const Scene probe = loadSceneFile(file);
    if (!probe.volumes.front().source.file.empty() && !fs::exists(probe.volumes.front().source.file)) {
      WARN("skipped: " << probe.volumes.front().source.file << " does not exist");
      continue;
    }
    for (double target : {40.0, 55.0}) {
      const Outcome o = renderAtTarget(file, target, 40);
      INFO(name << " at " << target << " dB: PSNR " << o.psnr << ", samples " << o.samples << " (finest step "
                << o.finestSamples << ", PSNR " << o.finestPsnr << ")");
      CHECK(o.psnr >= target);
      CHECK(o.samples < o.finestSamples);
    }
  }
}

// The levels follow the error model: a smooth field under a steep transfer
// function needs fine steps where the function changes and coarse ones
// where it is flat; a higher target never coarsens a macrocell.
TEST_CASE("step levels vary by region and refine with the target", "[levels]") {
  const GridGeometry grid = cubeGrid(33);
  const Brick volume = makeVolume(grid, ScalarType::kFloat32, [](Vec3 p) {
    const Vec3 q = (p - Vec3{16, 16, 16}) * (1.0 / 16);
    return marschnerLobb(q);
  });
  TransferFunctionSpec tf;
  tf.points = {{0, 1, 1, 1, 0}, {0.45, 1, 1, 1, 0}, {0.55, 1, 0.5, 0.2, 0.6}, {1, 1, 0.5, 0.2, 0.6}};
  tf.unitDistance = 1;
  StepLevels low(volume, 0.5), high(volume, 0.5);
  low.choose(tf, 35, 0);
  high.choose(tf, 60, 0);
  const std::size_t n = std::size_t(low.count().product());
  const std::set<int> lowLevels(low.levels(), low.levels() + n);
  CHECK(lowLevels.size() >= 2);
  for (std::size_t i = 0; i < n; ++i) CHECK(high.levels()[i] <= low.levels()[i]);
  CHECK(*std::min_element(high.levels(), high.levels() + n) < *std::min_element(low.levels(), low.levels() + n));
}

// The model's two regimes: quadratic in the step where the integrand is
// piecewise linear and resolved, linear (bounded by the jump) where not.
TEST_CASE("levelError is quadratic for smooth integrands and bounded by a jump", "[levels]") {
  CHECK(levelError(0.5, 1, 1e-3, 100) == Approx(levelError(1, 1, 1e-3, 100) / 4));
  CHECK(levelError(8, 0.1, 0.1, 100) == Approx(8 * 0.1 / std::sqrt(12.0)));
  CHECK(levelError(1, 0, 0, 0) == 0);
  CHECK(levelBudget(40) == Approx(10 * levelBudget(60)));
}

}  // namespace pvr::core
