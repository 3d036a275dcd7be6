#include "catalog_listing.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <filesystem>
#include <set>

#include "error.h"
#include "io/data_directory.h"
#include "io/series.h"
#include "scene_patch.h"

namespace pvr::node {

namespace {

namespace fs = std::filesystem;

std::string realPath(const std::string& path) {
  char buf[PATH_MAX];
  return ::realpath(path.c_str(), buf) ? std::string(buf) : std::string();
}

// A file the catalog considers: its name relative to the directory and its real path.
struct Candidate {
  std::string name;
  std::string real;
};

// Dataset-named regular files in the directory and one level below, inside
// it; not the server's presets (kPresetFolder).
std::vector<Candidate> candidates(const core::DataDirectory& dir) {
  std::vector<Candidate> out;
  std::error_code ec;
  const auto consider = [&](const fs::path& file, const std::string& name) {
    if (!core::isDatasetFileName(name)) return;
    if (auto real = dir.confine(file.string())) out.push_back({name, *real});
  };
  for (const auto& entry : fs::directory_iterator(dir.path(), ec)) {
    const std::string top = entry.path().filename().string();
    if (top.empty() || top[0] == '.' || top == kPresetFolder) continue;
    if (!entry.is_directory(ec)) {
      consider(entry.path(), top);
      continue;
    }
    for (const auto& sub : fs::directory_iterator(entry.path(), ec)) {
      const std::string leaf = sub.path().filename().string();
      if (!leaf.empty() && leaf[0] != '.') consider(sub.path(), top + "/" + leaf);
    }
  }
  return out;
}

}  // namespace

CatalogListing listCatalog(const std::string& dataDir) {
  std::error_code ec;
  if (!fs::is_directory(dataDir, ec)) throw Error(ErrorCode::kIo, dataDir + ": no such directory");
  const core::DataDirectory within(dataDir);

  // Open every candidate (headers only), refusing files they name outside
  // the directory; remember what the series read.
  CatalogListing listing;
  std::vector<CatalogDataset> opened;
  std::vector<std::string> openedReal;
  std::set<std::string> stepFiles;
  for (const Candidate& c : candidates(within)) {
    if (c.name.find_first_of("\t\n") != std::string::npos) {
      listing.leftOut.push_back(c.name + ": the name holds a tab or line break, which a catalog line cannot");
      continue;
    }
    try {
      const auto source = core::openVolumeFile(c.real, &within);
      for (const std::string& file : core::seriesFiles(*source)) stepFiles.insert(realPath(file));
      opened.push_back({c.name, source->steps()});
      openedReal.push_back(c.real);
    } catch (const Error& e) {
      listing.leftOut.push_back(c.name + ": " + e.what());
    }
  }
  for (std::size_t i = 0; i < opened.size(); ++i)
    if (!stepFiles.count(openedReal[i])) listing.datasets.push_back(opened[i]);
  std::sort(listing.datasets.begin(), listing.datasets.end(),
            [](const CatalogDataset& a, const CatalogDataset& b) { return a.name < b.name; });
  std::sort(listing.leftOut.begin(), listing.leftOut.end());
  return listing;
}

int printCatalog(const std::string& dataDir, std::FILE* out, std::FILE* err) {
  try {
    const CatalogListing listing = listCatalog(dataDir);
    // The notes first: pvrd reads both streams through one pipe, and a
    // buffered stdout flushed between them could split a dataset line.
    for (const std::string& why : listing.leftOut) std::fprintf(err, "pvr-node --catalog: left out %s\n", why.c_str());
    std::fflush(err);
    for (const CatalogDataset& d : listing.datasets) std::fprintf(out, "%d\t%s\n", d.steps, d.name.c_str());
    return std::fflush(out) == 0 ? 0 : 1;
  } catch (const Error& e) {
    std::fprintf(err, "pvr-node --catalog: %s\n", e.what());
    return 1;
  }
}

}  // namespace pvr::node
