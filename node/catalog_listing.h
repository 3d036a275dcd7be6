// pvr-node --catalog DIR: the datasets of a data directory, for pvrd's
// catalog (pvrd links no renderer, so it runs this program; docs/pvrd.md).
// The renderer's format registry decides what a dataset is; a time series
// is listed once with its number of steps, and the files it reads its steps
// from are not listed at all.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace pvr::node {

// One volume, listed once under its stem: "head" for head.json and
// head.nhdr alike (datasetStem), "ct/ct" shortened to "ct".
struct CatalogDataset {
  std::string name;    // the stem, relative to the data directory
  int steps = 1;
  std::string file;    // the file it opens from, relative to the data directory
  std::string format;  // the registry's name: "raw+json", "nrrd", "nifti", "series"
  std::array<std::uint32_t, 3> dims{0, 0, 0};  // 0 0 0 when it cannot be loaded
  std::string dtype;   // "int16", ...; empty when it cannot be loaded
  // Why it cannot be loaded ("cannot be loaded: float64 ..."), or, when it
  // can, what its rendering does not show as the file says (an oblique
  // orientation, VolumeSource::caveat); empty when neither.
  std::string note;
  bool operator==(const CatalogDataset&) const = default;
};

struct CatalogListing {
  std::vector<CatalogDataset> datasets;  // sorted by name, names unique
  std::vector<std::string> leftOut;      // "NAME: why" for files of a stem listed from another file
};

// The name a dataset file is listed under: its path without the format's
// extension (the longest registered one that matches), and a file named
// like its folder ("ct/ct.json") as the folder ("ct").
std::string datasetStem(const std::string& name);

// The datasets in `dataDir` and one level of its subdirectories (names not
// starting with '.'): every file a registered format takes as a dataset of
// its own, that resolves (symlinks included) inside the directory and that
// no series there reads as a step, once per stem: of the files sharing a
// stem, the first that opens in the registry's order (series, raw+json,
// nrrd, nifti) is listed, or, when none opens, the first with the reason
// as its note. Throws pvr::Error(kIo) when `dataDir` is no directory.
CatalogListing listCatalog(const std::string& dataDir);

// Prints listCatalog(dataDir) to `out` as one
// "STEPS<TAB>NAME<TAB>FILE<TAB>FORMAT<TAB>X<TAB>Y<TAB>Z<TAB>DTYPE<TAB>NOTE" line per
// dataset (pvrd/catalog.cpp reads it) and the files left out to `err` as "pvr-node --catalog: left out
// NAME: why"; returns the exit status (0, or 1 with the error on `err`).
int printCatalog(const std::string& dataDir, std::FILE* out, std::FILE* err);

}  // namespace pvr::node
