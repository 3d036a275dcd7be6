// Naming a dataset the way a user types it: by its catalog stem or its
// file name, and, for a name that is neither, the catalog's closest names
// (Levenshtein distance) to suggest.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::daemon {

// Insertions, deletions and substitutions that turn `a` into `b`.
std::size_t editDistance(const std::string& a, const std::string& b);

// Up to `most` of `names` nearest to `name`, nearest first (ties in the
// given order), only those that look like what was typed
// (dataset_names.cpp: close as a whole, a start or end of the name, or a
// mistyped start).
std::vector<std::string> closestNames(const std::string& name, const std::vector<std::string>& names,
                                      std::size_t most = 3);

// The file (relative to the data directory) of the catalog entry named
// `name`, or nullopt when none is.
std::optional<std::string> fileOfStem(const std::vector<proto::CatalogEntry>& catalog, const std::string& name);

// "no dataset 'NAME' in the catalog" plus "; did you mean 'a' or 'b'?" when
// the catalog holds close names.
std::string unknownDatasetText(const std::string& name, const std::vector<proto::CatalogEntry>& catalog);

}  // namespace pvr::daemon
