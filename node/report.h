// The time breakdown of a distributed frame, after a header naming the
// volume, the ranks and their hosts, printed like Table 1 of the
// binary-swap paper with every phase of a batch run named (start, read,
// prep, dist, rend, comp, comm, send, write: max, mean, min over ranks), so
// that the phases add up to the time from process start to the written
// image; with the bytes and messages of compositing, the voxel bytes and
// the peak resident memory per rank; and the same per rank as CSV.
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

// What rank 0 measures after the frame: writing the image, and its process
// age when the image is written (the batch run's wall time but for
// mpirun's launch before exec and MPI's finalize after).
struct OutputTimes {
  double write = 0;
  double wall = 0;
};

// `hosts`: every rank's host name, in rank order (hosts.h).
std::string formatReport(const FrameResult& result, const FrameOptions& options,
                         const std::vector<std::string>& hosts, const OutputTimes& output);
// One row per rank (write and wall on rank 0's row, 0 on the others);
// throws pvr::Error naming the path if it cannot write.
void writeStatsCsv(const std::string& path, const FrameResult& result, const FrameOptions& options,
                   const OutputTimes& output);

}  // namespace pvr::node
