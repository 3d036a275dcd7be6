// The dataset's range and 256-bin histogram agreed over the ranks
// (data_summary.h): bricks of a k-d tree with ghost layers, each counting
// its owned voxels in the preprocessing pass, must give what one serial
// loop over every voxel of the volume gives, for any number of ranks.
#include <catch2/catch.hpp>

#include <cmath>
#include <mutex>

#include "brick.h"
#include "data_summary.h"
#include "decompose/kd_tree.h"
#include "distribute.h"
#include "in_process_communicator.h"
#include "value_histogram.h"

using namespace pvr;

namespace {

// A whole volume of type T, dims 23x17x11 (odd, so bricks are uneven),
// with values spread over a wide range and a few repeats.
template <typename T>
core::Brick makeVolume(core::ScalarType type, double scale, double offset) {
  core::GridGeometry grid;
  grid.dims = {23, 17, 11};
  core::Brick b(grid, type, grid.allNodes(), grid.allNodes());
  T* v = b.as<T>();
  for (std::int64_t z = 0; z < 11; ++z)
    for (std::int64_t y = 0; y < 17; ++y)
      for (std::int64_t x = 0; x < 23; ++x)
        v[b.linearIndex({x, y, z})] = T(offset + scale * std::sin(0.37 * double(x) + 0.91 * double(y) * double(z % 3 + 1)));
  b.updateValueRange();
  return b;
}

// The serial count: every voxel once, binned from its value as the
// histogram's rule says (a float by its fine key's value).
std::vector<std::uint64_t> serialHistogram(const core::Brick& whole, double min, double max) {
  std::vector<std::uint64_t> bins(core::kHistogramBins, 0);
  const core::NodeBox all = whole.grid().allNodes();
  for (std::int64_t z = all.lo.z; z <= all.hi.z; ++z)
    for (std::int64_t y = all.lo.y; y <= all.hi.y; ++y)
      for (std::int64_t x = all.lo.x; x <= all.hi.x; ++x) {
        double v = whole.valueAt({x, y, z});
        if (whole.type() == core::ScalarType::kFloat32)
          v = core::fineKeyValue(whole.type(), core::fineKey(float(v)));
        const double at = std::floor((v - min) / (max - min) * core::kHistogramBins);
        bins[std::size_t(std::clamp(at, 0.0, double(core::kHistogramBins - 1)))] += 1;
      }
  return bins;
}

void checkEveryRankCount(const core::Brick& whole) {
  const std::vector<std::uint64_t> serial =
      serialHistogram(whole, whole.valueRange().min, whole.valueRange().max);
  std::uint64_t total = 0;
  for (std::uint64_t n : serial) total += n;
  REQUIRE(total == std::uint64_t(whole.grid().allNodes().nodeCount()));
  for (int ranks : {1, 2, 3}) {
    CAPTURE(ranks);
    const core::KdTree tree = core::KdTree::build(whole.grid(), ranks, node::splitAxisRule(node::Decomposition::kKd));
    std::mutex m;
    std::vector<node::DataSummary> got;
    comm::runInProcess(ranks, [&](comm::Communicator& comm) {
      // Ghost layers of 2: they must not be counted.
      const core::Brick brick = core::cropBrick(whole, tree.ownedBox(comm.rank()), 2);
      const auto s = node::summarizeData(comm, &brick, true);
      const std::lock_guard<std::mutex> lock(m);
      REQUIRE(s);
      got.push_back(*s);
    });
    REQUIRE(got.size() == std::size_t(ranks));
    for (const node::DataSummary& s : got) {
      CHECK(s.range[0] == whole.valueRange().min);
      CHECK(s.range[1] == whole.valueRange().max);
      CHECK(s.histogram == serial);
    }
  }
}

}  // namespace

TEST_CASE("the histogram over 1, 2 and 3 ranks equals a serial count of the volume") {
  SECTION("int16 over a Hounsfield-like range") { checkEveryRankCount(makeVolume<std::int16_t>(core::ScalarType::kInt16, 1500, 500)); }
  SECTION("uint8") { checkEveryRankCount(makeVolume<std::uint8_t>(core::ScalarType::kUInt8, 120, 128)); }
  SECTION("uint16") { checkEveryRankCount(makeVolume<std::uint16_t>(core::ScalarType::kUInt16, 30000, 32000)); }
  SECTION("float32, signed") { checkEveryRankCount(makeVolume<float>(core::ScalarType::kFloat32, 0.66, 0)); }
}

TEST_CASE("a rank without a brick, or whose brick does not count, adds nothing to the histogram") {
  const core::Brick whole = makeVolume<std::int16_t>(core::ScalarType::kInt16, 1000, 0);
  const auto serial = serialHistogram(whole, whole.valueRange().min, whole.valueRange().max);
  // Rank 0 holds the whole volume and counts; rank 1 holds it again (a
  // second render cluster) and does not count; rank 2 holds nothing.
  std::mutex m;
  std::vector<node::DataSummary> got;
  comm::runInProcess(3, [&](comm::Communicator& comm) {
    const core::Brick* brick = comm.rank() < 2 ? &whole : nullptr;
    const auto s = node::summarizeData(comm, brick, comm.rank() == 0);
    const std::lock_guard<std::mutex> lock(m);
    REQUIRE(s);
    got.push_back(*s);
  });
  for (const node::DataSummary& s : got) CHECK(s.histogram == serial);
}

TEST_CASE("no rank with data: no summary, on every rank") {
  comm::runInProcess(2, [](comm::Communicator& comm) { CHECK_FALSE(node::summarizeData(comm, nullptr, true)); });
}
