#include "data_summary.h"

#include <limits>

#include "error.h"
#include "value_histogram.h"

namespace pvr::node {

std::optional<DataSummary> summarizeData(comm::Communicator& comm, const core::Brick* brick, bool counts) {
  const bool mine = brick && counts && brick->fineHistogram();
  return summarizeData(comm, brick, mine ? brick->fineHistogram().get() : nullptr);
}

std::optional<DataSummary> summarizeData(comm::Communicator& comm, const core::Brick* brick,
                                         const core::FineHistogram* counted) {
  // Step: the range, as the max of (-min, max) over the ranks that hold a brick.
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  std::vector<double> range{kNone, kNone};
  if (brick) range = {-brick->valueRange().min, brick->valueRange().max};
  comm.allReduceMax(range);
  const bool any = range[1] > kNone;

  // Step: each counting brick's fine counts in the agreed bins, summed.
  // Every rank takes part, data or not, so nobody waits alone.
  DataSummary summary;
  summary.range = {-range[0], range[1]};
  summary.histogram.assign(std::size_t(core::kHistogramBins), 0);
  if (any && counted) summary.histogram = core::binHistogram(*counted, summary.range[0], summary.range[1]);
  comm.allReduceSum(summary.histogram);
  if (!any) return std::nullopt;
  return summary;
}

}  // namespace pvr::node
