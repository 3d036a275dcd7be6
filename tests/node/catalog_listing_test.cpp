// The catalog lists each volume once under its stem (catalog_listing.h):
// head.json and head.nhdr over one raw file are one dataset "head"; a
// volume of a type not rendered is listed with a note; a file that is no
// volume is left out.
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
