// Bricks of a several-volume scene rendered apart and composited in
// visibility order equal one rendering of the whole scene
// (decompose/union_regions.h, SceneRenderer's region constructor).
//
// The union of the volumes' domains is split by a k-d tree into 2..9
// regions; each region's brick holds, of each volume, volumeBoxFor() of
// it (or nothing when that is empty), renders the pieces of rays whose
// midpoints it owns, and the images are composited front to back in the
// tree's visibility order. Each piece belongs to exactly one region and
// reads the same voxels there as in the whole, so what differs is float
// rounding (composition regrouped: each brick accumulates from zero and
// the images are composited in float), ~1e-7 per channel (1.2e-7 the
// largest measured); the tolerance is 1e-5, early termination off.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "decompose/union_regions.h"
#include "raycast/raycaster.h"
#include "raycast/scene_renderer.h"
#include "mixed_scenes.h"
#include "reference.h"

namespace pvr::core {
namespace {

using namespace test;


// The scene split over `ranks` regions of the union, each brick cropped
// from the whole volumes, composited front to back. `held` counts the
// bricks that hold no data of some volume.
Image renderBricked(const std::vector<TestVolume>& volumes, int ranks, const Camera& camera, const RenderOptions& o,
                    int* held = nullptr, std::uint64_t* samples = nullptr) {
  std::vector<GridGeometry> grids;
  for (const TestVolume& v : volumes) grids.push_back(v.brick.grid());
  const KdTree tree = KdTree::build(unionGrid(grids), ranks, SplitAxisRule::kLongest);
  Image out = Image::fullFrame(camera.width(), camera.height());
  for (int rank : tree.visibilityOrder(camera)) {
    const WorldRegion region = regionOf(tree, rank);
    std::vector<Brick> parts;
    parts.reserve(volumes.size());
    std::vector<const Brick*> bricks;
    for (const TestVolume& v : volumes) {
      const NodeBox box = volumeBoxFor(v.brick.grid(), region, o.step);
      if (box.empty()) {
        bricks.push_back(nullptr);
        if (held) ++*held;
        continue;
      }
      parts.push_back(cropBrick(v.brick, box, 0));
      bricks.push_back(&parts.back());
    }
    SceneRenderer renderer(bricks, grids, region);
    renderer.classify(sceneVolumes(volumes), o);
    RenderStats stats;
    compositeUnder(out, renderer.render(camera, o, pool(), &stats));
    if (samples) *samples += stats.samples;
  }
  return out;
}

// Bricked over 2..9 regions == whole, within 1e-5 (see the file comment).
void checkBricks(const std::vector<TestVolume>& volumes, const Camera& camera, const RenderOptions& o) {
  RenderStats full;
  const Image whole = castScene(volumes, camera, o, &full);
  CHECK(maxAlpha(whole) > 0.2);
  for (int ranks = 2; ranks <= 9; ++ranks) {
    std::uint64_t samples = 0;
    const ImageError e = compareImages(renderBricked(volumes, ranks, camera, o, nullptr, &samples), whole);
    INFO(ranks << " bricks: max " << e.maxAbs << ", RMSE " << e.rmse << "; samples " << samples << " of " << full.samples);
    CHECK(e.maxAbs < 1e-5);
    // The bricks split the work: a sample is taken by the brick that owns
    // it, twice only where a slot cut by a volume's face is split between
    // two bricks (0.4 % more at most measured).
    CHECK(double(samples) <= 1.01 * double(full.samples));
  }
}

}  // namespace

// The union grid covers every domain, at the finest spacing per axis; a
// region's outer faces are infinite; a volume far from a region has no box;
// the regions partition each volume's nodes (nodesIn).
TEST_CASE("union regions cover every volume and name the nodes each brick reads", "[decompose][mixed]") {
  const GridGeometry a = boxGrid({11, 11, 11}, 1.0, {0, 0, 0}), b = boxGrid({9, 9, 9}, 0.5, {40, 1, 2});
  const GridGeometry u = unionGrid({a, b});
  CHECK(u.origin == Vec3{0, 0, 0});
  CHECK(u.domainMax().x == Approx(44.0));
  CHECK(u.domainMax().y == Approx(10.0));
  CHECK(u.spacing.x <= 0.5);
  const KdTree tree = KdTree::build(u, 2, SplitAxisRule::kLongest);
  const WorldRegion left = regionOf(tree, 0), right = regionOf(tree, 1);
  CHECK(left.lo.x == -WorldRegion::kInfinity);
  CHECK(right.hi.x == WorldRegion::kInfinity);
  CHECK(left.hi.x == right.lo.x);
  CHECK(volumeBoxFor(b, left, 0.5).empty());
  CHECK(volumeBoxFor(a, right, 0.5).empty());
  CHECK(volumeBoxFor(a, left, 0.5) == a.allNodes());
  CHECK(volumeBoxFor(b, WorldRegion{}, 0.5) == b.allNodes());
  // Each volume's nodes in the regions: every node once, each inside the
  // box its brick reads.
  for (int ranks = 1; ranks <= 9; ++ranks) {
    const KdTree t = KdTree::build(u, ranks, SplitAxisRule::kLongest);
    for (const GridGeometry& g : {a, b}) {
      std::int64_t nodes = 0;
      for (int r = 0; r < ranks; ++r) {
        const NodeBox mine = nodesIn(g, regionOf(t, r));
        if (mine.empty()) continue;
        nodes += mine.nodeCount();
        CHECK(volumeBoxFor(g, regionOf(t, r), 0.5).contains(mine));
        for (int q = 0; q < r; ++q) CHECK(mine.intersect(nodesIn(g, regionOf(t, q))).empty());
      }
      CHECK(nodes == g.allNodes().nodeCount());
    }
  }
}

TEST_CASE("bricks of two overlapping volumes of different spacing equal the whole", "[raycast][mixed][bricks]") {
  const std::vector<TestVolume> volumes = overlappingVolumes();
  const Vec3 c{14, 12, 10};
  SECTION("eye outside") {
    const Vec3 d = normalize(Vec3{-0.6, 0.7, -0.4});
    checkBricks(volumes, orthographic(c - d * 50.0, c, 40), makeOptions(1.0));
    checkBricks(volumes, perspective(c - d * 60.0, c, 40), makeOptions(0.6));
  }
  SECTION("eye inside both") {
    const Vec3 eye{15, 12, 10};
    checkBricks(volumes, perspective(eye, eye + Vec3{1, 0.2, 0.1}, 90), makeOptions(0.35));
  }
  SECTION("shaded") {
    const Vec3 d = normalize(Vec3{-0.6, 0.7, -0.4});
    checkBricks(volumes, perspective(c - d * 60.0, c, 40), makeOptions(0.5, false, true));
  }
}

TEST_CASE("bricks of a volume inside another equal the whole", "[raycast][mixed][bricks]") {
  const std::vector<TestVolume> volumes = nestedVolumes();
  const Vec3 c{13.5, 13.5, 13.5};
  SECTION("eye outside") {
    const Vec3 d = normalize(Vec3{0.7, 0.5, -0.5});
    checkBricks(volumes, orthographic(c - d * 50.0, c, 44), makeOptions(1.0));
  }
  SECTION("eye inside both") {
    const Vec3 eye{14, 13, 14};
    checkBricks(volumes, perspective(eye, eye + Vec3{0.4, 1, -0.3}, 100), makeOptions(0.25));
  }
}

TEST_CASE("bricks of disjoint volumes side by side equal the whole", "[raycast][mixed][bricks]") {
  const std::vector<TestVolume> volumes = disjointVolumes();
  SECTION("eye outside") {
    const Vec3 at{18, 7.5, 7.5};
    checkBricks(volumes, perspective(at + Vec3{-40, -6, 5}, at, 30), makeOptions(1.0));
    // Some bricks hold nothing of one volume: its faces still cut the rays there.
    int held = 0;
    renderBricked(volumes, 6, perspective(at + Vec3{-40, -6, 5}, at, 30), makeOptions(1.0), &held);
    CHECK(held > 0);
  }
  SECTION("eye inside the nearer volume") {
    const Vec3 eye{8, 7.5, 7.5};
    checkBricks(volumes, perspective(eye, eye + Vec3{1, 0.05, 0.02}, 90), makeOptions(0.4));
  }
}

// One visible volume of two renders through its brick renderer, with
// every option, restricted to each region: bricked == whole as well.
TEST_CASE("bricks of a scene with one visible volume of two equal the whole", "[raycast][mixed][bricks]") {
  std::vector<TestVolume> volumes = overlappingVolumes();
  volumes[1].visible = false;
  const Vec3 c{14, 12, 10};
  const Vec3 d = normalize(Vec3{-0.6, 0.7, -0.4});
  for (int options = 0; options < 4; ++options) {
    INFO("preintegrated " << (options & 1) << ", shaded " << (options & 2));
    checkBricks(volumes, perspective(c - d * 60.0, c, 40), makeOptions(0.7, options & 1, options & 2));
  }
}

}  // namespace pvr::core
