// The k-d decomposition (000_6d6ea58ffa34a9ff.txt, "Data subdivision" and
// Figure 1): leaves partition the grid's cells, planes follow the rank
// counts (or the content), the traversal order is a correct front-to-back
// order for any camera, and bricks cut by the tree render, composited in
// that order, to the image of the whole.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "decompose/content.h"
#include "decompose/kd_tree.h"
#include "error.h"
#include "raycast/raycaster.h"

namespace pvr::core {
namespace {

constexpr SplitAxisRule kRules[] = {SplitAxisRule::kAlternating, SplitAxisRule::kLongest, SplitAxisRule::kSlowest};

GridGeometry makeGrid(IVec3 dims, Vec3 spacing = {1, 1, 1}, Vec3 origin = {0, 0, 0}) {
  GridGeometry g;
  g.dims = dims;
  g.spacing = spacing;
  g.origin = origin;
  return g;
}

// A camera looking from `eye` at `at`; up is z unless the view is nearly along z.
Camera viewFrom(Projection projection, Vec3 eye, Vec3 at, double orthoHeight, int size = 8) {
  CameraSpec s;
  s.projection = projection;
  s.eye = eye;
  s.lookAt = at;
  s.up = std::abs(normalize(at - eye).z) > 0.9 ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
  s.height = orthoHeight;
  s.fovYDeg = 50;
  s.automatic = false;
  return Camera(s, size, size);
}

// A whole-volume float32 brick with node values f(world position).
template <typename F>
Brick floatVolume(const GridGeometry& grid, F f) {
  Brick volume(grid, ScalarType::kFloat32, grid.allNodes(), grid.allNodes());
  float* v = volume.as<float>();
  for (std::int64_t z = 0; z < grid.dims.z; ++z)
    for (std::int64_t y = 0; y < grid.dims.y; ++y)
      for (std::int64_t x = 0; x < grid.dims.x; ++x)
        v[volume.linearIndex({x, y, z})] = float(f(grid.nodePosition({x, y, z})));
  volume.updateValueRange();
  return volume;
}

Vec3 randomDirection(std::mt19937& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3 d{n(rng), n(rng), n(rng)};
    if (length(d) > 1e-3) return normalize(d);
  }
}

// Cells of a leaf on an axis; an axis on which the grid has no cells counts
// its single node plane as one cell, so products count leaves' shares.
std::int64_t cellSpan(const GridGeometry& grid, const NodeBox& box, int a) {
  return grid.dims[a] > 1 ? box.hi[a] - box.lo[a] : 1;
}

// Every cell of the grid lies in exactly one leaf, every leaf has a cell on
// each axis with cells, and the tree is consistent: ranks contiguous in tree
// order, children meet on the plane node, leaves numbered by rank.
void checkPartition(const KdTree& tree) {
  const GridGeometry& grid = tree.grid();
  IVec3 cells;
  for (int a = 0; a < 3; ++a) cells[a] = std::max<std::int64_t>(grid.dims[a] - 1, 1);
  std::vector<int> owners(std::size_t(cells.product()), 0);
  REQUIRE(int(tree.nodes().size()) == 2 * tree.rankCount() - 1);
  for (int rank = 0; rank < tree.rankCount(); ++rank) {
    const KdNode& leaf = tree.nodes()[std::size_t(tree.leafOfRank(rank))];
    REQUIRE(leaf.leaf());
    REQUIRE(leaf.rankBegin == rank);
    REQUIRE(leaf.rankEnd == rank + 1);
    const NodeBox& box = tree.ownedBox(rank);
    REQUIRE(grid.allNodes().contains(box));
    for (int a = 0; a < 3; ++a) REQUIRE(cellSpan(grid, box, a) >= 1);
    for (std::int64_t z = box.lo.z; z < box.lo.z + cellSpan(grid, box, 2); ++z)
      for (std::int64_t y = box.lo.y; y < box.lo.y + cellSpan(grid, box, 1); ++y)
        for (std::int64_t x = box.lo.x; x < box.lo.x + cellSpan(grid, box, 0); ++x)
          ++owners[std::size_t((z * cells.y + y) * cells.x + x)];
  }
  CHECK(std::all_of(owners.begin(), owners.end(), [](int n) { return n == 1; }));

  for (const KdNode& n : tree.nodes()) {
    if (n.leaf()) continue;
    const KdNode& l = tree.nodes()[std::size_t(n.left)];
    const KdNode& r = tree.nodes()[std::size_t(n.right)];
    const int ranks = n.rankEnd - n.rankBegin;
    CHECK(l.rankBegin == n.rankBegin);
    CHECK(l.rankEnd == r.rankBegin);
    CHECK(r.rankEnd == n.rankEnd);
    CHECK(l.rankEnd - l.rankBegin == ranks / 2);
    CHECK(l.box.hi[n.axis] == n.plane);
    CHECK(r.box.lo[n.axis] == n.plane);
    NodeBox joined = l.box;
    joined.hi[n.axis] = r.box.hi[n.axis];
    CHECK(joined == n.box);
  }
  CHECK(tree.nodes()[0].box == grid.allNodes());
}

// The non-empty voxels each rank owns, counted on its own brick.
std::vector<std::uint64_t> contentPerRank(const KdTree& tree, const Brick& whole,
                                          const TransferTable& table) {
  std::vector<std::uint64_t> perRank;
  for (int rank = 0; rank < tree.rankCount(); ++rank)
    perRank.push_back(totalContent(countContent(cropBrick(whole, tree.ownedBox(rank), 0), table)));
  return perRank;
}

// A ball of value 1 in the low corner of a 40^3 grid, 0 elsewhere, and a
// transfer function that shows only values above 0.5.
struct CornerScene {
  GridGeometry grid = makeGrid({40, 40, 40});
  Brick volume = floatVolume(grid, [](Vec3 p) {
    return length(p - Vec3{9, 10, 8}) < 15 ? 1.0 : 0.0;
  });
  TransferTable table;
  CornerScene() {
    TransferFunctionSpec tf;
    tf.points = {{0, 0, 0, 0, 0}, {0.5, 1, 1, 1, 0}, {1, 1, 1, 1, 0.5}};
    tf.unitDistance = 1;
    table = TransferTable(tf, 0.5);
  }
};

}  // namespace

