// The catalog lists each volume once under its stem (catalog_listing.h):
// head.json and head.nhdr over one raw file are one dataset "head"; a
// volume of a type not rendered is listed with a note; a file that is no
// volume is left out; an oblique scan is listed, loadable, with a warning.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "catalog_listing.h"

using namespace pvr::node;
namespace fs = std::filesystem;

TEST_CASE("a dataset's stem drops the format's extension and a folder's repeated name") {
  CHECK(datasetStem("head.json") == "head");
  CHECK(datasetStem("head.nhdr") == "head");
  CHECK(datasetStem("brain.nii.gz") == "brain");
  CHECK(datasetStem("run.series.json") == "run");
  CHECK(datasetStem("ct_head/ct_head.json") == "ct_head");
  CHECK(datasetStem("scans/knee.nrrd") == "scans/knee");
}

TEST_CASE("the catalog lists head.json and head.nhdr once as head, an unsupported type with a note") {
  const fs::path dir = fs::temp_directory_path() / ("pvr_catalog_stems_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "ct");
  {
    std::ofstream raw(dir / "ct" / "ct.raw", std::ios::binary);
    const std::string zeros(4 * 3 * 2 * 2, '\0');
    raw << zeros;
  }
  std::ofstream(dir / "ct" / "ct.json") << R"({"dims": [4, 3, 2], "dtype": "int16", "spacing": [1, 1, 2]})";
  std::ofstream(dir / "ct" / "ct.nhdr") << "NRRD0004\ntype: short\ndimension: 3\nsizes: 4 3 2\nencoding: raw\n"
                                           "endian: little\ndata file: ct.raw\n\n";
  std::ofstream(dir / "wide.nhdr") << "NRRD0004\ntype: double\ndimension: 3\nsizes: 4 3 2\nencoding: raw\n"
                                      "endian: little\ndata file: ct/ct.raw\n\n";
  std::ofstream(dir / "notes.json") << "not a volume";

  const CatalogListing listing = listCatalog(dir.string());
  REQUIRE(listing.datasets.size() == 2);
  const CatalogDataset& ct = listing.datasets[0];
  CHECK(ct.name == "ct");
  CHECK(ct.file == "ct/ct.json");  // raw+json comes before nrrd in the registry
  CHECK(ct.format == "raw+json");
  CHECK(ct.dims == std::array<std::uint32_t, 3>{4, 3, 2});
  CHECK(ct.dtype == "int16");
  CHECK(ct.note.empty());
  const CatalogDataset& wide = listing.datasets[1];
  CHECK(wide.name == "wide");
  CHECK(wide.format == "nrrd");
  CHECK(wide.dtype.empty());
  CHECK_THAT(wide.note, Catch::StartsWith("cannot be loaded: ") && Catch::Contains("double"));
  // The other file of the stem and the non-volume are noted, not listed.
  REQUIRE(listing.leftOut.size() == 2);
  CHECK_THAT(listing.leftOut[0], Catch::StartsWith("ct/ct.nhdr: listed as 'ct' from ct/ct.json"));
  CHECK_THAT(listing.leftOut[1], Catch::StartsWith("notes.json: "));
  fs::remove_all(dir);
}

namespace {

// An empty scratch directory holding v.raw of `bytes` zero bytes.
fs::path dirWithZeros(const std::string& name, std::size_t bytes) {
  const fs::path dir = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "v.raw", std::ios::binary) << std::string(bytes, '\0');
  return dir;
}

}  // namespace

// Issue 14, point 5: the renderer's grids are axis-aligned, so a scan whose
// index axes are rotated against its space is rendered on the nearest
// signed axes; the catalog says so in the note of a loadable dataset (dims
// and dtype filled in), while a flip alone is rendered exactly and gets none.
TEST_CASE("the catalog notes an oblique NRRD as rendered axis-aligned, and a flipped one not at all") {
  const fs::path dir = dirWithZeros("pvr_catalog_oblique", 4 * 3 * 2);
  const std::string common = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 2\nencoding: raw\ndata file: v.raw\n"
                             "space: right-anterior-superior\nspace origin: (0,0,0)\n";
  // Index axes 0 and 1 turned 30 degrees about z.
  std::ofstream(dir / "tilted.nhdr") << common
                                     << "space directions: (0.8660254,0.5,0) (-0.5,0.8660254,0) (0,0,2)\n\n";
  std::ofstream(dir / "flipped.nhdr") << common << "space directions: (-1,0,0) (0,1,0) (0,0,2)\n\n";

  const CatalogListing listing = listCatalog(dir.string());
  REQUIRE(listing.datasets.size() == 2);
  const CatalogDataset& flipped = listing.datasets[0];
  CHECK(flipped.name == "flipped");
  CHECK(flipped.note.empty());
  const CatalogDataset& tilted = listing.datasets[1];
  CHECK(tilted.name == "tilted");
  CHECK(tilted.dims == std::array<std::uint32_t, 3>{4, 3, 2});
  CHECK(tilted.dtype == "uint8");
  CHECK(tilted.note == "oblique orientation (30 degrees off the axes): rendered axis-aligned on the nearest signed axes");
  fs::remove_all(dir);
}

TEST_CASE("of one stem, an oblique file that loads is listed before one that cannot, note and all") {
  const fs::path dir = dirWithZeros("pvr_catalog_oblique_rank", 4 * 3 * 2 * 8);
  // raw+json comes first in the registry, but this one is float64.
  std::ofstream(dir / "v.json") << R"({"dims": [4, 3, 2], "dtype": "float64"})";
  std::ofstream(dir / "v.nhdr") << "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 2\nencoding: raw\ndata file: v.raw\n"
                                   "byte skip: -1\nspace directions: (0.8660254,0.5,0) (-0.5,0.8660254,0) (0,0,2)\n"
                                   "space origin: (0,0,0)\n\n";
  const CatalogListing listing = listCatalog(dir.string());
  REQUIRE(listing.datasets.size() == 1);
  CHECK(listing.datasets[0].file == "v.nhdr");
  CHECK_THAT(listing.datasets[0].note, Catch::StartsWith("oblique orientation (30 degrees"));
  fs::remove_all(dir);
}
