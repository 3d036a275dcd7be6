// The MPI driver's "steering" mode (mpi_driver.cpp): the Gray-Scott example
// computation (node/computations/) run over the job's ranks against a
// serial run of the same steps written here from the equations alone.
//
// Identities checked, on every rank's owned nodes, both fields:
//   distributed(N steps) == serial(N steps)              within 1e-6
//   a parameter set after step S: step S unchanged, step S+1 differs from the
//     unsteered run and equals the serial run steered the same way
//   fields moved to other bricks (another tree, more ghost layers) go on
//     as if nothing happened
//   the brick the renderer draws holds v (or u with field 1) as float32
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "communicator.h"
#include "computation_run.h"
#include "decompose/kd_tree.h"

namespace {

using namespace pvr;
using core::IVec3;
using core::NodeBox;

constexpr IVec3 kDims{23, 19, 17};
constexpr double kTolerance = 1e-6;

// The serial run: both fields on the whole grid, forward Euler with the
// 7-point Laplacian and mirrored faces, as docs/steering.md states them.
struct Serial {
  core::GridGeometry grid;
  std::vector<double> u, v;

  explicit Serial(const node::ComputationEntry& entry) {
    grid.dims = kDims;
    const std::size_t n = std::size_t(kDims.product());
    u.resize(n);
    v.resize(n);
    std::vector<double> values(2);
    for (std::int64_t z = 0; z < kDims.z; ++z)
      for (std::int64_t y = 0; y < kDims.y; ++y)
        for (std::int64_t x = 0; x < kDims.x; ++x) {
          entry.initial(grid, {x, y, z}, values);
          u[at({x, y, z})] = values[0];
          v[at({x, y, z})] = values[1];
        }
  }
  static std::size_t at(IVec3 n) { return std::size_t((n.z * kDims.y + n.y) * kDims.x + n.x); }
  // Node n's value of `f` with the faces mirrored (node -1 is node 1).
  static double mirrored(const std::vector<double>& f, IVec3 n) {
    for (int a = 0; a < 3; ++a) {
      if (n[a] < 0) n[a] = -n[a];
      if (n[a] > kDims[a] - 1) n[a] = 2 * (kDims[a] - 1) - n[a];
    }
    return f[at(n)];
  }
  static double laplacian(const std::vector<double>& f, IVec3 n) {
    double sum = -6 * f[at(n)];
    for (int a = 0; a < 3; ++a)
      for (int d : {-1, 1}) {
        IVec3 m = n;
        m[a] += d;
        sum += mirrored(f, m);
      }
    return sum;
  }
  void step(double feed, double kill, double du, double dv) {
    std::vector<double> nu(u.size()), nv(v.size());
    for (std::int64_t z = 0; z < kDims.z; ++z)
      for (std::int64_t y = 0; y < kDims.y; ++y)
        for (std::int64_t x = 0; x < kDims.x; ++x) {
          const std::size_t i = at({x, y, z});
          const double uvv = u[i] * v[i] * v[i];
          nu[i] = u[i] + du * laplacian(u, {x, y, z}) - uvv + feed * (1 - u[i]);
          nv[i] = v[i] + dv * laplacian(v, {x, y, z}) + uvv - (feed + kill) * v[i];
        }
    u.swap(nu);
    v.swap(nv);
  }
};

// The largest difference between the run's owned nodes and the serial run, over every rank.
double maxDifference(comm::Communicator& comm, const node::ComputationRun& run, const Serial& serial) {
  const NodeBox& owned = run.owned();
  const node::FieldBlock& f = run.fields();
  double worst = 0;
  for (std::int64_t z = owned.lo.z; z <= owned.hi.z; ++z)
    for (std::int64_t y = owned.lo.y; y <= owned.hi.y; ++y)
      for (std::int64_t x = owned.lo.x; x <= owned.hi.x; ++x) {
        const std::size_t i = f.index({x, y, z}), j = Serial::at({x, y, z});
        worst = std::max({worst, std::abs(f.field(0)[i] - serial.u[j]), std::abs(f.field(1)[i] - serial.v[j])});
      }
  std::vector<double> all{worst};
  comm.allReduceMax(all);
  return all[0];
}

std::vector<NodeBox> ownedBoxes(const core::GridGeometry& grid, int ranks, core::SplitAxisRule rule) {
  const core::KdTree tree = core::KdTree::build(grid, ranks, rule);
  std::vector<NodeBox> boxes;
  for (int r = 0; r < ranks; ++r) boxes.push_back(tree.ownedBox(r));
  return boxes;
}

}  // namespace

