// What a loaded dataset's values look like, agreed by every rank: the
// finite value range and the 256-bin histogram (value_histogram.h) that
// `list status`, `:s info` and the GUI's transfer-function editor show and
// the default transfer function is a ramp over.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "brick.h"
#include "communicator.h"

namespace pvr::node {

struct DataSummary {
  std::array<double, 2> range{0, 0};   // min, max of the finite values
  std::vector<std::uint64_t> histogram;  // core::kHistogramBins bins over range
};

// Collective over `comm`: every rank passes its brick (null where it holds
// none) and whether that brick counts towards the histogram: the bricks
// that count must cover the volume once (one render cluster's ranks), the
// range takes every brick. Each counting brick bins its fine counts over
// the agreed range and the bins are summed: the result equals a serial
// count of the whole volume. Nullopt on every rank when no rank holds a brick.
std::optional<DataSummary> summarizeData(comm::Communicator& comm, const core::Brick* brick, bool counts);
// The same with this rank's fine counts given apart from the brick (null:
// it counts nothing), for bricks whose own counts overlap (scene_bricks.h).
std::optional<DataSummary> summarizeData(comm::Communicator& comm, const core::Brick* brick,
                                         const core::FineHistogram* counted);

}  // namespace pvr::node
