#include "catalog_listing.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

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

std::string datasetStem(const std::string& name) {
  // Step: the longest registered extension that ends the name.
  std::size_t cut = 0;
  for (const core::VolumeFormat& f : core::volumeFormats()) {
    std::istringstream words(f.extensions);
    for (std::string ext; words >> ext;)
      if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0)
        cut = std::max(cut, ext.size());
  }
  std::string stem = name.substr(0, name.size() - cut);
  // Step: "ct/ct" is "ct".
  const std::size_t slash = stem.find('/');
  if (slash != std::string::npos && stem.compare(0, slash, stem, slash + 1, std::string::npos) == 0)
    stem.resize(slash);
  return stem;
}

namespace {

// The registry's name for a file, and its place in the registry's order.
std::pair<std::string, std::size_t> formatOf(const std::string& name) {
  const auto& formats = core::volumeFormats();
  for (std::size_t i = 0; i < formats.size(); ++i)
    if (formats[i].matches(name)) return {formats[i].name, i};
  return {"", formats.size()};
}

}  // namespace

CatalogListing listCatalog(const std::string& dataDir) {
  std::error_code ec;
  if (!fs::is_directory(dataDir, ec)) throw Error(ErrorCode::kIo, dataDir + ": no such directory");
  const core::DataDirectory within(dataDir);

  // Open every candidate (headers only), refusing files they name outside
  // the directory; remember what the series read. A file that does not
  // open is kept with its reason as a note.
  CatalogListing listing;
  struct Opened {
    CatalogDataset dataset;
    std::string real;
    std::size_t order;  // the format's place in the registry
  };
  std::vector<Opened> opened;
  std::set<std::string> stepFiles;
  for (const Candidate& c : candidates(within)) {
    if (c.name.find_first_of("\t\n") != std::string::npos) {
      listing.leftOut.push_back(c.name + ": the name holds a tab or line break, which a catalog line cannot");
      continue;
    }
    const auto [format, order] = formatOf(c.name);
    Opened o{{datasetStem(c.name), 1, c.name, format, {0, 0, 0}, "", ""}, c.real, order};
    try {
      const auto source = core::openVolumeFile(c.real, &within);
      for (const std::string& file : core::seriesFiles(*source)) stepFiles.insert(realPath(file));
      const core::IVec3 d = source->grid().dims;
      o.dataset.steps = source->steps();
      o.dataset.dims = {std::uint32_t(d.x), std::uint32_t(d.y), std::uint32_t(d.z)};
      o.dataset.dtype = std::string(core::scalarName(source->type()));
      // Loadable, with a warning where it renders otherwise than the file
      // says (issue 14, point 5: an oblique scan on the nearest axes).
      o.dataset.note = source->caveat();
    } catch (const Error& e) {
      // A volume of a kind not rendered (float64, 4-D, ...) is listed with
      // the reason; a file that is no volume at all is left out.
      if (e.code() != ErrorCode::kUnsupported) {
        listing.leftOut.push_back(c.name + ": " + e.what());
        continue;
      }
      // The reason without the path the server sees: the file is named already.
      std::string why = e.what();
      if (const std::size_t at = why.find(c.real + ": "); at == 0) why = why.substr(c.real.size() + 2);
      o.dataset.note = "cannot be loaded: " + why;
    }
    for (char& ch : o.dataset.note)
      if (ch == '\t' || ch == '\n') ch = ' ';
    opened.push_back(std::move(o));
  }

  // One dataset per stem: loadable before not, then the registry's order.
  std::map<std::string, const Opened*> best;
  for (const Opened& o : opened) {
    if (stepFiles.count(o.real)) continue;
    const Opened*& b = best[o.dataset.name];
    // dtype is empty exactly when the file cannot be loaded (a note may be a warning).
    const auto rank = [](const Opened* x) { return std::make_tuple(x->dataset.dtype.empty(), x->order, x->dataset.file); };
    if (!b) b = &o;
    else {
      const Opened* other = rank(&o) < rank(b) ? b : &o;
      if (rank(&o) < rank(b)) b = &o;
      listing.leftOut.push_back(other->dataset.file + ": listed as '" + other->dataset.name + "' from " +
                                (b == &o ? o.dataset.file : b->dataset.file) + " (its file name still opens it)");
    }
  }
  for (const auto& [name, o] : best) listing.datasets.push_back(o->dataset);  // std::map: sorted by name
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
    for (const CatalogDataset& d : listing.datasets)
      std::fprintf(out, "%d\t%s\t%s\t%s\t%u\t%u\t%u\t%s\t%s\n", d.steps, d.name.c_str(), d.file.c_str(),
                   d.format.c_str(), d.dims[0], d.dims[1], d.dims[2], d.dtype.c_str(), d.note.c_str());
    return std::fflush(out) == 0 ? 0 : 1;
  } catch (const Error& e) {
    std::fprintf(err, "pvr-node --catalog: %s\n", e.what());
    return 1;
  }
}

}  // namespace pvr::node
