// Gray-Scott reaction-diffusion in 3-D: the example computation
// (docs/steering.md). Two chemicals u and v on the grid's nodes,
//
//   du/dt = du_coeff * lap(u) - u v^2 + feed (1 - u)
//   dv/dt = dv_coeff * lap(v) + u v^2 - (feed + kill) v
//
// stepped by forward Euler with dt = 1 in grid units (a node's neighbours
// are one unit away whatever the scene's spacing, which only places the
// grid in the world). lap is the 7-point Laplacian; the grid's faces are
// no-flux (a missing neighbour mirrors the one inside: node -1 reads node
// 1). Forward Euler is stable while a diffusion coefficient stays at or
// below 1/6; their ranges end at 0.16.
#include <cmath>
#include <cstdint>

#include "computation.h"

namespace pvr::node {

namespace {

constexpr int kU = 0, kV = 1;

// A value in [0, 1) that depends on the global node alone (splitmix64 of
// its linear index): the seed's noise is the same on any decomposition.
double noiseAt(const core::GridGeometry& grid, core::IVec3 n) {
  std::uint64_t z = std::uint64_t((n.z * grid.dims.y + n.y) * grid.dims.x + n.x) + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

// u = 1, v = 0 everywhere but a cube at the centre, a fifth of each side
// wide (at least one node), where u = 0.5 and v = 0.25 plus a little noise
// that breaks the cube's symmetry.
void initial(const core::GridGeometry& grid, core::IVec3 n, std::span<double> values) {
  bool inSeed = true;
  for (int a = 0; a < 3; ++a) {
    const std::int64_t half = grid.dims[a] / 10;
    const std::int64_t centre = (grid.dims[a] - 1) / 2;
    inSeed = inSeed && std::llabs(n[a] - centre) <= half;
  }
  values[kU] = inSeed ? 0.5 : 1.0;
  values[kV] = inSeed ? 0.25 + 0.05 * noiseAt(grid, n) : 0.0;
}

// The offset from index i to the neighbour before (sign -1) or after (+1)
// node x on an axis of nodes 0..last with storage stride s: the mirror
// image across a face, nothing on an axis of one node.
std::int64_t before(std::int64_t x, std::int64_t s, std::int64_t last) { return x > 0 ? -s : (last > 0 ? s : 0); }
std::int64_t after(std::int64_t x, std::int64_t s, std::int64_t last) { return x < last ? s : (last > 0 ? -s : 0); }

void step(const StepArgs& a) {
  const double feed = a.parameters["feed"], kill = a.parameters["kill"];
  const double du = a.parameters["du"], dv = a.parameters["dv"];
  const double* u = a.now.field(kU);
  const double* v = a.now.field(kV);
  double* nu = a.next.field(kU);
  double* nv = a.next.field(kV);
  const core::IVec3 last{a.grid.dims.x - 1, a.grid.dims.y - 1, a.grid.dims.z - 1};
  const std::int64_t sy = a.now.strideY(), sz = a.now.strideZ();
  for (std::int64_t z = a.owned.lo.z; z <= a.owned.hi.z; ++z) {
    const std::int64_t zm = before(z, sz, last.z), zp = after(z, sz, last.z);
    for (std::int64_t y = a.owned.lo.y; y <= a.owned.hi.y; ++y) {
      const std::int64_t ym = before(y, sy, last.y), yp = after(y, sy, last.y);
      for (std::int64_t x = a.owned.lo.x; x <= a.owned.hi.x; ++x) {
        const std::int64_t xm = before(x, 1, last.x), xp = after(x, 1, last.x);
        const std::size_t i = a.now.index({x, y, z});
        const double lapU = u[i + xm] + u[i + xp] + u[i + ym] + u[i + yp] + u[i + zm] + u[i + zp] - 6 * u[i];
        const double lapV = v[i + xm] + v[i + xp] + v[i + ym] + v[i + yp] + v[i + zm] + v[i + zp] - 6 * v[i];
        const double uvv = u[i] * v[i] * v[i];
        const std::size_t j = a.next.index({x, y, z});
        nu[j] = u[i] + du * lapU - uvv + feed * (1 - u[i]);
        nv[j] = v[i] + dv * lapV + uvv - (feed + kill) * v[i];
      }
    }
  }
}

int shown(const Parameters& p) { return p["field"] >= 0.5 ? kU : kV; }

}  // namespace

ComputationEntry grayScott() {
  return ComputationEntry{
      "gray-scott",
      "3-D Gray-Scott reaction-diffusion of u and v (draws v, or u with field 1)",
      {
          {"feed", 0.035, 0, 0.1, "feed rate F: u flows in at F (1 - u)"},
          {"kill", 0.065, 0, 0.1, "kill rate k: v decays at (F + k) v"},
          {"du", 0.16, 0, 0.16, "diffusion of u, grid units per step (forward Euler is stable up to 1/6)"},
          {"dv", 0.08, 0, 0.16, "diffusion of v, grid units per step (forward Euler is stable up to 1/6)"},
          {"field", 0, 0, 1, "the field drawn: 0 is v, 1 is u"},
      },
      {"u", "v"},
      1,
      &initial,
      &step,
      &shown,
  };
}

}  // namespace pvr::node
