// Clear cells (renderer/raycast/clear_cells.h): the cells whose samples all
// classify as transparent, which the batched kernels (plain and
// pre-integrated) skip before reading a voxel. Which cells are marked, and
// that the skip leaves every image bit for bit as it was: an integer brick
// (with clear cells) renders exactly as its float copy (float bricks have
// none) does.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "raycast/clear_cells.h"
#include "raycast/kernel.h"
#include "raycast/kernel_setup.h"
#include "raycast/macrocells.h"
#include "raycast/raycaster.h"
#include "reference.h"
#include "transfer.h"

namespace pvr::core {
namespace {

// Integer node values on 40^3 nodes: 0 around, a soft blob of up to 120 in
// the middle and a speck of 250 at the eight nodes of cell (30, 8, 30).
double speckAndBlob(Vec3 p) {
  const Vec3 blob = p - Vec3{20, 19, 21}, speck = p - Vec3{30.5, 8.5, 30.5};
  if (std::max({std::abs(speck.x), std::abs(speck.y), std::abs(speck.z)}) < 0.6) return 250.0;
  return std::round(120.0 * std::exp(-dot(blob, blob) / (2 * 5.0 * 5.0)));
}

// Opacity only from 200 up: the speck alone is visible.
TransferFunctionSpec speckOnly() { return transfer({{0, 0, 0, 0, 0}, {200, 0, 0, 0, 0}, {250, 1, 0.5, 0.2, 0.9}}); }

// Opacity between 40 and 130 only: the speck's value lies in the table's
// transparent high end, the ground's in its low end.
TransferFunctionSpec blobOnly() {
  return transfer({{0, 0, 0, 0, 0}, {40, 0.2, 0.5, 0.9, 0}, {80, 0.4, 0.8, 0.6, 0.3}, {130, 0, 0, 0, 0},
                   {255, 0, 0, 0, 0}});
}

// The bit of cell (i, j, k) of a whole-volume brick of n^3 nodes.
bool clearCell(const ClearCells& cells, std::int64_t n, int i, int j, int k) {
  const std::int64_t at = i + j * n + k * n * n;
  return (cells.bits()[at >> 3] >> (at & 7)) & 1;
}

// The clear cells of plain samples, or of pre-integrated segments; whole
// macrocells decided by their bounds, or (byBounds false) every node read.
ClearCells clearCellsOf(const Brick& brick, const TransferFunctionSpec& tf, bool segments = false,
                        bool byBounds = true) {
  const MacrocellGrid macrocells(brick);
  const TransferTable table(tf, 0.5);
  const PreintegratedTable integrals(tf);
  KernelParams p;
  setBrick(p, brick, macrocells);
  setTables(p, table, segments ? &integrals : nullptr, 0.5);
  ClearCells cells;
  cells.build(segments ? ClearEnds::ofSegments(p.preint) : ClearEnds::ofSamples(p), p, brick,
              byBounds ? &macrocells.bounds() : nullptr, &pool());
  return cells;
}

TEST_CASE("a cell is clear when its eight nodes all lie in one transparent end of the table") {
  const Brick brick = makeVolume(cubeGrid(40), ScalarType::kUInt8, speckAndBlob);
  const ClearCells speck = clearCellsOf(brick, speckOnly());
  REQUIRE(speck.bits() != nullptr);
  CHECK(clearCell(speck, 40, 0, 0, 0));     // ground
  CHECK(clearCell(speck, 40, 20, 19, 21));  // the blob's middle, 120: below the visible 200
  // The speck's cell and every cell that shares one of its nodes.
  for (int k = 29; k <= 31; ++k)
    for (int j = 7; j <= 9; ++j)
      for (int i = 29; i <= 31; ++i) CHECK_FALSE(clearCell(speck, 40, i, j, k));
  CHECK(clearCell(speck, 40, 28, 8, 30));  // one cell further: all its nodes 0

  const ClearCells blob = clearCellsOf(brick, blobOnly());
  REQUIRE(blob.bits() != nullptr);
  CHECK(clearCell(blob, 40, 0, 0, 0));         // ground, the low end
  CHECK(clearCell(blob, 40, 30, 8, 30));       // the speck's own cell, the high end
  CHECK_FALSE(clearCell(blob, 40, 29, 8, 30));  // 0 and 250: its samples pass the visible middle
  CHECK_FALSE(clearCell(blob, 40, 20, 19, 21));  // the blob's middle is visible
}

TEST_CASE("segments' clear cells mark one transparent end, the low one") {
  const Brick brick = makeVolume(cubeGrid(40), ScalarType::kUInt8, speckAndBlob);
  // A segment from the ground (low end) into the speck (high end) crosses the visible middle.
  const ClearCells blob = clearCellsOf(brick, blobOnly(), true);
  REQUIRE(blob.bits() != nullptr);
  CHECK(clearCell(blob, 40, 0, 0, 0));
  CHECK_FALSE(clearCell(blob, 40, 30, 8, 30));  // the high end: not marked
  CHECK_FALSE(clearCell(blob, 40, 20, 19, 21));
  // Only a high end: it is marked.
  const ClearCells high = clearCellsOf(brick, transfer({{0, 0.2, 0.5, 0.9, 0.3}, {130, 0.4, 0.8, 0.6, 0.3},
                                                         {200, 0, 0, 0, 0}, {255, 0, 0, 0, 0}}), true);
  REQUIRE(high.bits() != nullptr);
  CHECK(clearCell(high, 40, 30, 8, 30));
  CHECK_FALSE(clearCell(high, 40, 0, 0, 0));
}

TEST_CASE("macrocells decided by their bounds leave the bits every node read gives") {
  // Odd sizes (partial macrocells at the far faces), bricks cut out of the
  // volume at offsets that are not multiples of a macrocell, with ghost
  // layers (stored cells outside every macrocell the brick owns).
  GridGeometry grid;
  grid.dims = {37, 41, 35};
  const std::vector<std::pair<NodeBox, int>> cuts = {
      {NodeBox{{0, 0, 0}, {36, 40, 34}}, 0}, {NodeBox{{5, 3, 0}, {30, 22, 17}}, 1}, {NodeBox{{18, 21, 17}, {36, 40, 34}}, 2}};
  const std::vector<TransferFunctionSpec> tfs = {speckOnly(), blobOnly(),
                                                 transfer({{0, 0.2, 0.5, 0.9, 0.3}, {100, 0.4, 0.8, 0.6, 0.3},
                                                           {110, 0, 0, 0, 0}, {255, 0, 0, 0, 0}})};
  std::size_t marked = 0;
  for (const ScalarType type : {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16}) {
    const Brick whole = makeVolume(grid, type, speckAndBlob);
    for (const auto& [owned, ghost] : cuts) {
      const Brick brick = ghost == 0 && owned == NodeBox{{0, 0, 0}, {36, 40, 34}} ? whole : cropBrick(whole, owned, ghost);
      for (const TransferFunctionSpec& tf : tfs)
        for (const bool segments : {false, true}) {
          const ClearCells byBounds = clearCellsOf(brick, tf, segments, true);
          const ClearCells byNodes = clearCellsOf(brick, tf, segments, false);
          REQUIRE(byBounds.bits() != nullptr);
          REQUIRE(byNodes.bits() != nullptr);
          const std::size_t bytes = std::size_t(brick.stored().nodeCount() + 7) / 8;
          std::size_t differing = 0;
          for (std::size_t n = 0; n < bytes; ++n) {
            differing += byBounds.bits()[n] != byNodes.bits()[n];
            marked += std::size_t(__builtin_popcount(byNodes.bits()[n]));  // (compared bits, not all zero)
          }
          CAPTURE(int(type), owned.lo.x, owned.lo.y, owned.lo.z, ghost, segments);
          CHECK(differing == 0);
        }
    }
  }
  CHECK(marked > 0);
}

TEST_CASE("a transfer function that keeps the transparent ends keeps the bits") {
  const Brick brick = makeVolume(cubeGrid(40), ScalarType::kUInt8, speckAndBlob);
  const MacrocellGrid macrocells(brick);
  auto build = [&](ClearCells& cells, const TransferFunctionSpec& tf) {
    const TransferTable table(tf, 0.5);
    KernelParams p;
    setBrick(p, brick, macrocells);
    setTables(p, table, nullptr, 0.5);
    return cells.build(ClearEnds::ofSamples(p), p, brick, &macrocells.bounds(), &pool());
  };
  ClearCells cells;
  REQUIRE(build(cells, blobOnly()));
  const std::vector<std::uint8_t> before(cells.bits(), cells.bits() + 40 * 40 * 40 / 8);
  // Other colours and opacities inside the visible values: the same ends, nothing built.
  CHECK_FALSE(build(cells, transfer({{0, 0, 0, 0, 0}, {40, 0.9, 0.1, 0.1, 0}, {80, 0.1, 0.9, 0.1, 0.6},
                                     {130, 0, 0, 0, 0}, {255, 0, 0, 0, 0}})));
  CHECK(std::vector<std::uint8_t>(cells.bits(), cells.bits() + before.size()) == before);
  // The visible values moved: built again, as a new ClearCells builds them.
  CHECK(build(cells, speckOnly()));
  ClearCells fresh;
  CHECK(build(fresh, speckOnly()));
  CHECK(std::vector<std::uint8_t>(cells.bits(), cells.bits() + before.size()) ==
        std::vector<std::uint8_t>(fresh.bits(), fresh.bits() + before.size()));
  CHECK(std::vector<std::uint8_t>(cells.bits(), cells.bits() + before.size()) != before);
}

TEST_CASE("no clear cells for a brick above kMaxNodes: issue 11's memory bound has no room for them") {
  // One node more than the limit, zero-filled (all in the low end).
  GridGeometry grid;
  grid.dims = {ClearCells::kMaxNodes / (256 * 256) + 1, 256, 256};
  const Brick big(grid, ScalarType::kUInt8, grid.allNodes(), grid.allNodes());
  REQUIRE(big.stored().nodeCount() > ClearCells::kMaxNodes);
  CHECK(clearCellsOf(big, speckOnly()).bits() == nullptr);
  grid.dims.x -= 1;  // at the limit
  const Brick limit(grid, ScalarType::kUInt8, grid.allNodes(), grid.allNodes());
  REQUIRE(limit.stored().nodeCount() == ClearCells::kMaxNodes);
  CHECK(clearCellsOf(limit, speckOnly()).bits() != nullptr);
}

TEST_CASE("no clear cells for a float brick or a table without a transparent end") {
  const Brick floats = makeVolume(cubeGrid(24), ScalarType::kFloat32, speckAndBlob);
  CHECK(clearCellsOf(floats, speckOnly()).bits() == nullptr);
  const Brick bytes = makeVolume(cubeGrid(24), ScalarType::kUInt8, speckAndBlob);
  CHECK(clearCellsOf(bytes, transfer({{0, 0.5, 0.5, 0.5, 0.1}, {255, 1, 1, 1, 0.5}})).bits() == nullptr);
}

TEST_CASE("skipping clear cells leaves the image bit for bit as it was") {
  const GridGeometry grid = cubeGrid(40);
  const std::vector<Camera> cameras = {
      makeCamera(Projection::kPerspective, {80, -40, 75}, {20, 20, 20}, {0, 0, 1}, 45, 64, 64),
      makeCamera(Projection::kOrthographic, {20, -60, 30}, {20, 20, 30}, {0, 0, 1}, 45, 64, 64),
      makeCamera(Projection::kPerspective, {25, 12, 28}, {30, 8, 30}, {0, 0, 1}, 70, 64, 64)};
  for (const ScalarType type : {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16}) {
    const Brick integers = makeVolume(grid, type, speckAndBlob);
    const Brick floats = makeVolume(grid, ScalarType::kFloat32, speckAndBlob);
    for (const TransferFunctionSpec& tf : {speckOnly(), blobOnly()})
      for (const bool preintegrated : {false, true})
        for (const bool shaded : {false, true})
          for (const double step : {0.5, 1.0}) {
            RenderOptions options = makeOptions(step, preintegrated, shaded);
            BrickRenderer withCells(integers), without(floats);
            withCells.classify(tf, options, &pool());
            without.classify(tf, options, &pool());
            for (const Camera& camera : cameras) {
              RenderStats a, b;
              const Image x = withCells.render(camera, options, pool(), &a).toFullFrame();
              const Image y = without.render(camera, options, pool(), &b).toFullFrame();
              CAPTURE(int(type), preintegrated, shaded, step);
              CHECK(a.samples == b.samples);
              int differing = 0;
              for (std::size_t n = 0; n < x.pixels().size(); ++n) {
                const Rgba& s = x.pixels()[n];
                const Rgba& t = y.pixels()[n];
                differing += s.r != t.r || s.g != t.g || s.b != t.b || s.a != t.a;
              }
              CHECK(differing == 0);
            }
          }
  }
}

}  // namespace
}  // namespace pvr::core
