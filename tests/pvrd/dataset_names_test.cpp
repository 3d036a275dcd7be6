// Naming datasets (dataset_names.h): edit distance, the closest catalog
// names suggested for a name that is no dataset, and stems to files.
#include <catch2/catch.hpp>

#include "dataset_names.h"

using namespace pvr::daemon;
using pvr::proto::CatalogEntry;

TEST_CASE("edit distance counts insertions, deletions and substitutions") {
  CHECK(editDistance("", "") == 0);
  CHECK(editDistance("head", "head") == 0);
  CHECK(editDistance("hed", "head") == 1);
  CHECK(editDistance("haed", "head") == 2);
  CHECK(editDistance("kitten", "sitting") == 3);
  CHECK(editDistance("", "abc") == 3);
}

TEST_CASE("the closest names come nearest first, only when they look alike") {
  const std::vector<std::string> names{"ct_head_cranium", "mri_head_volpack", "orbital_oxirane_homo", "head", "heart"};
  CHECK(closestNames("hed", names) == std::vector<std::string>{"head", "heart"});
  CHECK(closestNames("ct_head", names).front() == "ct_head_cranium");  // a prefix is one edit away
  CHECK(closestNames("orbital_oxiran_homo", names) == std::vector<std::string>{"orbital_oxirane_homo"});
  CHECK(closestNames("ct_haed", names).front() == "ct_head_cranium");  // a mistyped start
  CHECK(closestNames("zzzzzzzzzz", names).empty());
  CHECK(closestNames("hea", names, 1).size() == 1);
}

TEST_CASE("an unknown dataset's error suggests the closest stems, a stem names its file") {
  const std::vector<CatalogEntry> catalog{{"ct_head_cranium", 1, "ct_head_cranium/ct_head_cranium.json", "raw+json", {256, 256, 108}, "int16", ""},
                                          {"mri_head_volpack", 1, "mri_head_volpack/mri_head_volpack.json", "raw+json", {128, 128, 84}, "uint8", ""}};
  CHECK(fileOfStem(catalog, "ct_head_cranium") == "ct_head_cranium/ct_head_cranium.json");
  CHECK_FALSE(fileOfStem(catalog, "ct_head"));
  CHECK(unknownDatasetText("ct_haed_cranium", catalog) ==
        "no dataset 'ct_haed_cranium' in the catalog; did you mean 'ct_head_cranium'?");
  CHECK(unknownDatasetText("qqqqqqqqqqqqqqqqqqqqqqqqq", catalog) == "no dataset 'qqqqqqqqqqqqqqqqqqqqqqqqq' in the catalog");
}
