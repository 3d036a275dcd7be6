// Bricks rendered apart and composited front to back equal one rendering
// of the whole volume (ARCHITECTURE.md, "Sampling"; 000_6d6ea58ffa34a9ff.txt,
// Figure 2).
//
// The volume is split into 2 to 9 bricks of uneven sizes by a k-d tree of
// node planes (neighbours share the plane: A.hi == B.lo), each brick is
// cropped with the ghost layers the options need, rendered by its own
// BrickRenderer, and the images are composited in the tree's visibility
// order. The identity holds sample by sample: each sample lies in exactly
// one brick and reads the same voxels there, so what differs is float
// rounding (composition regrouped, positions and cell clamps rounded per
// brick), ~1e-7; the tolerance with early termination off is 1e-5.
//
// With early termination at a_max the two may differ by what each left out.
// Colours are non-negative, so both lie between V - miss and V, V the full
// integral. The whole stops once its opacity reaches a_max: it misses at
// most E (1 - a_max), E the largest colour per unit opacity (1 unshaded;
// ambient + diffuse + specular shaded). A brick stops likewise, inside
// itself; after the first brick that stops, at most 1 - a_max of
// transmittance is left, and each later one that stops leaves at most a
// 1 - a_max share of what reached it, so the composite misses at most
// E (1 - a_max) (1 + (1 - a_max) + ...) = E (1 - a_max) / a_max.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <set>
#include <vector>

#include "raycast/raycaster.h"
#include "raycast/step_levels.h"
#include "reference.h"

