// Every strategy on the in-process communicator, 1..8 ranks, against the
// serial composite of the same partial images in the tree's visibility
// order: composite = p_0 over p_1 over ... over p_{n-1}, front to back.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <mutex>
#include <random>

#include "decompose/kd_tree.h"
#include "in_process_communicator.h"
#include "strategy.h"

using namespace pvr::composite;
using pvr::comm::runInProcess;
using namespace pvr::core;

namespace {

GridGeometry testGrid() {
  GridGeometry g;
  g.dims = {41, 33, 29};
  g.spacing = {1, 1.25, 1.5};
  return g;
}

struct View {
  const char* name;
  CameraSpec spec;
};

std::vector<View> views(const GridGeometry& grid) {
  const Vec3 c = grid.center();
  std::vector<View> out;
  CameraSpec axis;
  axis.projection = Projection::kOrthographic;
  axis.eye = c + Vec3{0, 0, 100};
  axis.lookAt = c;
  axis.up = {0, 1, 0};
  axis.height = 60;
  out.push_back({"axis-aligned", axis});
  CameraSpec oblique = axis;
  oblique.eye = c + Vec3{-70, 50, 40};
  oblique.up = {0, 0, 1};
  out.push_back({"oblique", oblique});
  CameraSpec persp;
  persp.projection = Projection::kPerspective;
  persp.eye = c + Vec3{60, -80, 35};
  persp.lookAt = c;
  persp.fovYDeg = 40;
  out.push_back({"perspective", persp});
  CameraSpec inside = persp;
  inside.eye = c + Vec3{3, -2, 1};
  inside.lookAt = c + Vec3{10, 5, 2};
  inside.fovYDeg = 90;
  out.push_back({"eye inside", inside});
  return out;
}

// A partial image over the brick's screen rectangle: random premultiplied
// colours with holes of empty pixels, different per rank.
Image partialImage(const KdTree& tree, const Camera& camera, int rank) {
  const GridGeometry& g = tree.grid();
  const NodeBox box = tree.ownedBox(rank);
  const PixelRect rect = camera.project(g.nodePosition(box.lo), g.nodePosition(box.hi));
  Image image(camera.width(), camera.height(), rect);
  std::mt19937 rng(1234u + unsigned(rank));
  std::uniform_real_distribution<float> u(0, 1);
  for (Rgba& p : image.pixels()) {
    if (u(rng) < 0.2f) continue;
    p.a = u(rng);
    p.r = p.a * u(rng);
    p.g = p.a * u(rng);
    p.b = p.a * u(rng);
  }
  return image;
}

Image serialComposite(const std::vector<Image>& partials, const KdTree& tree, const Camera& camera) {
  Image frame = Image::fullFrame(camera.width(), camera.height());
  for (int r : tree.visibilityOrder(camera)) compositeUnder(frame, partials[std::size_t(r)]);
  return frame;
}

struct Run {
  Image root;
  std::vector<Image> tiles;
  std::vector<PixelRect> tileRects;
  std::vector<CompositeStats> stats;
};

Run runStrategy(const Strategy& strategy, const std::vector<Image>& partials, const KdTree& tree,
                const Camera& camera, const CompositeOptions& options) {
  const int n = tree.rankCount();
  Run run;
  run.tiles.resize(std::size_t(n));
  run.tileRects.resize(std::size_t(n));
  run.stats.resize(std::size_t(n));
  runInProcess(n, [&](Communicator& comm) {
    CompositeResult result = strategy.composite(partials[std::size_t(comm.rank())], tree, camera, comm, options);
    const auto r = std::size_t(comm.rank());
    run.stats[r] = result.stats;
    run.tileRects[r] = result.tile;
    if (comm.rank() == options.root && options.final == FinalImage::kGatherAtRoot) run.root = result.image;
    run.tiles[r] = std::move(result.image);
  });
  return run;
}

}  // namespace