TEST_CASE("k-d leaves partition the grid's cells for 1 to 17 ranks", "[kd]") {
  const GridGeometry grids[] = {
      makeGrid({40, 40, 40}), makeGrid({33, 20, 9}, {1, 2, 0.5}, {-3, 1, 2}),
      makeGrid({30, 25, 1}),  // one node thick: no cells on z
  };
  for (const GridGeometry& grid : grids)
    for (SplitAxisRule rule : kRules)
      for (int ranks = 1; ranks <= 17; ++ranks) {
        INFO(toString(grid.allNodes()) << " rule " << int(rule) << " ranks " << ranks);
        checkPartition(KdTree::build(grid, ranks, rule));
      }
}

TEST_CASE("k-d trees exist up to 64 ranks, on tight grids too", "[kd]") {
  const GridGeometry grids[] = {makeGrid({40, 40, 40}), makeGrid({17, 9, 5}), makeGrid({5, 5, 5}),
                                makeGrid({200, 3, 2})};
  for (const GridGeometry& grid : grids)
    for (SplitAxisRule rule : kRules)
      for (int ranks = 1; ranks <= 64; ++ranks) {
        INFO(toString(grid.allNodes()) << " rule " << int(rule) << " ranks " << ranks);
        checkPartition(KdTree::build(grid, ranks, rule));
      }
  // 65 ranks do not fit 4^3 cells.
  CHECK_THROWS_AS(KdTree::build(makeGrid({5, 5, 5}), 65, SplitAxisRule::kLongest), Error);
}