namespace pvr::core {
namespace {


// A k-d tree of node planes; leaves are bricks.
struct Split {
  struct Node {
    NodeBox box;
    int axis = -1;  // -1: a leaf
    std::int64_t plane = 0;
    int low = -1, high = -1;  // children: box.lo..plane and plane..box.hi
  };
  std::vector<Node> nodes;
};

// Splits `all` into `leaves` bricks: the largest brick is cut across its
// longest axis (in cells) at a fraction that changes from cut to cut, so
// the bricks come out of uneven sizes and planes fall anywhere.
Split splitUnevenly(const NodeBox& all, int leaves) {
  static constexpr double kFractions[] = {0.37, 0.62, 0.29, 0.55, 0.71, 0.43, 0.33, 0.58};
  Split s;
  s.nodes.push_back({all});
  std::vector<int> open{0};
  for (int cut = 0; int(open.size()) < leaves; ++cut) {
    auto largest = std::max_element(open.begin(), open.end(), [&](int a, int b) {
      return s.nodes[a].box.nodeCount() < s.nodes[b].box.nodeCount();
    });
    const int node = *largest;
    const NodeBox box = s.nodes[node].box;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (box.extent(a) > box.extent(axis)) axis = a;
    const std::int64_t cells = box.extent(axis) - 1;
    REQUIRE(cells >= 2);
    const double f = kFractions[cut % 8];
    const std::int64_t plane =
        box.lo[axis] + std::clamp<std::int64_t>(std::llround(double(cells) * f), 1, cells - 1);
    NodeBox low = box, high = box;
    low.hi[axis] = plane;
    high.lo[axis] = plane;
    s.nodes[node].axis = axis;
    s.nodes[node].plane = plane;
    s.nodes[node].low = int(s.nodes.size());
    s.nodes.push_back({low});
    s.nodes[node].high = int(s.nodes.size());
    s.nodes.push_back({high});
    *largest = s.nodes[node].low;
    open.push_back(s.nodes[node].high);
  }
  return s;
}

// Leaves front to back: at each split the child on the viewer's side first
// (orthographic: the side the view direction comes from; perspective: the
// eye's side of the plane). Convex boxes of a k-d split need nothing more.
void frontToBack(const Split& s, int node, const Camera& camera, const GridGeometry& grid,
                 std::vector<int>& order) {
  const Split::Node& n = s.nodes[node];
  if (n.axis < 0) {
    order.push_back(node);
    return;
  }
  const double plane = grid.origin[n.axis] + double(n.plane) * grid.spacing[n.axis];
  const bool lowFirst = camera.projection() == Projection::kOrthographic
                            ? camera.forward()[n.axis] >= 0
                            : camera.spec().eye[n.axis] < plane;
  frontToBack(s, lowFirst ? n.low : n.high, camera, grid, order);
  frontToBack(s, lowFirst ? n.high : n.low, camera, grid, order);
}

Image renderWhole(const Brick& volume, const TransferFunctionSpec& tf, const Camera& camera,
                  const RenderOptions& o) {
  BrickRenderer r(volume);
  r.classify(tf, o);
  return r.render(camera, o, pool()).toFullFrame();
}

Image renderSplit(const Brick& volume, int leaves, const TransferFunctionSpec& tf,
                  const Camera& camera, const RenderOptions& o) {
  const Split split = splitUnevenly(volume.grid().allNodes(), leaves);
  std::vector<int> order;
  frontToBack(split, 0, camera, volume.grid(), order);
  REQUIRE(int(order.size()) == leaves);
  const int ghost = ghostLayers(volume.grid(), o);
  Image out = Image::fullFrame(camera.width(), camera.height());
  for (int leaf : order) {
    const Brick brick = cropBrick(volume, split.nodes[leaf].box, ghost);
    BrickRenderer r(brick);
    r.classify(tf, o);
    compositeUnder(out, r.render(camera, o, pool()));
  }
  return out;
}

// The Marschner-Lobb signal over the grid's domain mapped onto [-1, 1]^3,
// scaled into [lo, hi] (a type's range).
Brick signalVolume(const GridGeometry& grid, ScalarType type, double lo, double hi) {
  const Vec3 dmin = grid.domainMin(), dmax = grid.domainMax();
  return makeVolume(grid, type, [&](Vec3 p) {
    Vec3 q;
    for (int a = 0; a < 3; ++a) q[a] = 2 * (p[a] - dmin[a]) / (dmax[a] - dmin[a]) - 1;
    return lo + (hi - lo) * marschnerLobb(q);
  });
}

// Colour and opacity over the signal's range [lo, hi]: empty below 30%,
// then rising, with a sharper band around 60%.
TransferFunctionSpec signalTransfer(double lo, double hi, double unitDistance) {
  auto s = [&](double f) { return lo + (hi - lo) * f; };
  TransferFunctionSpec tf;
  tf.points = {{s(0.0), 0, 0, 0, 0},         {s(0.3), 0.1, 0.2, 0.8, 0},
               {s(0.55), 0.3, 0.7, 0.9, 0.08}, {s(0.6), 1.0, 0.8, 0.2, 0.5},
               {s(0.65), 0.9, 0.5, 0.3, 0.1},  {s(1.0), 1.0, 1.0, 1.0, 0.3}};
  tf.unitDistance = unitDistance;
  return tf;
}

// Orthographic, the whole domain in view from `direction`.
Camera orthographic(const GridGeometry& grid, Vec3 direction, Vec3 up, int size) {
  const Vec3 c = grid.center();
  const double extent = length(grid.domainMax() - grid.domainMin());
  return makeCamera(Projection::kOrthographic, c - normalize(direction) * extent, c, up, extent,
                    size, size);
}

Camera perspective(Vec3 eye, Vec3 at, Vec3 up, double fov, int size) {
  return makeCamera(Projection::kPerspective, eye, at, up, fov, size, size);
}

// Renders the volume whole and split into each of `leafCounts` bricks,
// with early termination off and at 0.95, and checks the identities of the
// header. (Every test could take 2..9 bricks; they share the counts out to
// keep the suite fast, and the oblique view takes them all.)
void checkSplitsMatch(const Brick& volume, const TransferFunctionSpec& tf, const Camera& camera,
                      RenderOptions o, std::initializer_list<int> leafCounts) {
  const double emission = o.shading.enabled
                              ? o.shading.ambient + o.shading.diffuse + o.shading.specular
                              : 1.0;
  for (double aMax : {1.0, 0.95}) {
    o.earlyTermination = aMax;
    const Image whole = renderWhole(volume, tf, camera, o);
    // The scene must show something for the check to mean anything.
    double coverage = 0;
    for (const Rgba& p : whole.pixels()) coverage += p.a;
    REQUIRE(coverage > 0.05 * camera.width() * camera.height());
    const double tolerance = aMax < 1 ? emission * (1 - aMax) / aMax : 1e-5;
    for (int leaves : leafCounts) {
      const double diff = compareImages(renderSplit(volume, leaves, tf, camera, o), whole).maxAbs;
      INFO("a_max " << aMax << ", " << leaves << " bricks: max difference " << diff);
      CHECK(diff <= tolerance);
    }
  }
}

}  // namespace

// Views along the axes, with pixel centres on integer node coordinates
// (64 pixels over 64 units: pixel centres at eye + x - 31.5, the eye at
// 20.5): rays run exactly along brick faces, whose samples belong to the
// brick on their high side.
TEST_CASE("bricks equal the whole: orthographic along the axes", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = signalVolume(grid, ScalarType::kFloat32, 0, 1);
  const TransferFunctionSpec tf = signalTransfer(0, 1, 1.0);
  const Vec3 axes[] = {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}};
  for (const Vec3& d : axes) {
    const Vec3 at{20.5, 20.5, 20.5};
    const Camera camera = makeCamera(Projection::kOrthographic, at - d * 50.0, at,
                                     d.z != 0 ? Vec3{0, 1, 0} : Vec3{0, 0, 1}, 64, 64, 64);
    INFO("direction " << d.x << " " << d.y << " " << d.z);
    checkSplitsMatch(volume, tf, camera, makeOptions(0.5), {3, 6, 9});
  }
}

