// The time breakdown of a distributed frame, after a header naming the
// volume, the ranks and their hosts, printed like Table 1 of the
// binary-swap paper (dist, rend, comp, comm, send: max over ranks), with
// the bytes and messages of compositing and the voxel bytes per rank; and
// the same per rank as CSV.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "frame.h"

namespace pvr::node {

// Compositing traffic of a frame summed over its ranks.
struct TrafficTotals {
  std::uint64_t messages = 0, maxMessagesPerRank = 0;
  std::uint64_t rawBytes = 0, encodedBytes = 0, pixels = 0, gatherBytes = 0;
};
TrafficTotals sumTraffic(const std::vector<RankReport>& ranks);

// `hosts`: every rank's host name, in rank order (hosts.h).
std::string formatReport(const FrameResult& result, const FrameOptions& options,
                         const std::vector<std::string>& hosts);
// One row per rank; throws pvr::Error naming the path if it cannot write.
void writeStatsCsv(const std::string& path, const FrameResult& result, const FrameOptions& options);

}  // namespace pvr::node