// Identity: a node with n ranks gives floor(n/2) to the left, and its plane
// cuts c cells at round(c * floor(n/2) / n), so each side's cells (the other
// axes are shared) are proportional to its ranks within half a slab.
TEST_CASE("k-d planes split cells in proportion to the ranks", "[kd]") {
  const GridGeometry grid = makeGrid({61, 40, 37});
  for (SplitAxisRule rule : kRules)
    for (int ranks : {2, 3, 5, 6, 7, 11, 13, 17}) {
      const KdTree tree = KdTree::build(grid, ranks, rule);
      for (const KdNode& n : tree.nodes()) {
        if (n.leaf()) continue;
        const int all = n.rankEnd - n.rankBegin, left = all / 2;
        const double cells = double(n.box.hi[n.axis] - n.box.lo[n.axis]);
        const double cut = double(n.plane - n.box.lo[n.axis]);
        INFO("ranks " << ranks << " node " << toString(n.box) << " axis " << n.axis);
        CHECK(std::abs(cut - cells * left / all) <= 0.5);
      }
    }
  // 3 ranks over 60 cells in x: 20 | 40.
  const KdTree three = KdTree::build(makeGrid({61, 10, 10}), 3, SplitAxisRule::kLongest);
  CHECK(three.ownedBox(0).hi.x == 20);
  CHECK(three.ownedBox(1).lo.x == 20);
}

TEST_CASE("k-d axis rules: alternating, longest in world units, unsplittable axes skipped",
          "[kd]") {
  SECTION("alternating takes x, y, z in turn") {
    const KdTree tree = KdTree::build(makeGrid({40, 40, 40}), 8, SplitAxisRule::kAlternating);
    for (const KdNode& n : tree.nodes()) {
      if (n.leaf()) continue;
      int depth = 0;
      for (int r = n.rankEnd - n.rankBegin; r < 8; r *= 2) ++depth;
      CHECK(n.axis == depth);
    }
  }
  SECTION("longest follows spacing, not node counts") {
    // 32 cells on every axis, but y spans 96 world units.
    const KdTree tree =
        KdTree::build(makeGrid({33, 33, 33}, {1, 3, 1}), 4, SplitAxisRule::kLongest);
    const KdNode& root = tree.nodes()[0];
    CHECK(root.axis == 1);
    // Halves span 32 x 48 x 32 world units: y again.
    CHECK(tree.nodes()[std::size_t(root.left)].axis == 1);
    CHECK(tree.nodes()[std::size_t(root.right)].axis == 1);
  }
  SECTION("slowest cuts whole slabs along z while z has cells for the ranks, then y") {
    const KdTree slabs = KdTree::build(makeGrid({40, 30, 20}), 8, SplitAxisRule::kSlowest);
    for (int r = 0; r < 8; ++r) {
      const NodeBox& b = slabs.ownedBox(r);
      CHECK(b.lo.x == 0);
      CHECK(b.hi.x == 39);
      CHECK(b.lo.y == 0);
      CHECK(b.hi.y == 29);
    }
    // 3 z cells for 8 ranks: z first, then y inside the slabs.
    const KdTree thin = KdTree::build(makeGrid({40, 30, 4}), 8, SplitAxisRule::kSlowest);
    CHECK(thin.nodes()[0].axis == 2);
    for (const KdNode& n : thin.nodes()) CHECK(n.axis != 0);
  }
  SECTION("an axis without cells, or with one, is never split") {
    for (SplitAxisRule rule : kRules) {
      const KdTree flat = KdTree::build(makeGrid({30, 25, 1}), 8, rule);
      const KdTree thin = KdTree::build(makeGrid({2, 50, 50}), 8, rule);
      for (const KdNode& n : flat.nodes()) CHECK(n.axis != 2);
      for (const KdNode& n : thin.nodes()) CHECK(n.axis != 0);
    }
  }
}