TEST_CASE("bricks equal the whole: oblique orthographic", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = signalVolume(grid, ScalarType::kFloat32, 0, 1);
  const TransferFunctionSpec tf = signalTransfer(0, 1, 1.0);
  checkSplitsMatch(volume, tf, orthographic(grid, {0.7, -0.5, 0.45}, {0, 0, 1}, 96),
                   makeOptions(0.7), {2, 3, 4, 5, 6, 7, 8, 9});
}

TEST_CASE("bricks equal the whole: perspective from outside and from inside", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = signalVolume(grid, ScalarType::kFloat32, 0, 1);
  const TransferFunctionSpec tf = signalTransfer(0, 1, 1.0);
  SECTION("outside") {
    checkSplitsMatch(volume, tf, perspective({-30, -45, 60}, {19.5, 20, 19}, {0, 0, 1}, 40, 96),
                     makeOptions(0.5), {2, 5, 8});
  }
  SECTION("inside") {
    checkSplitsMatch(volume, tf, perspective({17.3, 21.6, 19.2}, {40, 10, 30}, {0, 0, 1}, 100, 96),
                     makeOptions(0.5), {3, 7, 9});
  }
}

// Shading reads one voxel beyond a sample: one ghost layer.
TEST_CASE("bricks equal the whole: shaded", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = signalVolume(grid, ScalarType::kFloat32, 0, 1);
  const TransferFunctionSpec tf = signalTransfer(0, 1, 1.0);
  RenderOptions o = makeOptions(0.5, false, true);
  checkSplitsMatch(volume, tf, orthographic(grid, {-0.4, 0.8, -0.5}, {0, 0, 1}, 96), o, {4, 7});
  o.shading.lightDirection = {0.5, 0.5, 0.7};
  checkSplitsMatch(volume, tf, perspective({60, -30, 50}, {20, 20, 20}, {0, 0, 1}, 45, 96), o, {5, 9});
}

// A pre-integrated segment reaches one step beyond its sample: ghost
// layers of ceil(step / spacing).
TEST_CASE("bricks equal the whole: pre-integrated up to two voxels a step", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = signalVolume(grid, ScalarType::kFloat32, 0, 1);
  const TransferFunctionSpec tf = signalTransfer(0, 1, 1.0);
  for (double step : {0.5, 1.3, 2.0}) {
    INFO("step " << step);
    checkSplitsMatch(volume, tf, orthographic(grid, {0.6, 0.5, -0.6}, {0, 0, 1}, 96),
                     makeOptions(step, true), {3, 8});
  }
  checkSplitsMatch(volume, tf, perspective({-20, 50, 55}, {20, 20, 20}, {0, 0, 1}, 45, 96),
                   makeOptions(2.0, true, true), {6});
}

