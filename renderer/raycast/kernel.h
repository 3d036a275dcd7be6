// The per-ray kernel: march one ray through one brick.
//
// Templated on the scalar type, shading and pre-integration, so the loop
// over samples branches on no configuration, allocates nothing and takes no
// lock. Everything a ray needs that does not change per ray lives in
// KernelParams, set up once per frame by raycaster.cpp.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "../image.h"
#include "../preintegration.h"
#include "specular_power.h"

namespace pvr::core {

// Entries of the table of x^shininess over [0, 1], interpolated linearly:
// the error stays below 2e-4 for shininess up to 64.
inline constexpr int kSpecularTableSize = 2048;

struct KernelParams {
  // Voxels of the stored box; index(i,j,k) = i*1 + j*strideY + k*strideZ + base.
  const void* voxels = nullptr;
  std::int64_t strideY = 0, strideZ = 0, base = 0;
  // log2 of strideY and strideZ where both are powers of two, else -1: the
  // batched kernel then finds voxel indices by shifts (voxelIndex8).
  int strideShift[2] = {-1, -1};
  bool indices32 = false;  // every stored voxel index fits an int32 (the batched kernel's lanes)
  // Owned box in index units, for membership: lo <= u < hi, or u <= hi where
  // the box meets the far edge of the grid (hiClosed).
  double ownLo[3], ownHi[3];
  bool hiClosed[3];
  // Cell clamps: a sample's cell index is clamped into [cellLo, cellHi]; the
  // owned clamp for samples, the stored clamp for reads around them.
  int ownCellLo[3], ownCellHi[3];
  int storedCellLo[3], storedCellHi[3];
  float domainMax[3];  // dims - 1: positions read around a sample stay in the domain
  float invSpacing[3];  // 1 / spacing, for world-space gradients
  // Macrocells.
  const std::uint8_t* distance = nullptr;  // MacrocellGrid::distance(): 0 = visible
  // The field a ray leaps by, by its direction octant (octantOf):
  // MacrocellGrid::leapFields(), or distance for every octant.
  const std::uint8_t* leapField[8] = {};
  int mcFirst[3], mcCount[3];
  // Every sample whose macrocell is visible lies in this box, index units
  // (the visible macrocells' box, MacrocellGrid::visibleFirst(), widened
  // against rounding; open where it reaches the brick's outer macrocells,
  // into which look-ups clamp); lo > hi when nothing is visible.
  double visibleLo[3] = {-1e30, -1e30, -1e30}, visibleHi[3] = {1e30, 1e30, 1e30};
  // Classification.
  const Rgba* table = nullptr;  // TransferTable entries (plain)
  int tableEntries = 0;
  float tableScale = 0, tableOffset = 0;
  // Table coordinates x < clearBelow or x >= clearAbove classify as fully
  // transparent (both entries classify1D reads are zero): the batched
  // kernel skips a batch whose samples all lie there (setTables).
  float clearBelow = 0, clearAbove = FLT_MAX;
  // One bit per voxel index: set where that cell's samples all classify
  // as transparent (ClearCells, clear_cells.h), null when none are known.
  const std::uint8_t* clearCells = nullptr;
  PreintegralTables preint;  // pre-integration's integral tables
  double stepLength = 0;     // world length of one step, h
  float earlyTermination = 1;
  // Shading (world space).
  float ambient = 0, diffuse = 0, specular = 0, shininess = 1;
  const float* specularTable = nullptr;  // kSpecularTableSize values of x^shininess, x in [0, 1]
  // A whole shininess's bits for the kernels that raise x^shininess by
  // steps (specular_power.h): 0 where bit k is set, 1 where clear.
  float powerFloor[kernel::kPowerBits] = {};
  // Quality chosen by error (step_levels.h, cast_ray_levels.h): the level
  // of each macrocell of StepLevels' layout, and per level l these
  // parameters with the table of a step of 2^l fine steps.
  const std::uint8_t* levels = nullptr;
  int lvFirst[3] = {0, 0, 0}, lvCount[3] = {0, 0, 0}, lvDomainLast[3] = {0, 0, 0};
  const KernelParams* atLevel = nullptr;
};

// One ray in the brick's index space: u(k) = origin + k * step.
struct RaySetup {
  double origin[3];
  double step[3];
  double invStep[3];  // 1 / step (0 where step is 0): macrocell exits without division
  double leapPerMacrocell;  // samples per macrocell edge along the ray's major axis
  float light[3];     // unit vector towards the light, world space
  float halfway[3];   // Blinn-Phong half vector, world space
};

// Rays a caster takes at once, neighbours along a row (castRays in
// cast_ray.h, renderTileRuns in tiles.h): a ray's walk through empty space
// is a chain of dependent look-ups, and the walks of four rays by turns
// overlap in the CPU (peer scene: 10-15 % less CPU time than one at a time;
// eight by turns gained nothing more). With AVX-512, sixteen (a tile's
// row): their look-ups go in the eight lanes of two vectors (walk_lanes.h;
// four lanes of 256 bits were no faster than four rays by turns,
// bench/results/walk.txt).
#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__FMA__)
#define PVR_HAVE_WALK_LANES 1
inline constexpr int kRaysAtOnce = 16;
#else
inline constexpr int kRaysAtOnce = 4;
#endif

struct RayResult {
  Rgba colour;
  std::uint64_t samples = 0;
  bool hit = false;
};

namespace kernel {

// What a ray has gathered so far, front to back: premultiplied colour and
// opacity, in double. A float sum stalls once a sample would add less than
// half an ulp of the running opacity (3e-8 near 1): a long ray of faint
// samples then stops short of the opacity it should reach (0.99998 instead
// of 0.999999 over 10^4 samples of 0.0014).
struct Accumulator {
  double r = 0, g = 0, b = 0, a = 0;