int steering(comm::Communicator& comm) {
  int failed = 0;
  const auto check = [&](bool ok, const std::string& what) {
    if (ok) return;
    ++failed;
    if (comm.rank() == 0) std::printf("FAILED: %s\n", what.c_str());
  };
  const node::ComputationEntry& entry = node::computationNamed("gray-scott");
  core::GridGeometry grid;
  grid.dims = kDims;
  std::vector<int> members;
  for (int r = 0; r < comm.size(); ++r) members.push_back(r);
  const double feed = 0.035, kill = 0.065, du = 0.16, dv = 0.08, steeredFeed = 0.055;

  // Distributed and serial, 40 steps with the defaults; then feed is set.
  node::ComputationRun run(entry, grid);
  run.place(comm, members, ownedBoxes(grid, comm.size(), core::SplitAxisRule::kAlternating), 1);
  Serial serial(entry);
  const node::Parameters defaults(entry, {});
  for (int s = 0; s < 40; ++s) {
    run.step(comm, defaults);
    serial.step(feed, kill, du, dv);
  }
  const double after40 = maxDifference(comm, run, serial);
  check(after40 <= kTolerance, "40 steps differ from the serial run by " + std::to_string(after40));
  check(run.steps() == 40, "the run counts " + std::to_string(run.steps()) + " steps, not 40");

  // The fields move to another decomposition with two ghost layers, and go on.
  run.place(comm, members, ownedBoxes(grid, comm.size(), core::SplitAxisRule::kLongest), 2);
  check(run.steps() == 40, "moving the fields lost the step count");
  const double moved = maxDifference(comm, run, serial);
  check(moved <= kTolerance, "the moved fields differ from the serial run by " + std::to_string(moved));

  // Steering: feed changes after step 40. Step 41 differs from the
  // unsteered serial run and equals the steered one.
  Serial unsteered = serial;
  const node::Parameters steered(entry, {{"feed", steeredFeed}});
  run.step(comm, steered);
  serial.step(steeredFeed, kill, du, dv);
  unsteered.step(feed, kill, du, dv);
  const double steeredDiff = maxDifference(comm, run, serial);
  const double fromUnsteered = maxDifference(comm, run, unsteered);
  check(steeredDiff <= kTolerance, "the steered step differs from the steered serial run by " + std::to_string(steeredDiff));
  check(fromUnsteered > 1e-4, "setting feed did not change step 41 (difference " + std::to_string(fromUnsteered) + ")");
  for (int s = 0; s < 9; ++s) {
    run.step(comm, steered);
    serial.step(steeredFeed, kill, du, dv);
  }
  const double after50 = maxDifference(comm, run, serial);
  check(after50 <= kTolerance, "50 steps (10 steered) differ from the serial run by " + std::to_string(after50));

  // The brick drawn: v as float32 on the stored box, u with field = 1.
  const core::KdTree tree = core::KdTree::build(grid, comm.size(), core::SplitAxisRule::kLongest);
  const NodeBox stored = core::storedBox(tree, comm.rank(), 2);
  for (int field : {0, 1}) {
    const core::Brick brick = run.brick(comm, node::Parameters(entry, {{"field", double(field)}, {"feed", steeredFeed}}), stored);
    const std::vector<double>& expected = field == 1 ? serial.u : serial.v;
    double worst = 0;
    for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
      for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
        for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x)
          worst = std::max(worst, std::abs(brick.valueAt({x, y, z}) - double(float(expected[Serial::at({x, y, z})]))));
    std::vector<double> all{worst};
    comm.allReduceMax(all);
    check(all[0] <= kTolerance, std::string("the brick of ") + (field ? "u" : "v") + " differs by " + std::to_string(all[0]));
  }
  if (comm.rank() == 0)
    std::printf("steering: %d ranks, 40 steps max |distributed - serial| = %.3g, moved %.3g, steered %.3g "
                "(unsteered differs by %.3g), 50 steps %.3g\n",
                comm.size(), after40, moved, steeredDiff, fromUnsteered, after50);
  return failed == 0 ? 0 : 1;
}
