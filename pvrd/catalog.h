// The data catalog: datasets are named relative to --data-dir, never pathed.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::daemon {

// True for a file name a volume loader reads (.json sidecar, .nhdr, .nrrd,
// .nii, .nii.gz).
bool isVolumeFileName(const std::string& name);

// Every volume file in `dataDir` and one level of subdirectories, as names
// relative to it, sorted. Entries whose real path leaves the directory are
// left out.
std::vector<std::string> listDatasets(const std::string& dataDir);

// The real path of dataset `name` inside `dataDir`, or the error to send:
// kBadArgument for an absolute name or one with a ".." component,
// kDatasetNotFound when it does not exist, is no volume file, or resolves
// (symlinks included) outside the directory.
std::variant<std::string, proto::ProtocolError> resolveDataset(const std::string& dataDir, const std::string& name);

}  // namespace pvr::daemon