  // Composites c behind what was gathered: this = this over c.
  void addBehind(const Rgba& c) {
    const double t = 1.0 - a;
    r += t * c.r;
    g += t * c.g;
    b += t * c.b;
    a += t * c.a;
  }
  Rgba rgba() const { return {float(r), float(g), float(b), float(a)}; }
};

// The per-sample helpers below are always inlined: GCC inlines a large
// helper with one caller, but not one that several kernels' paths call
// (castRay's sample loop and its chord-end segments).
template <typename T>
[[gnu::always_inline]] inline float trilinear(const T* v, const KernelParams& p, float u0, float u1, float u2,
                       const int* cellLo, const int* cellHi) {
  const int i = std::clamp(int(u0), cellLo[0], cellHi[0]);
  const int j = std::clamp(int(u1), cellLo[1], cellHi[1]);
  const int k = std::clamp(int(u2), cellLo[2], cellHi[2]);
  const float fx = u0 - float(i), fy = u1 - float(j), fz = u2 - float(k);
  const T* c = v + (p.base + i + j * p.strideY + k * p.strideZ);
  const std::int64_t sy = p.strideY, sz = p.strideZ;
  const float c00 = float(c[0]) + fx * (float(c[1]) - float(c[0]));
  const float c10 = float(c[sy]) + fx * (float(c[sy + 1]) - float(c[sy]));
  const float c01 = float(c[sz]) + fx * (float(c[sz + 1]) - float(c[sz]));
  const float c11 = float(c[sz + sy]) + fx * (float(c[sz + sy + 1]) - float(c[sz + sy]));
  const float c0 = c00 + fy * (c10 - c00);
  const float c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

// A value read around a sample (gradient or pre-integration back end):
// clamped into the domain, from anywhere in the stored box.
template <typename T>
[[gnu::always_inline]] inline float around(const T* v, const KernelParams& p, float u0, float u1, float u2) {
  return trilinear(v, p, std::clamp(u0, 0.0f, p.domainMax[0]), std::clamp(u1, 0.0f, p.domainMax[1]),
                   std::clamp(u2, 0.0f, p.domainMax[2]), p.storedCellLo, p.storedCellHi);
}

// The least and greatest of the eight nodes `around` interpolates at this
// position: bounds the field in that cell, and so within the macrocell
// ranges that empty-space skipping classifies.
template <typename T>
[[gnu::always_inline]] inline void aroundRange(const T* v, const KernelParams& p, float u0, float u1, float u2,
                                               float& lo, float& hi) {
  const float u[3] = {std::clamp(u0, 0.0f, p.domainMax[0]), std::clamp(u1, 0.0f, p.domainMax[1]),
                      std::clamp(u2, 0.0f, p.domainMax[2])};
  int cell[3];
  for (int a = 0; a < 3; ++a) cell[a] = std::clamp(int(u[a]), p.storedCellLo[a], p.storedCellHi[a]);
  const T* c = v + (p.base + cell[0] + cell[1] * p.strideY + cell[2] * p.strideZ);
  const std::int64_t sy = p.strideY, sz = p.strideZ;
  const float n[8] = {float(c[0]),  float(c[1]),      float(c[sy]),      float(c[sy + 1]),
                      float(c[sz]), float(c[sz + 1]), float(c[sz + sy]), float(c[sz + sy + 1])};
  lo = hi = n[0];
  for (int i = 1; i < 8; ++i) {
    lo = std::min(lo, n[i]);
    hi = std::max(hi, n[i]);
  }
}

template <typename T>
inline bool finite(float s) {
  if constexpr (std::is_floating_point_v<T>) return std::fabs(s) <= FLT_MAX;
  return true;
}

inline Rgba lerp(const Rgba& a, const Rgba& b, float w) {
  return {a.r + w * (b.r - a.r), a.g + w * (b.g - a.g), a.b + w * (b.b - a.b), a.a + w * (b.a - a.a)};
}

[[gnu::always_inline]] inline Rgba classify1D(const KernelParams& p, float s) {
  const float x = std::clamp(s * p.tableScale + p.tableOffset, 0.0f, float(p.tableEntries - 1));
  const int i = std::min(int(x), p.tableEntries - 2);
  return lerp(p.table[i], p.table[i + 1], x - float(i));
}

// The integrals at a pre-integrated segment's end. A non-finite scalar is
// looked up as 0: the caller, who knows, makes its segments empty.
template <typename T>
[[gnu::always_inline]] inline preint::End segmentEnd(const KernelParams& p, float value) {
  return preint::endAt(p.preint, finite<T>(value) ? value : 0.0f);
}

// Pre-integration's scalar at sample node k from the samples at k - 1, k,
// k + 1: s_k - (s_{k-1} - 2 s_k + s_{k+1}) / 12. The segment model takes the
// scalar linear between nodes, but the field curves between samples; with
// these node values each segment's mean scalar is the mean of the cubic
// through the four samples around it (weights -1, 13, 13, -1 over 24), so
// the linear path's first-order error in the transfer function's integral
// (twice point sampling's, of the other sign) cancels. The node stays
// within [lo, hi], the range of the cell it lies in (aroundRange()), so a
// segment between two empty macrocells stays empty and skipping them
// changes nothing. A non-finite neighbour leaves the sample as it is.
template <typename T>
[[gnu::always_inline]] inline float curvedNode(float before, float at, float after, float lo, float hi) {
  const float corrected = at - (before - 2.0f * at + after) * (1.0f / 12.0f);
  return finite<T>(corrected) ? std::min(std::max(corrected, lo), hi) : at;
}

// A pre-integrated run's state at segment s: the samples at s - 1, s and
// s + 1 (curvedNode() needs both neighbours of a node) and the integrals at
// the segment's front node.
struct PreintWindow {
  float before = 0, front = 0, back = 0;
  preint::End frontEnd;
  // On to segment s + 1, given the sample at s + 2 and the new front end.
  void advance(float next, const preint::End& end) {
    before = front;
    front = back;
    back = next;
    frontEnd = end;
  }
};

// The window at segment s, every sample at its position by the same
// formula as the loops', so a run that starts at s reads what a run
// carried there would have.
template <typename T>
inline PreintWindow preintWindow(const KernelParams& p, const RaySetup& ray, std::int64_t s) {
  const T* v = static_cast<const T*>(p.voxels);
  const float o0 = float(ray.origin[0]), o1 = float(ray.origin[1]), o2 = float(ray.origin[2]);
  const float d0 = float(ray.step[0]), d1 = float(ray.step[1]), d2 = float(ray.step[2]);
  auto at = [&](std::int64_t k) { return around(v, p, o0 + float(k) * d0, o1 + float(k) * d1, o2 + float(k) * d2); };
  PreintWindow w;
  w.before = at(s - 1);
  w.front = at(s);
  w.back = at(s + 1);
  float lo, hi;
  aroundRange(v, p, o0 + float(s) * d0, o1 + float(s) * d1, o2 + float(s) * d2, lo, hi);
  w.frontEnd = segmentEnd<T>(p, curvedNode<T>(w.before, w.front, w.back, lo, hi));
  return w;
}

// Central differences of the reconstructed field at a sample at least one
// voxel inside the domain, whose 4x4x4 node neighbourhood is stored: each
// component is the trilinear interpolation of the nodes' central
// differences, so the 32 nodes around the sample are read once instead of
// six full reconstructions. Returns false elsewhere (near the domain's
// faces), where the clamped general form applies; both agree in the
// interior up to rounding, and whole volume and bricks take the same path
// for the same sample.
template <typename T>
[[gnu::always_inline]] inline bool interiorGradient(const T* v, const KernelParams& p, float u0,
                                                    float u1, float u2, float g[3]) {
  if (!(u0 >= 1.0f && u1 >= 1.0f && u2 >= 1.0f && u0 <= p.domainMax[0] - 1.0f &&
        u1 <= p.domainMax[1] - 1.0f && u2 <= p.domainMax[2] - 1.0f))
    return false;
  const int i = int(u0), j = int(u1), k = int(u2);
  if (i - 1 < p.storedCellLo[0] || j - 1 < p.storedCellLo[1] || k - 1 < p.storedCellLo[2] ||
      i + 1 > p.storedCellHi[0] || j + 1 > p.storedCellHi[1] || k + 1 > p.storedCellHi[2])
    return false;
  const float fx = u0 - float(i), fy = u1 - float(j), fz = u2 - float(k);
  const std::int64_t sy = p.strideY, sz = p.strideZ;
  const T* c = v + (p.base + i + j * sy + k * sz);
  auto at = [&](std::int64_t dx, std::int64_t dy, std::int64_t dz) __attribute__((always_inline)) {
    return float(c[dx + dy * sy + dz * sz]);
  };
  auto bilinear = [](float w1, float w2, float a00, float a10, float a01, float a11)
                      __attribute__((always_inline)) {
    const float a0 = a00 + w1 * (a10 - a00), a1 = a01 + w1 * (a11 - a01);
    return a0 + w2 * (a1 - a0);
  };
  // Central difference along x at node (i + dx, j + dy, k + dz), interpolated along x.
  auto dX = [&](int dy, int dz) __attribute__((always_inline)) {
    return (1.0f - fx) * (at(1, dy, dz) - at(-1, dy, dz)) + fx * (at(2, dy, dz) - at(0, dy, dz));
  };
  auto dY = [&](int dx, int dz) __attribute__((always_inline)) {
    return (1.0f - fy) * (at(dx, 1, dz) - at(dx, -1, dz)) + fy * (at(dx, 2, dz) - at(dx, 0, dz));
  };
  auto dZ = [&](int dx, int dy) __attribute__((always_inline)) {
    return (1.0f - fz) * (at(dx, dy, 1) - at(dx, dy, -1)) + fz * (at(dx, dy, 2) - at(dx, dy, 0));
  };
  g[0] = bilinear(fy, fz, dX(0, 0), dX(1, 0), dX(0, 1), dX(1, 1)) * 0.5f * p.invSpacing[0];
  g[1] = bilinear(fx, fz, dY(0, 0), dY(1, 0), dY(0, 1), dY(1, 1)) * 0.5f * p.invSpacing[1];
  g[2] = bilinear(fx, fy, dZ(0, 0), dZ(1, 0), dZ(0, 1), dZ(1, 1)) * 0.5f * p.invSpacing[2];
  return true;
}

// The world-space gradient at a sample by central differences of the
// reconstructed field, one voxel either side, clamped into the domain (one
// sided at its faces). interiorGradient() where it applies.
template <typename T>
[[gnu::always_inline]] inline void gradient(const T* v, const KernelParams& p, float u0, float u1, float u2,
                                            float g[3]) {
  if (interiorGradient(v, p, u0, u1, u2, g)) return;
  const float u[3] = {u0, u1, u2};
  for (int a = 0; a < 3; ++a) {
    float up[3] = {u0, u1, u2}, dn[3] = {u0, u1, u2};
    up[a] = std::min(u[a] + 1.0f, p.domainMax[a]);
    dn[a] = std::max(u[a] - 1.0f, 0.0f);
    const float dist = up[a] - dn[a];
    const float diff = around(v, p, up[0], up[1], up[2]) - around(v, p, dn[0], dn[1], dn[2]);
    g[a] = dist > 0 ? diff / dist * p.invSpacing[a] : 0.0f;
  }
}

// Blinn-Phong with a central-difference gradient, two-sided. A zero or
// undefined gradient (homogeneous or non-finite data) is lit head-on.
// (shade_lanes.h lights eight samples of a batch alike.) kPower: how
// nh^shininess is raised (specular_power.h).
template <typename T, int kPower = kTablePower>
[[gnu::always_inline]] inline Rgba shade(const T* v, const KernelParams& p, const RaySetup& ray, float u0, float u1,
                  float u2, Rgba c) {
  float g[3];
  gradient(v, p, u0, u1, u2, g);
  const float gg = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
  float lit = p.ambient + p.diffuse;
  float spec = 0;
  if (gg > 1e-20f && gg <= FLT_MAX) {
    const float inv = 1.0f / std::sqrt(gg);
    const float nl = std::fabs((g[0] * ray.light[0] + g[1] * ray.light[1] + g[2] * ray.light[2]) * inv);
    const float nh = std::fabs((g[0] * ray.halfway[0] + g[1] * ray.halfway[1] + g[2] * ray.halfway[2]) * inv);
    lit = p.ambient + p.diffuse * nl;
    // nh^shininess by steps or from a table (raycaster.cpp): powf was a
    // tenth of a shaded frame.
    if constexpr (kPower == kTablePower) {
      const float x = std::min(nh, 1.0f) * float(kSpecularTableSize - 1);
      const int e = std::min(int(x), kSpecularTableSize - 2);
      const float w = x - float(e);
      spec = p.specular * (p.specularTable[e] + w * (p.specularTable[e + 1] - p.specularTable[e])) * c.a;
    } else {
      spec = p.specular * powerBySteps<kPower>(std::min(nh, 1.0f), p.powerFloor) * c.a;
    }
  }
  return {c.r * lit + spec, c.g * lit + spec, c.b * lit + spec, c.a};
}

// a * b + c for the walk's look-ups (pastEmpty, CubeExit::exit) and the
// membership tests of a ray's start (inside, inDomain): rounded once, as
// their lanes compute it (walk_lanes.h, start_lanes.h), wherever the CPU
// has FMA. Written out, GCC's -ffp-contract=fast fuses it or not
// depending on the code around it, so the same look-up rounded
// differently in different callers (and a position a rounding away from a
// macrocell face landed in the neighbouring macrocell).
template <typename F>
[[gnu::always_inline]] inline F walkMulAdd(F a, F b, F c) {
#ifdef __FMA__
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

// Exact membership of sample k in the owned box (see KernelParams).
// k may be fractional (a short chord's midpoint, see shortChord).
inline bool inside(const KernelParams& p, const RaySetup& r, double k) {
  for (int a = 0; a < 3; ++a) {
    const double u = walkMulAdd(k, r.step[a], r.origin[a]);
    if (!(u >= p.ownLo[a])) return false;
    if (p.hiClosed[a] ? !(u <= p.ownHi[a]) : !(u < p.ownHi[a])) return false;
  }
  return true;
}

// Narrows [kmin, kmax], in steps along ray r, to where the ray lies in the
// box [lo, hi], slab by slab; false when it misses the box along an axis it
// does not move on. The one ray-box intersection of the owned box, the
// visible box and the domain (callers round and test exactly after it).
template <typename Bound>
inline bool clipToBox(const RaySetup& r, const Bound* lo, const Bound* hi, double& kmin, double& kmax) {
  for (int a = 0; a < 3; ++a) {
    const double l = double(lo[a]), h = double(hi[a]);
    if (r.step[a] == 0) {
      if (!(r.origin[a] >= l && r.origin[a] <= h)) return false;
      continue;
    }
    double k0 = (l - r.origin[a]) * r.invStep[a];
    double k1 = (h - r.origin[a]) * r.invStep[a];
    if (k0 > k1) std::swap(k0, k1);
    kmin = std::max(kmin, k0);
    kmax = std::min(kmax, k1);
  }
  return true;
}

// The samples [first, last] of this ray inside the owned box; false if none.
inline bool sampleRange(const KernelParams& p, const RaySetup& r, std::int64_t& first,
                        std::int64_t& last) {
  double kmin = 0, kmax = 1e18;
  if (!clipToBox(r, p.ownLo, p.ownHi, kmin, kmax) || kmin > kmax + 2) return false;
  // The estimate is within a sample (rounding); the exact test decides.
  first = std::max<std::int64_t>(0, std::int64_t(std::ceil(kmin)) - 1);
  last = std::int64_t(std::floor(kmax)) + 1;
  while (first <= last && !inside(p, r, first)) ++first;
  if (first > last) return false;
  while (!inside(p, r, last)) --last;
  while (inside(p, r, last + 1)) ++last;
  while (first > 0 && inside(p, r, first - 1)) --first;
  return true;
}

// The samples [first, last] narrowed to those in the visible box
// (KernelParams::visibleLo): the others lie in invisible macrocells, which
// the ray would only walk past. False if none is left.
inline bool clipToVisible(const KernelParams& p, const RaySetup& r, std::int64_t& first, std::int64_t& last) {
  for (int a = 0; a < 3; ++a)
    if (!(p.visibleLo[a] <= p.visibleHi[a])) return false;  // nothing visible
  double kmin = double(first), kmax = double(last);
  if (!clipToBox(r, p.visibleLo, p.visibleHi, kmin, kmax) || !(kmin <= kmax)) return false;
  first = std::max(first, std::int64_t(std::floor(kmin)));
  last = std::min(last, std::int64_t(std::ceil(kmax)));
  return first <= last;
}

// Where the ray's chord through the whole domain begins and ends, measured
// against its samples. Each sample stands for a segment one step long (the
// plain kernel: centred on the sample; pre-integration: from the sample to
// the next). At the two ends of the chord those segments are stretched or
// cut to the chord (pre-integration: the entry to the first sample is a
// segment of its own, and the last sample's segment is cut at the exit),
// so that together they cover it exactly and a homogeneous medium
// integrates to 1 - exp(-tau L) for any step. The ends depend on the ray
// and the grid alone: every brick finds the same ones.
struct ChordEnds {
  std::int64_t first = 0, last = -1;  // the first and last samples in the domain
  double head = 0;  // steps from the chord's entry to sample `first`, in [0, 1]
  double tail = 0;  // steps from sample `last` to the chord's exit, in [0, 1]
};

// Exact membership of sample k in the closed domain box [0, dims - 1].
inline bool inDomain(const KernelParams& p, const RaySetup& r, std::int64_t k) {
  for (int a = 0; a < 3; ++a) {
    const double u = walkMulAdd(double(k), r.step[a], r.origin[a]);
    if (!(u >= 0.0 && u <= double(p.domainMax[a]))) return false;
  }
  return true;
}

// The ray's chord through the domain in steps, [kIn, kOut] with kIn >= 0
// (samples start at t = 0); false if it misses.
inline bool domainChord(const KernelParams& p, const RaySetup& r, double& kIn, double& kOut) {
  static constexpr float kOrigin[3] = {0, 0, 0};
  kIn = 0;
  kOut = 1e18;
  return clipToBox(r, kOrigin, p.domainMax, kIn, kOut) && kIn <= kOut;
}

// The chord ends of a ray whose samples [first, last] lie in this brick
// (and so in the domain).
inline ChordEnds chordEnds(const KernelParams& p, const RaySetup& r, std::int64_t first,
                           std::int64_t last) {
  double kIn, kOut;
  if (!domainChord(p, r, kIn, kOut)) kIn = kOut = double(first);  // rounding; ends unstretched
  // The estimate is within a sample of the exact membership test, which
  // decides (as sampleRange does for the owned box).
  ChordEnds e;
  e.first = std::clamp<std::int64_t>(std::int64_t(std::ceil(kIn)), 0, first);
  while (e.first > 0 && inDomain(p, r, e.first - 1)) --e.first;
  while (e.first < first && !inDomain(p, r, e.first)) ++e.first;
  e.last = std::max<std::int64_t>(last, std::int64_t(std::floor(kOut)));
  while (inDomain(p, r, e.last + 1)) ++e.last;
  while (e.last > last && !inDomain(p, r, e.last)) --e.last;
  e.head = std::clamp(double(e.first) - kIn, 0.0, 1.0);
  e.tail = std::clamp(kOut - double(e.last), 0.0, 1.0);
  return e;
}

// A chord too short to hold any sample (a sliver at a silhouette, a thin
// volume at a large step) is one segment [kIn, kOut], rendered by the brick
// that owns its midpoint. True if the ray's chord is such a segment and
// this brick owns it.
inline bool shortChord(const KernelParams& p, const RaySetup& r, double& kIn, double& kOut) {
  if (!domainChord(p, r, kIn, kOut)) return false;
  const std::int64_t k = std::int64_t(std::ceil(kIn));
  for (std::int64_t c = std::max<std::int64_t>(0, k - 1); c <= k + 1; ++c)
    if (inDomain(p, r, c)) return false;
  return inside(p, r, 0.5 * (kIn + kOut));
}

// A classified sample of one step stretched to w steps of the same medium:
// opacity 1 - (1 - a)^w, colour scaled alike (exact when homogeneous).
inline Rgba stretch(const Rgba& c, double w) {
  if (!(c.a > 0) || !(w > 0)) return {};
  const double a = c.a >= 1.0f ? 1.0 : -std::expm1(w * std::log1p(-double(c.a)));
  const float k = float(a / double(c.a));
  return {c.r * k, c.g * k, c.b * k, float(a)};
}

// Index into p.distance of the macrocell with global index m.
inline std::size_t macrocellIndex(const KernelParams& p, const int* m) {
  return std::size_t(((m[2] - p.mcFirst[2]) * p.mcCount[1] + (m[1] - p.mcFirst[1])) * p.mcCount[0] +
                     (m[0] - p.mcFirst[0]));
}

// The ray's direction octant: bit a set when it goes down axis a (a ray
// that does not move along an axis counts as going up it).
template <typename Direction>
inline int directionOctant(const Direction& d) {
  return int(d[0] < 0) | int(d[1] < 0) << 1 | int(d[2] < 0) << 2;
}
inline int octantOf(const RaySetup& r) { return directionOctant(r.step); }

// Samples taken per look-up while a ray is in visible macrocells: about
// two macrocells, in whole batches of eight. A look-up is a chain of
// dependent arithmetic, loads and a branch that costs about as much as a
// batch of samples; at half-voxel steps 32 samples a look-up took 7 % less
// CPU than 16 on the peer scene, while at larger steps 32 samples run far
// into empty space (tests/renderer/raycast_accuracy_test.cpp, skipping).
// (mix_kernel.cpp's chunk, and the least of castRay's).
inline constexpr std::int64_t kVisibleChunk = 16;
inline std::int64_t visibleChunk(const RaySetup& r) { return r.leapPerMacrocell >= 8 ? 2 * kVisibleChunk : kVisibleChunk; }

// The first sample at or after the ray leaves the cube of macrocells
// within `distance - 1` of macrocell m (global index), never less than
// k + 1: where a macrocell's distance field value (MacrocellGrid::
// distance()) proves that cube empty, a ray in m crosses it without a
// look-up. Distance 1 is m itself. From anywhere in m the cube reaches at
// least distance - 1 macrocells further along every axis, so this leaps at
// least as far as distance - 1 macrocells along the major axis would, and
// the rest of m and the cube's reach along the minor axes besides, with no
// branch on the distance. Set up once per ray: each leap is then three
// multiply-adds and a minimum, with no branch on the ray's direction (a
// ray's walk takes one per empty look-up).
class CubeExit {
 public:
  CubeExit() = default;
  CubeExit(const RaySetup& r, int shift) {
    const double size = double(std::int64_t(1) << shift);
    for (int a = 0; a < 3; ++a) {
      // The face the ray leaves by, in steps: (m + d) size going up,
      // (m - d + 1) size going down, as (m + sign d) scale + base.
      sign_[a] = r.step[a] > 0 ? 1 : r.step[a] < 0 ? -1 : 0;
      scale_[a] = sign_[a] != 0 ? size * r.invStep[a] : 0.0;
      base_[a] = r.step[a] > 0 ? -r.origin[a] * r.invStep[a]
                 : r.step[a] < 0 ? (size - r.origin[a]) * r.invStep[a]
                                 : 1e300;
    }
  }
  std::int64_t exit(const int m[3], int distance, std::int64_t k) const {
    double exitK = 1e300;
    for (int a = 0; a < 3; ++a)
      exitK = std::min(exitK, walkMulAdd(double(m[a] + sign_[a] * distance), scale_[a], base_[a]));
    return std::max<std::int64_t>(k + 1, std::int64_t(std::ceil(std::min(exitK, 1e18))));
  }
  // The terms of exit() along axis a, for its lanes (walk_lanes.h).
  double scale(int a) const { return scale_[a]; }
  double base(int a) const { return base_[a]; }
  int sign(int a) const { return sign_[a]; }

 private:
  double scale_[3] = {0, 0, 0}, base_[3] = {1e300, 1e300, 1e300};
  int sign_[3] = {0, 0, 0};
};

inline std::int64_t emptyExit(const RaySetup& r, const int m[3], int distance, std::int64_t k, int shift) {
  return CubeExit(r, shift).exit(m, distance, k);
}

}  // namespace kernel

}  // namespace pvr::core