TEST_CASE("k-d build throws pvr::Error when no tree exists", "[kd]") {
  for (SplitAxisRule rule : kRules) {
    CHECK_THROWS_AS(KdTree::build(makeGrid({40, 40, 40}), 0, rule), Error);
    CHECK_THROWS_AS(KdTree::build(makeGrid({1, 1, 1}), 2, rule), Error);
    // 2 x 2 x 2 cells hold 8 ranks, not 9.
    CHECK_NOTHROW(KdTree::build(makeGrid({3, 3, 3}), 8, rule));
    CHECK_THROWS_AS(KdTree::build(makeGrid({3, 3, 3}), 9, rule), Error);
    // 3 x 3 cells would hold 9 (or 8) leaves, but halving 9 into 4 + 5 (or
    // 8 into 4 + 4) needs two columns on each side of the first plane.
    CHECK_THROWS_AS(KdTree::build(makeGrid({4, 4, 1}), 9, rule), Error);
    CHECK_THROWS_AS(KdTree::build(makeGrid({4, 4, 1}), 8, rule), Error);
    CHECK_NOTHROW(checkPartition(KdTree::build(makeGrid({4, 4, 1}), 7, rule)));
    CHECK_NOTHROW(checkPartition(KdTree::build(makeGrid({1, 1, 1}), 1, rule)));
  }
  // Tight but possible: planes move off the proportional place to keep
  // every leaf at least one cell wide.
  checkPartition(KdTree::build(makeGrid({6, 2, 2}), 5, SplitAxisRule::kAlternating));
  checkPartition(KdTree::build(makeGrid({4, 5, 2}), 12, SplitAxisRule::kLongest));
}

// Identity: bricks that partition the grid own every node once (half-open,
// closed at the far edge), so their content grids add up to the whole's.
TEST_CASE("content grids of the bricks add up to the whole volume's", "[kd]") {
  const CornerScene scene;
  const ContentGrid whole = countContent(scene.volume, scene.table);
  CHECK(whole.blocks == IVec3{5, 5, 5});
  CHECK(totalContent(whole) > 1000);
  for (int ranks : {3, 8}) {
    const KdTree tree = KdTree::build(scene.grid, ranks, SplitAxisRule::kAlternating);
    ContentGrid sum = makeContentGrid(scene.grid);
    for (int rank = 0; rank < ranks; ++rank)
      addContent(sum, countContent(cropBrick(scene.volume, tree.ownedBox(rank), 1), scene.table));
    CHECK(sum.counts == whole.counts);
  }
  ContentGrid other = makeContentGrid(scene.grid, {4, 4, 4});
  CHECK_THROWS_AS(addContent(other, whole), Error);
  CHECK_THROWS_AS(makeContentGrid(scene.grid, {0, 8, 8}), Error);
  CHECK_THROWS_AS(KdTree::buildBalanced(makeGrid({50, 40, 40}), 4, SplitAxisRule::kLongest, whole),
                  Error);
}

TEST_CASE("balanced k-d tree gives each rank about equal content", "[kd]") {
  const CornerScene scene;
  for (IVec3 block : {IVec3{8, 8, 8}, IVec3{2, 2, 2}}) {
    const ContentGrid content = countContent(scene.volume, scene.table, block);
    const double total = double(totalContent(content));
    // Balancing is for trees that turn their axis (decomposition
    // "balanced"); slabs of one axis cannot even out a ball this small.
    for (SplitAxisRule rule : {SplitAxisRule::kAlternating, SplitAxisRule::kLongest})
      for (int ranks : {2, 3, 5, 8}) {
        const KdTree plain = KdTree::build(scene.grid, ranks, rule);
        const KdTree balanced = KdTree::buildBalanced(scene.grid, ranks, rule, content);
        checkPartition(balanced);
        const std::vector<std::uint64_t> even = contentPerRank(balanced, scene.volume, scene.table);
        const std::vector<std::uint64_t> naive = contentPerRank(plain, scene.volume, scene.table);
        const auto [lo, hi] = std::minmax_element(even.begin(), even.end());
        const double mean = total / ranks;
        INFO("block " << block.x << " rule " << int(rule) << " ranks " << ranks << ": balanced "
                      << *lo << ".." << *hi << ", mean " << mean);
        // Planes fall on nodes: a slab of the ball holds up to ~700 voxels,
        // over half the mean at 8 ranks, and each level of the tree can
        // miss by half a slab (see the next test). Coarse blocks also
        // spread a count evenly over cells the ball fills unevenly.
        const double tolerance = block.x == 8 ? 0.3 : 0.2;
        CHECK(double(*lo) >= (1 - tolerance) * mean);
        CHECK(double(*hi) <= (1 + tolerance) * mean);
        // The cell split is far from even: the ranks near the ball carry it.
        CHECK(double(*std::max_element(naive.begin(), naive.end())) > (1 + 2 * tolerance) * mean);
        bool differs = false;
        for (int r = 0; r < ranks; ++r) differs |= !(plain.ownedBox(r) == balanced.ownedBox(r));
        CHECK(differs);
      }
  }
  // No content at all: the balanced tree is the plain one.
  const ContentGrid none = makeContentGrid(scene.grid);
  const KdTree a = KdTree::buildBalanced(scene.grid, 5, SplitAxisRule::kLongest, none);
  const KdTree b = KdTree::build(scene.grid, 5, SplitAxisRule::kLongest);
  for (int r = 0; r < 5; ++r) CHECK(a.ownedBox(r) == b.ownedBox(r));
}

