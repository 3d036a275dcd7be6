// The master's scene patches (scene_patch.h), serially: a patch is checked
// as a whole, with or without a dataset, and a refused one changes nothing.
#include <sys/stat.h>
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
    // A real volume, for the catalog to list under its stem "head".
    std::ofstream(d / "head.raw") << std::string(8, '\x01');
    std::ofstream(d / "head.json") << R"({"dims": [2, 2, 2], "dtype": "uint8", "spacing": [1, 1, 1]})";
    // A FIFO, a symlink to a device and one leading outside: names a client
    // may give that must never be opened.
    ::mkfifo((d / "pipe.json").c_str(), 0600);
    fs::create_symlink("/dev/zero", d / "zero.raw");
    fs::create_symlink("/etc/passwd", d / "passwd.json");
    fs::create_directories(d / "presets");
    std::ofstream(d / "presets" / "bone.json") << R"([{"Name": "bone", "RGBPoints": [0, 1, 1, 1, 1, 1, 1, 1]}])";
    std::ofstream(d / "outside.json") << R"([{"Name": "x", "RGBPoints": [0, 1, 1, 1, 1, 1, 1, 1]}])";
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
  // Missing, outside, a FIFO or a device: refused in the same words.
  for (const char* name : {"missing.json", "pipe.json", "zero.raw", "passwd.json", "/etc/passwd", "presets"}) {
    INFO(name);
    const auto e = refused({}, {name, ""});
    CHECK(e.code == proto::ErrorCode::kDatasetNotFound);
    CHECK(e.text == std::string("no dataset '") + name + "' in the data directory");
  }
  // A procedural volume may be named in the JSON.
  CHECK(accepted({}, {"", R"({"volume": {"procedural": "shepp-logan", "dims": [8, 8, 8]}})"}).hasVolume());
}

TEST_CASE("a dataset's volume gives way to a computation volume whose patch removes the file with null") {
  const SessionScene loaded = accepted({}, {"ct.json", ""});
  const SessionScene next =
      accepted(loaded, {"", R"({"volume": {"computation": "gray-scott", "dims": [8, 8, 8], "file": null}})"});
  CHECK_FALSE(next.doc["volume"].contains("file"));
  CHECK(next.doc["volume"]["computation"] == "gray-scott");
}

TEST_CASE("runtime null resets the settings to their defaults") {
  const SessionScene set = accepted({}, {"", R"({"runtime": {"threads": 4, "compression": "rle"}})"});
  CHECK(set.settings.compression == proto::Compression::kRle);
  const SessionScene reset = accepted(set, {"", R"({"runtime": null})"});
  CHECK(reset.settings == node::RuntimeSettings{});
}

TEST_CASE("a paraview_preset names a file of the data directory's presets folder, nothing else") {
  const SessionScene bone = accepted({}, {"", R"({"transfer_function": {"paraview_preset": "bone.json"}})"});
  CHECK(bone.doc["transfer_function"]["paraview_preset"] == (fs::path(dataDir()) / "presets" / "bone.json").string());
  // Kept resolved, so a later patch checks the same file again and passes.
  CHECK(accepted(bone, {"", R"({"image": {"width": 32}})"}).doc["transfer_function"] == bone.doc["transfer_function"]);
  for (const std::string named : {"missing.json", "../outside.json", "/etc/passwd", "../ct.json", "."}) {
    INFO(named);
    const auto e = refused({}, {"", R"({"transfer_function": {"paraview_preset": ")" + named + R"("}})"});
    CHECK(e.code == proto::ErrorCode::kBadArgument);
    CHECK(e.text == "scene.transfer_function.paraview_preset: no preset '" + named +
                        "' in the data directory's presets/ folder (send your own preset as \"paraview\")");
  }
  // In a volumes list too.
  const auto e = refused({}, {"", R"({"volumes": [{"name": "a", "procedural": "shepp-logan", )"
                                  R"("transfer_function": {"paraview_preset": "/etc/shadow"}}]})"});
  CHECK_THAT(e.text, Catch::StartsWith("scene.volumes[0].transfer_function.paraview_preset: no preset '/etc/shadow'"));
}

TEST_CASE("a scene patch nested deeper than the protocol's JSON limit is refused before it is parsed") {
  std::string bomb;
  for (int i = 0; i < 100000; ++i) bomb += "{\"a\":";
  const auto e = refused({}, {"", bomb});
  CHECK(e.code == proto::ErrorCode::kMalformedPayload);
  CHECK(e.text == "scene: JSON nests deeper than 64 levels (at byte 320)");
}