TEST_CASE("bricks equal the whole: every scalar type", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  struct TypeCase {
    ScalarType type;
    double lo, hi;
  };
  const TypeCase types[] = {{ScalarType::kUInt8, 0, 255},
                            {ScalarType::kUInt16, 0, 65535},
                            {ScalarType::kInt16, -32768, 32767},
                            {ScalarType::kFloat32, -3, 5}};
  const Camera camera = orthographic(grid, {0.5, 0.8, -0.3}, {0, 0, 1}, 96);
  for (const TypeCase& t : types) {
    INFO(scalarName(t.type));
    const Brick volume = signalVolume(grid, t.type, t.lo, t.hi);
    const TransferFunctionSpec tf = signalTransfer(t.lo, t.hi, 1.0);
    checkSplitsMatch(volume, tf, camera, makeOptions(0.6), {2, 5, 9});
  }
}

// Spacing 1 x 1 x 7: index steps differ per axis, and the ghost layers of
// pre-integration count in the smallest spacing.
TEST_CASE("bricks equal the whole: anisotropic spacing", "[bricks]") {
  GridGeometry grid;
  grid.dims = {40, 36, 9};
  grid.spacing = {1, 1, 7};
  grid.origin = {-3, 2, 1};
  const Brick volume = signalVolume(grid, ScalarType::kUInt16, 0, 65535);
  const TransferFunctionSpec tf = signalTransfer(0, 65535, 1.0);
  const Camera camera = orthographic(grid, {0.4, 0.6, -0.7}, {0, 0, 1}, 96);
  checkSplitsMatch(volume, tf, camera, makeOptions(0.8), {3, 7});
  checkSplitsMatch(volume, tf, camera, makeOptions(1.5, true, true), {4, 9});
}

// Rays walk only the box of a brick's visible macrocells (kernel::
// clipToVisible): a blob off in one corner leaves some bricks with no
// visible macrocell (every ray misses their box) and others with a box
// that ends at the brick's faces, where the blob runs on into the next.
TEST_CASE("bricks equal the whole: visible box in some bricks only", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = makeVolume(grid, ScalarType::kUInt8, [](Vec3 p) {
    const Vec3 d = p - Vec3{27, 26, 12};
    return 255 * std::exp(-dot(d, d) / (2 * 8.0 * 8.0));
  });
  TransferFunctionSpec tf;
  tf.points = {{0, 0, 0, 0, 0}, {50, 0.1, 0.3, 0.9, 0}, {150, 0.8, 0.7, 0.3, 0.3}, {255, 1, 0.9, 0.8, 0.6}};
  tf.unitDistance = 1.0;
  checkSplitsMatch(volume, tf, orthographic(grid, {0.5, 0.7, 0.5}, {0, 0, 1}, 96), makeOptions(0.5), {4, 9});
  checkSplitsMatch(volume, tf, perspective({-25, 60, 45}, {20, 20, 20}, {0, 0, 1}, 50, 96), makeOptions(1.3, true),
                   {3, 7});
}

// Quality chosen by error (step_levels.h): every brick reads a block's
// level at the same points of the global level field and owns the coarse
// samples whose positions it owns, so bricks still equal the whole while
// the step changes from region to region.
TEST_CASE("bricks equal the whole: step chosen per region by a target PSNR", "[bricks]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = signalVolume(grid, ScalarType::kFloat32, 0, 1);
  const TransferFunctionSpec tf = signalTransfer(0, 1, 1.0);
  // The scene must take several steps for the check to mean anything.
  StepLevels levels(volume, 0.5);
  levels.choose(tf, 45, 0);
  const std::set<int> taken(levels.levels(), levels.levels() + levels.count().product());
  REQUIRE(taken.size() >= 3);
  for (bool shaded : {false, true}) {
    RenderOptions o = makeOptions(0.5, false, shaded);
    o.targetPsnr = 45;
    INFO((shaded ? "shaded" : "unshaded"));
    checkSplitsMatch(volume, tf, orthographic(grid, normalize(Vec3{0.3, -0.5, 0.8}), {0, 0, 1}, 48), o, {2, 5});
    checkSplitsMatch(volume, tf, perspective({-30, -45, 50}, {20, 18, 21}, {0, 0, 1}, 40, 48), o, {3, 8});
  }
}

}  // namespace pvr::core