// Identity: with one-cell blocks the content profile is exact (block i
// holds the nodes of index i, the grid's last node with the last), so the
// balanced plane is the node plane whose left content is nearest the
// target share: it misses by at most half the slab beside the plane.
TEST_CASE("balanced planes miss their content share by at most half a slab", "[kd]") {
  const CornerScene scene;
  auto contentOf = [&](const NodeBox& box) {
    return double(totalContent(countContent(cropBrick(scene.volume, box, 0), scene.table)));
  };
  const ContentGrid content = countContent(scene.volume, scene.table, {1, 1, 1});
  for (SplitAxisRule rule : kRules)
    for (int ranks : {2, 3, 5, 8, 11}) {
      const KdTree tree = KdTree::buildBalanced(scene.grid, ranks, rule, content);
      for (const KdNode& n : tree.nodes()) {
        if (n.leaf()) continue;
        const int all = n.rankEnd - n.rankBegin;
        const double target = contentOf(n.box) * (all / 2) / all;
        const double left = contentOf(tree.nodes()[std::size_t(n.left)].box);
        NodeBox before = n.box, after = n.box;
        before.lo[n.axis] = n.plane - 1;
        before.hi[n.axis] = n.plane;
        after.lo[n.axis] = n.plane;
        after.hi[n.axis] = n.plane + 1;
        INFO("ranks " << ranks << " node " << toString(n.box) << " plane " << n.plane);
        CHECK(std::abs(left - target) <=
              0.5 * std::max(contentOf(before), contentOf(after)) + 1e-9);
      }
    }
}

TEST_CASE("leftInFront: the eye's side, or the side the view comes from", "[kd]") {
  const GridGeometry grid = makeGrid({41, 11, 11}, {0.5, 1, 1}, {10, 0, 0});
  const KdTree tree = KdTree::build(grid, 2, SplitAxisRule::kLongest);
  REQUIRE(tree.nodes()[0].axis == 0);
  REQUIRE(tree.nodes()[0].plane == 20);  // world x = 20
  const Vec3 at{20, 5, 5};
  using P = Projection;
  CHECK(tree.leftInFront(0, viewFrom(P::kPerspective, {19.9, 5, -30}, at, 0)));
  CHECK_FALSE(tree.leftInFront(0, viewFrom(P::kPerspective, {20.1, 5, -30}, at, 0)));
  // Orthographic: where the eye sits does not matter, the direction does.
  CHECK(tree.leftInFront(0, viewFrom(P::kOrthographic, {25, 5, -30}, {25.1, 5, 5}, 20)));
  CHECK_FALSE(tree.leftInFront(0, viewFrom(P::kOrthographic, {15, 5, -30}, {14.9, 5, 5}, 20)));
  // inFront agrees.
  CHECK(tree.inFront(0, 1, viewFrom(P::kPerspective, {0, 5, 5}, at, 0)));
  CHECK(tree.inFront(1, 0, viewFrom(P::kPerspective, {40, 5, 5}, at, 0)));
  CHECK_THROWS_AS(tree.inFront(0, 2, viewFrom(P::kPerspective, {0, 5, 5}, at, 0)), Error);
}