// docs/protocol.md, SetScene: "volumes" as a list replaces the volumes and
// drops the single form; entries name data by "dataset", resolved in the
// data directory; "file" and unknown datasets are refused naming the entry.
TEST_CASE("a volumes list replaces the session's volumes, its datasets resolved in the data directory") {
  const SessionScene one = accepted({}, {"ct.json", R"({"transfer_function": {"points": [[0, 1, 1, 1, 0], [1, 1, 1, 1, 1]]}})"});
  const SessionScene two = accepted(one, {"", R"({"volumes": [
      {"name": "ct", "dataset": "ct.json", "visible": false},
      {"name": "ml", "procedural": "marschner-lobb", "dims": [9, 9, 9]}]})"});
  CHECK_FALSE(two.doc.contains("volume"));
  CHECK_FALSE(two.doc.contains("transfer_function"));
  REQUIRE(two.doc["volumes"].size() == 2);
  CHECK(two.doc["volumes"][0]["file"] == dataDir() + "/ct.json");
  CHECK_FALSE(two.doc["volumes"][0].contains("dataset"));
  CHECK(two.doc["volumes"][0]["visible"] == false);
  CHECK(two.doc["volumes"][1]["procedural"] == "marschner-lobb");
  // By catalog stem, as `list datasets` names it (and pvrd the dataset field).
  const SessionScene stem = accepted(one, {"", R"({"volumes": [{"name": "h", "dataset": "head"}]})"});
  CHECK(stem.doc["volumes"][0]["file"] == dataDir() + "/head.json");

  auto e = refused(one, {"", R"({"volumes": [{"name": "a", "file": "/etc/passwd"}]})"});
  CHECK(e.code == proto::ErrorCode::kBadArgument);
  CHECK(e.text == "scene.volumes[0].file: name a dataset, not a volume file");
  e = refused(one, {"", R"({"volumes": [{"name": "a", "dataset": "ct.json"}, {"name": "b", "dataset": "passwd.json"}]})"});
  CHECK(e.code == proto::ErrorCode::kDatasetNotFound);
  CHECK(e.text == "scene.volumes[1].dataset: no dataset 'passwd.json' in the data directory");
  // Names are unique: the scene parser's check, naming the entry.
  e = refused(one, {"", R"({"volumes": [{"name": "a", "dataset": "ct.json"}, {"name": "a", "dataset": "ct.json"}]})"});
  CHECK(e.text.find("volumes[1].name") != std::string::npos);
}

// docs/protocol.md, SetScene: "volumes" as an object patches volumes by
// name: add (naming data), change visible or the transfer function,
// remove with null, never the last; a single-form scene is first the list
// [volume]; a dataset is exactly one volume again.
TEST_CASE("volumes patched by name are added, changed and removed, and a dataset means one volume") {
  const SessionScene one = accepted({}, {"ct.json", R"({"transfer_function": {"points": [[0, 1, 1, 1, 0], [1, 1, 1, 1, 1]]}})"});
  const SessionScene two = accepted(one, {"", R"({"volumes": {"pet": {"dataset": "ct.json", "visible": false}}})"});
  REQUIRE(two.doc["volumes"].size() == 2);
  CHECK(two.doc["volumes"][0]["name"] == "volume");
  CHECK(two.doc["volumes"][0]["file"] == dataDir() + "/ct.json");
  CHECK(two.doc["volumes"][0]["transfer_function"]["points"][1][4] == 1);
  CHECK(two.doc["volumes"][1]["name"] == "pet");
  CHECK_FALSE(two.doc.contains("volume"));

  // Another transfer function replaces the old whole; visibility merges.
  const SessionScene changed = accepted(two, {"", R"({"volumes": {"pet": {"visible": true,
      "transfer_function": {"paraview_preset": "bone.json"}}}})"});
  const auto& pet = changed.doc["volumes"][1];
  CHECK(pet["visible"] == true);
  CHECK(pet["transfer_function"] == nlohmann::json{{"paraview_preset", dataDir() + "/presets/bone.json"}});
  // New data replaces the old data's keys.
  const SessionScene procedural =
      accepted(changed, {"", R"({"volumes": {"pet": {"procedural": "shepp-logan", "dims": [8, 8, 8]}}})"});
  CHECK_FALSE(procedural.doc["volumes"][1].contains("file"));
  CHECK(procedural.doc["volumes"][1]["procedural"] == "shepp-logan");

  const SessionScene removed = accepted(changed, {"", R"({"volumes": {"volume": null}})"});
  REQUIRE(removed.doc["volumes"].size() == 1);
  CHECK(removed.doc["volumes"][0]["name"] == "pet");
  auto e = refused(removed, {"", R"({"volumes": {"pet": null}})"});
  CHECK(e.text == "scene.volumes.pet: cannot remove the last volume 'pet'; name another dataset");
  e = refused(removed, {"", R"({"volumes": {"nope": null}})"});
  CHECK(e.text == "scene.volumes.nope: no volume 'nope' to remove");
  e = refused(removed, {"", R"({"volumes": {"new": {"visible": true}}})"});
  CHECK(e.text == "scene.volumes.new: a new volume names its data (\"dataset\" or \"procedural\")");
  e = refused(removed, {"", R"({"volumes": {"pet": {"dataset": "missing.json"}}})"});
  CHECK(e.code == proto::ErrorCode::kDatasetNotFound);
  e = refused(removed, {"", R"({"volumes": 3})"});
  CHECK(e.code == proto::ErrorCode::kBadArgument);

  // set -dataset: exactly this one volume.
  const SessionScene single = accepted(changed, {"ct.json", ""});
  CHECK_FALSE(single.doc.contains("volumes"));
  CHECK(single.doc["volume"]["file"] == dataDir() + "/ct.json");
  // So does a "volume" of the scene document.
  const SessionScene generated =
      accepted(changed, {"", R"({"volume": {"procedural": "shepp-logan", "dims": [8, 8, 8]}})"});
  CHECK_FALSE(generated.doc.contains("volumes"));
}
