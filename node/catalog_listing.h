// pvr-node --catalog DIR: the datasets of a data directory, for pvrd's
// catalog (pvrd links no renderer, so it runs this program; docs/pvrd.md).
// The renderer's format registry decides what a dataset is; a time series
// is listed once with its number of steps, and the files it reads its steps
// from are not listed at all.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

namespace pvr::node {

struct CatalogDataset {
  std::string name;  // relative to the data directory
  int steps = 1;
  bool operator==(const CatalogDataset&) const = default;
};

struct CatalogListing {
  std::vector<CatalogDataset> datasets;  // sorted by name
  std::vector<std::string> leftOut;      // "NAME: why" for files that did not open
};

// The datasets in `dataDir` and one level of its subdirectories (names not
// starting with '.'): every file a registered format opens as a dataset of
// its own, that resolves (symlinks included) inside the directory, that
// opens, and that no series there reads as a step. Throws pvr::Error(kIo)
// when `dataDir` is no directory.
CatalogListing listCatalog(const std::string& dataDir);

// Prints listCatalog(dataDir) to `out` as one "STEPS<TAB>NAME" line per
// dataset and the files left out to `err` as "pvr-node --catalog: left out
// NAME: why"; returns the exit status (0, or 1 with the error on `err`).
int printCatalog(const std::string& dataDir, std::FILE* out, std::FILE* err);

}  // namespace pvr::node
