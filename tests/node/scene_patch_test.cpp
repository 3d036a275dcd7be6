// The master's scene patches (scene_patch.h), serially: a patch is checked
// as a whole, with or without a dataset, and a refused one changes nothing.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "scene_patch.h"

using namespace pvr;
using node::SessionScene;

namespace {

namespace fs = std::filesystem;

// A data directory holding one (empty) dataset file, as a real path;
// removed when the test program ends.
struct ScratchDataDir {
  fs::path path;
  ScratchDataDir() {
    const fs::path d = fs::temp_directory_path() / ("pvr-scene-patch-" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::ofstream(d / "ct.json") << "{}";
    path = fs::canonical(d);
  }
  ~ScratchDataDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

std::string dataDir() {
  static const ScratchDataDir dir;
  return dir.path.string();
}

SessionScene accepted(const SessionScene& current, const proto::SetScene& request) {
  auto result = node::patchScene(current, request, dataDir());
  if (const auto* e = std::get_if<proto::ProtocolError>(&result)) FAIL("refused: " << e->text);
  return std::get<SessionScene>(result);
}

proto::ProtocolError refused(const SessionScene& current, const proto::SetScene& request) {
  auto result = node::patchScene(current, request, dataDir());
  REQUIRE(std::holds_alternative<proto::ProtocolError>(result));
  return std::get<proto::ProtocolError>(result);
}

}  // namespace

TEST_CASE("a bad key is refused before any dataset, naming the key, and leaves the scene as it was") {
  const SessionScene before = accepted({}, {"", R"({"image": {"width": 32}, "runtime": {"threads": 2}})"});
  const auto e = refused(before, {"", R"({"image": {"height": 16}, "shading": {"enabeld": true}})"});
  CHECK(e.code == proto::ErrorCode::kBadArgument);
  CHECK_THAT(e.text, Catch::Contains("shading.enabeld"));
  // The next dataset load sees only what was accepted.
  const SessionScene loaded = accepted(before, {"ct.json", ""});
  CHECK(loaded.doc["image"] == nlohmann::json{{"width", 32}});
  CHECK(loaded.doc["volume"]["file"] == dataDir() + "/ct.json");
  CHECK(loaded.settings.threads == 2);
}

TEST_CASE("a refused runtime section leaves the scene and the settings as they were") {
  const SessionScene before = accepted({}, {"", R"({"runtime": {"decomposition": "balanced"}})"});
  const auto e = refused(before, {"", R"({"image": {"width": 40}, "runtime": {"strategy": "nope"}})"});
  CHECK_THAT(e.text, Catch::Contains("runtime.strategy") && Catch::Contains("binary-swap"));
  const SessionScene after = accepted(before, {"", "{}"});
  CHECK(after.doc == nlohmann::json::object());
  CHECK(after.settings.decomposition == node::Decomposition::kBalanced);
  CHECK(after.settings.strategy == "binary-swap");
}

TEST_CASE("an image that does not fit a frame in the session's pixel format is refused at set time") {
  const auto huge = refused({}, {"", R"({"image": {"width": 16384, "height": 16384}})"});
  CHECK(huge.code == proto::ErrorCode::kLimitExceeded);
  CHECK_THAT(huge.text, Catch::Contains(std::to_string(proto::Limits{}.maxImagePixels)));
  // 4096 x 4096 fits a frame as RGB8, not as RGBA8 (the default).
  const char* square = R"({"image": {"width": 4096, "height": 4096}})";
  const auto rgba = refused({}, {"", square});
  CHECK(rgba.code == proto::ErrorCode::kLimitExceeded);
  CHECK_THAT(rgba.text, Catch::Contains(std::to_string(proto::kMaxFrameBytes)));
  const SessionScene rgb = accepted({}, {"", R"({"runtime": {"pixels": "rgb8"}})"});
  const SessionScene big = accepted(rgb, {"", square});
  // Going back to RGBA8 would make the kept image too big: refused too.
  refused(big, {"", R"({"runtime": {"pixels": "rgba8"}})"});
}

TEST_CASE("datasets resolve inside the data directory, volume files in the JSON are refused") {
  CHECK(refused({}, {"../etc/passwd", ""}).code == proto::ErrorCode::kDatasetNotFound);
  CHECK(refused({}, {"missing.json", ""}).code == proto::ErrorCode::kDatasetNotFound);
  CHECK_THAT(refused({}, {"", R"({"volume": {"file": "/etc/passwd"}})"}).text, Catch::Contains("volume.file"));
  CHECK(refused({}, {"", "[1, 2]"}).code == proto::ErrorCode::kBadArgument);
  const SessionScene loaded = accepted({}, {"ct.json", ""});
  CHECK_THAT(refused(loaded, {"", R"({"volume": null})"}).text, Catch::Contains("volume"));
  // A procedural volume may be named in the JSON.
  CHECK(accepted({}, {"", R"({"volume": {"procedural": "shepp-logan", "dims": [8, 8, 8]}})"}).hasVolume());
}

TEST_CASE("runtime null resets the settings to their defaults") {
  const SessionScene set = accepted({}, {"", R"({"runtime": {"threads": 4, "compression": "rle"}})"});
  CHECK(set.settings.compression == proto::Compression::kRle);
  const SessionScene reset = accepted(set, {"", R"({"runtime": null})"});
  CHECK(reset.settings == node::RuntimeSettings{});
}
