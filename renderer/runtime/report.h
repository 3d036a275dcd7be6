// The time breakdown of a distributed frame, printed like Table 1 of the
// binary-swap paper (dist, rend, comp, comm, send: max over ranks), with
// the bytes and messages of compositing and the voxel bytes per rank; and
// the same per rank as CSV.
#pragma once

#include <string>

#include "frame.h"

namespace pvr::runtime {

std::string formatReport(const FrameResult& result, const FrameOptions& options);
// One row per rank; throws pvr::Error naming the path if it cannot write.
void writeStatsCsv(const std::string& path, const FrameResult& result, const FrameOptions& options);

}  // namespace pvr::runtime