// Identity: a front-to-back order is one in which no brick comes after a
// brick it hides. Checked two ways for many cameras: (1) brute force, along
// random rays the bricks are entered in visibilityOrder; (2) two bricks that
// are separated along one axis and overlap on the other two can only be
// ordered by the plane between them: the one on the eye's side (the side
// the orthographic view comes from) first.
TEST_CASE("visibilityOrder is a front-to-back order for any camera", "[kd]") {
  const GridGeometry grid = makeGrid({40, 33, 27}, {1, 0.7, 1.3}, {-5, 2, 1});
  const Vec3 lo = grid.domainMin(), hi = grid.domainMax(), centre = grid.center();
  const double radius = length(hi - lo) / 2;
  std::mt19937 rng(20261121);
  std::uniform_real_distribution<double> unit(0, 1);
  auto pointInDomain = [&] {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = lo[a] + (hi[a] - lo[a]) * unit(rng);
    return p;
  };

  // Cameras: outside from random and axis-aligned directions, and inside.
  std::vector<Camera> cameras;
  std::vector<Vec3> directions = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (int i = 0; i < 14; ++i) directions.push_back(randomDirection(rng));
  for (const Vec3& d : directions) {
    cameras.push_back(
        viewFrom(Projection::kOrthographic, centre - d * (3 * radius), centre, 2 * radius));
    cameras.push_back(viewFrom(Projection::kPerspective, centre - d * (3 * radius), centre, 0));
  }
  for (int i = 0; i < 10; ++i) {
    const Vec3 eye = pointInDomain();
    cameras.push_back(viewFrom(Projection::kPerspective, eye, eye + randomDirection(rng), 0));
  }
  // An eye exactly on a plane node (world x of node 20): either order is right.
  cameras.push_back(viewFrom(Projection::kPerspective, {15, 13, 18}, {15.5, 40, 18}, 0));

  std::vector<KdTree> trees;
  for (int ranks : {2, 3, 5, 7, 8, 13})
    for (SplitAxisRule rule : kRules) trees.push_back(KdTree::build(grid, ranks, rule));

  for (const KdTree& tree : trees) {
    const int n = tree.rankCount();
    std::vector<Vec3> boxLo(static_cast<std::size_t>(n)), boxHi(static_cast<std::size_t>(n));
    for (int r = 0; r < n; ++r) {
      boxLo[std::size_t(r)] = grid.nodePosition(tree.ownedBox(r).lo);
      boxHi[std::size_t(r)] = grid.nodePosition(tree.ownedBox(r).hi);
    }
    for (const Camera& camera : cameras) {
      const std::vector<int> order = tree.visibilityOrder(camera);
      std::vector<int> position(static_cast<std::size_t>(n), -1);
      REQUIRE(int(order.size()) == n);
      for (int i = 0; i < n; ++i) {
        REQUIRE(order[std::size_t(i)] >= 0);
        REQUIRE(order[std::size_t(i)] < n);
        REQUIRE(position[std::size_t(order[std::size_t(i)])] == -1);  // a permutation
        position[std::size_t(order[std::size_t(i)])] = i;
      }
      const bool ortho = camera.projection() == Projection::kOrthographic;
      const Vec3 eye = camera.spec().eye;

      // (1) Random rays: where each brick's interval begins along the ray.
      for (int k = 0; k < 200; ++k) {
        Ray ray;
        if (ortho) {
          const double s = (2 * unit(rng) - 1) * radius, t = (2 * unit(rng) - 1) * radius;
          ray = {eye + camera.right() * s + camera.up() * t, camera.forward()};
        } else {
          ray = {eye, randomDirection(rng)};
        }
        std::vector<std::pair<double, int>> entered;
        for (int r = 0; r < n; ++r) {
          double t0 = 0, t1 = 1e300;
          for (int a = 0; a < 3 && t0 < t1; ++a) {
            const double d = ray.direction[a], o = ray.origin[a];
            const double near = boxLo[std::size_t(r)][a], far = boxHi[std::size_t(r)][a];
            if (d == 0) {
              if (o < near || o > far) t1 = -1;
              continue;
            }
            const double ta = (near - o) / d, tb = (far - o) / d;
            t0 = std::max(t0, std::min(ta, tb));
            t1 = std::min(t1, std::max(ta, tb));
          }
          if (t1 - t0 > 1e-6) entered.push_back({t0, r});
        }
        std::sort(entered.begin(), entered.end());
        for (std::size_t i = 1; i < entered.size(); ++i) {
          INFO("ranks " << n << " ray " << k << ": brick " << entered[i - 1].second
                        << " entered before " << entered[i].second);
          CHECK(position[std::size_t(entered[i - 1].second)] <
                position[std::size_t(entered[i].second)]);
        }
      }

      // (2) Pairs separated along exactly one axis.
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          if (a == b) continue;
          CHECK(tree.inFront(a, b, camera) ==
                (position[std::size_t(a)] < position[std::size_t(b)]));
          const NodeBox& A = tree.ownedBox(a);
          const NodeBox& B = tree.ownedBox(b);
          for (int axis = 0; axis < 3; ++axis) {
            if (A.hi[axis] > B.lo[axis]) continue;  // A is not below B on this axis
            bool overlap = true;
            for (int o = 0; o < 3; ++o)
              if (o != axis) overlap &= std::min(A.hi[o], B.hi[o]) > std::max(A.lo[o], B.lo[o]);
            if (!overlap) continue;
            const bool aFirst =
                ortho ? camera.forward()[axis] > 0 : eye[axis] < grid.nodePosition(A.hi)[axis];
            const bool bFirst =
                ortho ? camera.forward()[axis] < 0 : eye[axis] > grid.nodePosition(B.lo)[axis];
            if (aFirst) CHECK(position[std::size_t(a)] < position[std::size_t(b)]);
            if (bFirst) CHECK(position[std::size_t(b)] < position[std::size_t(a)]);
          }
        }
    }
  }
}

