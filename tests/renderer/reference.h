// A reference integrator for the rendering contract, in double precision.
//
// It renders what the ray caster renders, far more accurately and far more
// slowly: the same camera rays; the exact chord of each ray through the
// domain box, clipped to t >= 0 as the caster's samples are; the
// emission-absorption integral of ARCHITECTURE.md by the midpoint rule on a
// tiny substep dt with the exact attenuation 1 - exp(-tau dt) of each
// substep; trilinear reconstruction of the voxels in double; classification
// by evaluateMedium (the continuous transfer function, no tables); and the
// caster's shading model in double. Its quadrature error is O(dt^2) for a
// smooth integrand, so dt = h / 32 puts it about three orders of magnitude
// below the error of a caster stepping h.
//
// Used by the accuracy tests and by bench/speed_vs_error, so it knows
// nothing of Catch2.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "brick.h"
#include "camera.h"
#include "image.h"
#include "raycast/raycaster.h"
#include "scene.h"
#include "thread_pool.h"
#include "transfer.h"
#include "vec.h"

namespace pvr::core {

// Premultiplied RGBA in double.
struct RgbaD {
  double r = 0, g = 0, b = 0, a = 0;
};

// The voxels of a whole volume as double, with the caster's reconstruction.
class ReferenceVolume {
 public:
  // `whole` must store every node of its grid.
  explicit ReferenceVolume(const Brick& whole);

  const GridGeometry& grid() const { return grid_; }
  double node(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return v_[std::size_t((k * grid_.dims.y + j) * grid_.dims.x + i)];
  }
  // Trilinear value at a position in index units (node (i,j,k) at (i,j,k)).
  // The cell is floor(u) clamped into [0, dims - 2] on each axis, as in the
  // caster, so a position on a node plane reads the same eight voxels (it
  // matters beside non-finite voxels, which make their cells non-finite).
  double value(Vec3 u) const;
  // The caster's gradient in world units: per axis a central difference
  // over one voxel each way, the two positions clamped into the domain,
  // divided by their distance times the spacing (0 where that distance is 0).
  Vec3 gradient(Vec3 u) const;

 private:
  GridGeometry grid_;
  std::vector<double> v_;
};

// The part [t0, t1] of a ray inside the closed domain box, with t0 >= 0.
// A grid one node thick on some axis has no cells: no chord.
struct Chord {
  double t0 = 0, t1 = 0;
  bool hit = false;
  double length() const { return hit ? t1 - t0 : 0.0; }
};
Chord domainChord(const GridGeometry& grid, const Ray& ray);

struct ReferenceOptions {
  double step = 0;  // substep dt in world units, > 0 (the last one is shortened to the chord)
  ShadingSpec shading;
  // A ray stops once its transmittance falls below this; the colour it then
  // misses is at most this much (colours are at most 1 + specular).
  double minTransmittance = 1e-10;
};

// World-space unit vector towards the light: the shading spec's camera-space
// direction through the camera, as the caster does it.
Vec3 referenceLight(const Camera& camera, const ShadingSpec& shading);

// One ray: the emission-absorption integral over its domain chord.
// `tf` must be resolved (unitDistance > 0).
RgbaD integrateRay(const ReferenceVolume& volume, const TransferFunctionSpec& tf, const Ray& ray,
                   Vec3 lightWorld, const ReferenceOptions& options);

// Every pixel of `camera`, rows spread over `pool`.
Image renderReference(const ReferenceVolume& volume, const TransferFunctionSpec& tf,
                      const Camera& camera, const ReferenceOptions& options, ThreadPool& pool);

// One volume of a scene of several: its voxels and its (resolved)
// transfer function, both outliving the call.
struct ReferenceLayer {
  const ReferenceVolume* volume = nullptr;
  const TransferFunctionSpec* tf = nullptr;
};

// One ray through several volumes that may overlap (docs/scene.md,
// "Several volumes"). The ray is cut at every volume's chord ends; each
// segment between two cuts, where a fixed set of volumes is present, is
// integrated by the midpoint rule on equal substeps of at most
// options.step: at a substep the extinctions of the volumes present add,
// tau = sum tau_i, and the emitted colour is the extinction-weighted sum
// of their (shaded) colours, sum tau_i e_i / tau. One layer gives the
// one-volume integral above.
RgbaD integrateRay(const std::vector<ReferenceLayer>& layers, const Ray& ray, Vec3 lightWorld,
                   const ReferenceOptions& options);
Image renderReference(const std::vector<ReferenceLayer>& layers, const Camera& camera,
                      const ReferenceOptions& options, ThreadPool& pool);

// Closed form of a homogeneous medium over a chord of length L:
// alpha = 1 - exp(-tau L), colour = c * alpha.
RgbaD constantMedium(const Medium& medium, double length);

// Test scenes, shared by the tests and the benches.
//
// A whole-volume brick of `type` with node values f(world position): integer
// types round and clamp into their range, float32 stores f as it is.
Brick makeVolume(const GridGeometry& grid, ScalarType type,
                 const std::function<double(Vec3)>& f);

// The Marschner-Lobb test signal (Marschner and Lobb 1994, f_M = 6,
// alpha = 0.25) at a point of [-1, 1]^3; values lie in [0, 1].
double marschnerLobb(Vec3 p);

// n x n x n nodes, unit spacing, origin 0.
GridGeometry cubeGrid(std::int64_t n);

// A camera looking from eye to lookAt; `extent` is the view height in world
// units (orthographic) or the vertical field of view in degrees (perspective).
Camera makeCamera(Projection projection, Vec3 eye, Vec3 lookAt, Vec3 up, double extent,
                  int width, int height);

// A transfer function of `points` with its opacity per `unitDistance`.
TransferFunctionSpec transfer(std::vector<TransferPoint> points, double unitDistance = 1.0);

// Two worker threads for a test binary's renders.
ThreadPool& pool();

// Render options with everything else at its default (no early termination,
// skipping on, default shading parameters).
RenderOptions makeOptions(double step, bool preintegrated = false, bool shaded = false);

}  // namespace pvr::core
