// A server opens only regular files inside its data directory: the dataset
// a client names and every file that dataset's header or sidecar names.
// The refusal reads the same whether the file exists or not.
#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <filesystem>
#include <regex>

#include "error.h"
#include "io/data_directory.h"
#include "io/volume_io.h"
#include "test_files.h"
#include "volume_test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

// A data directory "data" with a good sidecar dataset, and a file "secret"
// beside it (outside the data directory).
struct Layout {
  std::string root, data, secret;
};

Layout makeLayout(const std::string& name) {
  Layout l;
  l.root = scratchDir(name);
  l.data = l.root + "/data";
  fs::create_directories(l.data);
  writeRawJson(l.data, "good", testVolume(ScalarType::kUInt8), false);
  l.secret = l.root + "/secret.raw";
  writeBytes(l.secret, voxelData(testVolume(ScalarType::kUInt8), false));
  return l;
}

// The message openVolumeFile refuses `path` with inside `dir`.
std::string refusal(const std::string& path, const DataDirectory& dir) {
  try {
    openVolumeFile(path, &dir);
  } catch (const pvr::Error& e) {
    CHECK(e.code() == pvr::ErrorCode::kInvalidArgument);
    return e.what();
  }
  return "(opened)";
}

// A sidecar in `dir` whose raw_file is `rawFile`.
std::string sidecarNaming(const std::string& dir, const std::string& name, const std::string& rawFile) {
  const std::string json = writeRawJson(dir, name, testVolume(ScalarType::kUInt8), false);
  std::string text = readText(json);
  text = std::regex_replace(text, std::regex("\"raw_file\": \"[^\"]*\""), "\"raw_file\": \"" + rawFile + "\"");
  writeText(json, text);
  fs::remove(dir + "/" + name + ".raw");
  return json;
}

}  // namespace

TEST_CASE("a dataset inside the data directory opens", "[io][confinement]") {
  const Layout l = makeLayout("confine_good");
  const DataDirectory dir(l.data);
  CHECK(openVolumeFile(l.data + "/good.json", &dir)->grid().dims == testVolume(ScalarType::kUInt8).grid.dims);
  CHECK(dir.confine("good.json") == fs::canonical(l.data + "/good.json").string());
  // A symlink that stays inside is fine.
  fs::create_symlink("good.json", l.data + "/alias.json");
  CHECK(dir.confine("alias.json") == fs::canonical(l.data + "/good.json").string());
}

TEST_CASE("missing, outside, directory, FIFO and device paths are refused with one message", "[io][confinement]") {
  const Layout l = makeLayout("confine_refused");
  const DataDirectory dir(l.data);
  fs::create_directories(l.data + "/sub.json");
  REQUIRE(::mkfifo((l.data + "/pipe.json").c_str(), 0600) == 0);
  fs::create_symlink("/dev/zero", l.data + "/zero.raw");
  fs::create_symlink(l.secret, l.data + "/link.raw");
  const auto expected = [](const std::string& named) {
    return "dataset: '" + named + "' is not a regular file inside the data directory";
  };
  for (const std::string& named :
       {l.data + "/missing.json", l.root + "/secret.raw", std::string("/etc/shadow"), l.data + "/../secret.raw",
        l.data + "/sub.json", l.data + "/pipe.json", l.data + "/zero.raw", l.data + "/link.raw"}) {
    INFO(named);
    CHECK(refusal(named, dir) == expected(named));
  }
  CHECK_FALSE(dir.confine("../secret.raw"));
  CHECK_FALSE(dir.confine(""));
}

TEST_CASE("files a sidecar or header names must lie inside the data directory too", "[io][confinement]") {
  const Layout l = makeLayout("confine_named");
  const DataDirectory dir(l.data);
  const std::string absolute = sidecarNaming(l.data, "absolute", l.secret);
  CHECK_THAT(refusal(absolute, dir), Contains("'" + l.secret + "' is not a regular file inside the data directory"));
  const std::string upward = sidecarNaming(l.data, "upward", "../secret.raw");
  CHECK_THAT(refusal(upward, dir), Contains("is not a regular file inside the data directory"));
  // A .raw symlink beside its sidecar that leads outside.
  const std::string linked = sidecarNaming(l.data, "linked", "linked.raw");
  fs::create_symlink(l.secret, l.data + "/linked.raw");
  CHECK_THAT(refusal(linked, dir), Contains("is not a regular file inside the data directory"));
  const std::string zero = sidecarNaming(l.data, "zero", "/dev/zero");
  CHECK_THAT(refusal(zero, dir), Contains("'/dev/zero' is not a regular file inside the data directory"));

  // A detached NRRD header naming an absolute data file outside.
  NrrdOptions detached;
  detached.attached = false;
  const std::string nhdr = writeNrrd(l.data, "head", testVolume(ScalarType::kUInt8), detached);
  std::string text = readText(nhdr);
  text = std::regex_replace(text, std::regex("data file: [^\n]*"), "data file: " + l.secret);
  writeText(nhdr, text);
  CHECK_THAT(refusal(nhdr, dir), Contains("'" + l.secret + "' is not a regular file inside the data directory"));

  // Opened locally (pvr-render, no data directory) the same files still open.
  CHECK(openVolumeFile(absolute)->grid().dims == testVolume(ScalarType::kUInt8).grid.dims);
  CHECK(openVolumeFile(nhdr)->grid().dims == testVolume(ScalarType::kUInt8).grid.dims);
}

TEST_CASE("a data directory must be a directory", "[io][confinement]") {
  const Layout l = makeLayout("confine_root");
  CHECK_THROWS_WITH(DataDirectory(l.secret), Contains("not a directory"));
  CHECK_THROWS_WITH(DataDirectory(l.root + "/nowhere"), Contains("not a directory"));
}