TEST_CASE("storedBox holds the ghost layers ghostLayers asks for and no more", "[kd]") {
  const GridGeometry grid = makeGrid({40, 40, 40});
  const Brick whole = floatVolume(grid, [](Vec3 p) { return p.x + p.y; });
  const KdTree tree = KdTree::build(grid, 6, SplitAxisRule::kAlternating);
  RenderOptions plain, shaded, pre;
  plain.step = shaded.step = 0.5;
  shaded.shading.enabled = true;
  pre.step = 2.5;
  pre.preintegrated = true;
  for (const RenderOptions& o : {plain, shaded, pre}) {
    const int ghost = ghostLayers(grid, o);
    for (int rank = 0; rank < tree.rankCount(); ++rank) {
      const NodeBox owned = tree.ownedBox(rank);
      const NodeBox stored = storedBox(tree, rank, ghost);
      CHECK(stored == cropBrick(whole, owned, ghost).stored());
      for (int a = 0; a < 3; ++a) {
        CHECK(stored.lo[a] == std::max<std::int64_t>(0, owned.lo[a] - ghost));
        CHECK(stored.hi[a] == std::min<std::int64_t>(grid.dims[a] - 1, owned.hi[a] + ghost));
      }
    }
  }
  CHECK(ghostLayers(grid, plain) == 0);
  CHECK(ghostLayers(grid, shaded) == 1);
  CHECK(ghostLayers(grid, pre) == 5);  // a segment's back node is corrected from two steps on
  CHECK_THROWS_AS(storedBox(tree, 6, 0), Error);
  CHECK_THROWS_AS(storedBox(tree, 0, -1), Error);
}