TEST_CASE("every strategy equals the serial composite in visibility order, 1..8 ranks", "[strategy]") {
  const GridGeometry grid = testGrid();
  StrategyParams params;
  for (const StrategyEntry& entry : strategies())
    for (int radix : {2, 4, 8}) {
      if (entry.name != "radix-k" && radix != 2) continue;
      params.radix = radix;
      const auto strategy = entry.make(params);
      for (int n = 1; n <= 8; ++n) {
        const KdTree tree = KdTree::build(grid, n, SplitAxisRule::kAlternating);
        for (const View& view : views(grid)) {
          const Camera camera(view.spec, 48, 40);
          std::vector<Image> partials;
          for (int r = 0; r < n; ++r) partials.push_back(partialImage(tree, camera, r));
          const Image expected = serialComposite(partials, tree, camera);
          INFO(entry.name << " k=" << radix << ", " << n << " ranks, " << view.name);

          // Gathered at a root (rank n-1, to exercise a root other than 0).
          CompositeOptions options;
          options.root = n - 1;
          const Run gathered = runStrategy(*strategy, partials, tree, camera, options);
          CHECK(maxAbsDifference(gathered.root, expected) <= 1e-5);

          // Left in tiles: the tiles are disjoint and together make the frame.
          options.final = FinalImage::kTiles;
          options.codec = ImageCodec::kRle;
          const Run tiled = runStrategy(*strategy, partials, tree, camera, options);
          Image assembled = Image::fullFrame(camera.width(), camera.height());
          long area = 0;
          for (int r = 0; r < n; ++r) {
            const PixelRect t = tiled.tileRects[std::size_t(r)];
            area += long(t.width()) * t.height();
            const Image& tile = tiled.tiles[std::size_t(r)];
            CHECK(tile.rect().intersect(t) == tile.rect());
            for (int y = tile.rect().y0; y < tile.rect().y1; ++y)
              for (int x = tile.rect().x0; x < tile.rect().x1; ++x) assembled.at(x, y) = tile.at(x, y);
          }
          CHECK(area == long(camera.width()) * camera.height());
          CHECK(maxAbsDifference(assembled, expected) <= 1e-5);
        }
      }
    }
}

TEST_CASE("binary swap sends log2(n) messages per rank for powers of two", "[strategy]") {
  const GridGeometry grid = testGrid();
  const auto strategy = makeStrategy("binary-swap");
  for (int n : {1, 2, 4, 8}) {
    const KdTree tree = KdTree::build(grid, n, SplitAxisRule::kAlternating);
    const Camera camera(views(grid)[1].spec, 40, 40);
    std::vector<Image> partials;
    for (int r = 0; r < n; ++r) partials.push_back(partialImage(tree, camera, r));
    const Run run = runStrategy(*strategy, partials, tree, camera, {});
    for (const CompositeStats& s : run.stats) CHECK(s.messagesSent == std::uint64_t(std::countr_zero(unsigned(n))));
  }
}

TEST_CASE("every codec composites alike", "[strategy]") {
  const GridGeometry grid = testGrid();
  const KdTree tree = KdTree::build(grid, 5, SplitAxisRule::kAlternating);
  const Camera camera(views(grid)[2].spec, 40, 32);
  std::vector<Image> partials;
  for (int r = 0; r < 5; ++r) partials.push_back(partialImage(tree, camera, r));
  const Image expected = serialComposite(partials, tree, camera);
  for (ImageCodec codec : {ImageCodec::kRaw, ImageCodec::kRle, ImageCodec::kRleZlib, ImageCodec::kAuto}) {
    CompositeOptions options;
    options.codec = codec;
    const Run run = runStrategy(*makeStrategy("binary-swap"), partials, tree, camera, options);
    CHECK(maxAbsDifference(run.root, expected) <= 1e-5);
  }
}

TEST_CASE("unknown strategies and bad radices are refused by name", "[strategy]") {
  CHECK_THROWS_WITH(makeStrategy("bogus"), Catch::Contains("binary-swap"));
  StrategyParams params;
  params.radix = 3;
  CHECK_THROWS_WITH(makeStrategy("radix-k", params), Catch::Contains("power of two"));
}