// Identity: each sample lies in exactly one leaf's brick and reads the same
// voxels there (with the ghost layers of ghostLayers), so compositing the
// leaves' images in visibilityOrder equals rendering the whole, up to float
// rounding of the regrouped "over" (~1e-7; tolerance 1e-5).
TEST_CASE("k-d bricks composited in visibilityOrder equal the whole", "[kd]") {
  static ThreadPool pool(2);
  const GridGeometry grid = makeGrid({40, 40, 40}, {1, 1, 1}, {-19.5, -19.5, -19.5});
  const Brick whole = floatVolume(grid, [](Vec3 p) {
    auto gauss = [&](Vec3 c, double s) { return std::exp(-dot(p - c, p - c) / (2 * s * s)); };
    return std::min(
        1.0, 0.8 * gauss({-5, -3, 2}, 7) + 0.7 * gauss({7, 6, -4}, 5) + 0.5 * gauss({2, 9, 8}, 3));
  });
  TransferFunctionSpec tf;
  tf.points = {{0.0, 0, 0, 0, 0},
               {0.2, 0.1, 0.3, 0.9, 0.03},
               {0.5, 0.9, 0.6, 0.2, 0.15},
               {1.0, 1, 1, 1, 0.4}};
  tf.unitDistance = 1;
  TransferTable table(tf, 0.5);

  RenderOptions plain, shaded, pre;
  plain.step = shaded.step = 0.5;
  shaded.shading.enabled = true;
  pre.step = 1.5;
  pre.preintegrated = true;
  const Camera cameras[] = {
      viewFrom(Projection::kOrthographic, {-50, -70, 40}, {0, 0, 0}, 60, 64),
      viewFrom(Projection::kPerspective, {60, -45, -35}, {0, 0, 0}, 0, 64),
      viewFrom(Projection::kPerspective, {3, -4, 2}, {10, 6, -3}, 0, 64),  // inside
      viewFrom(Projection::kOrthographic, {0, 0, 80}, {0, 0, 0}, 45, 64),  // along an axis
  };
  const ContentGrid content = countContent(whole, table);

  // Pre-integration tables cost 0.1 s a brick to build: one rank count.
  struct Case {
    RenderOptions options;
    std::vector<int> rankCounts;
  };
  const Case cases[] = {{plain, {3, 5, 8}}, {shaded, {3, 5, 8}}, {pre, {5}}};
  for (const Case& c : cases) {
    const RenderOptions& o = c.options;
    BrickRenderer wholeRenderer(whole);
    wholeRenderer.classify(tf, o);
    const int ghost = ghostLayers(grid, o);
    for (int ranks : c.rankCounts) {
      const KdTree trees[] = {KdTree::build(grid, ranks, SplitAxisRule::kAlternating),
                              KdTree::buildBalanced(grid, ranks, SplitAxisRule::kLongest, content)};
      for (const KdTree& tree : trees) {
        std::vector<Brick> bricks;
        for (int rank = 0; rank < ranks; ++rank)
          bricks.push_back(cropBrick(whole, tree.ownedBox(rank), ghost));
        std::vector<std::unique_ptr<BrickRenderer>> renderers;
        for (const Brick& brick : bricks) {
          renderers.push_back(std::make_unique<BrickRenderer>(brick));
          renderers.back()->classify(tf, o);
        }
        for (const Camera& camera : cameras) {
          const Image reference = wholeRenderer.render(camera, o, pool);
          Image composite = Image::fullFrame(64, 64);
          for (int rank : tree.visibilityOrder(camera))
            compositeUnder(composite, renderers[std::size_t(rank)]->render(camera, o, pool));
          const ImageError e = compareImages(composite, reference);
          INFO("ranks " << ranks << " ghost " << ghost << " camera eye " << camera.spec().eye.x
                        << "," << camera.spec().eye.y << "," << camera.spec().eye.z
                        << ": max error " << e.maxAbs);
          CHECK(e.maxAbs <= 1e-5);
          // The scene is not blank: the identity says something.
          double alpha = 0;
          for (const Rgba& p : reference.toFullFrame().pixels())
            alpha = std::max(alpha, double(p.a));
          CHECK(alpha > 0.3);
        }
      }
    }
  }
}

}  // namespace pvr::core
