// libFuzzer target for the scene parser (renderer/scene*.cpp, docs/scene.md).
//
// The input is the text of a scene document, read as pvr-render reads a
// scene file (readJsonFile's rules: parseJsonText) and then parsed by
// parseScene. For any input:
//   - every refusal is a pvr::Error with a message of printable text (no
//     control bytes: a key "\u0000" once made an empty message); any other exception
//     (nlohmann's type_error, std::out_of_range, bad_alloc) escapes and
//     libFuzzer reports it as a crash;
//   - a scene that parses prints (sceneToJson) to a document that parses
//     again to a scene printing the same document;
//   - resolveDefaults, on the grid a procedural or computation volume
//     describes, either refuses with a pvr::Error or leaves nothing
//     automatic: a positive step within kMaxSamplesPerRay of the domain's
//     diagonal and a positive unit distance for every volume.
// Parse only: nothing is rendered and no volume is opened. The one key
// that makes the parser read a file, "paraview_preset", is pointed at a
// file that does not exist before parsing (the refusal path is what a
// missing preset exercises); inline presets ("paraview") are parsed as
// they are. Any broken property aborts; the sanitizers report the rest.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "error.h"
#include "io/json_file.h"
#include "scene.h"

namespace {

using nlohmann::json;

// The scene's directory: relative file names resolve against it. It does
// not exist, so nothing under it can be opened.
constexpr const char* kBaseDir = "/nonexistent-pvr-scene-fuzz";

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "scene fuzz: %s\n", what);
    std::abort();
  }
}

// A refusal's message: not empty, and no control byte below 0x20 in it (a
// NUL would cut it short, an escape sequence would reach a terminal or a log).
void requireMessage(const pvr::Error& e, const char* what) {
  const std::string_view message = e.what();
  require(!message.empty(), what);
  for (const char c : message)
    require(static_cast<unsigned char>(c) >= 0x20, "a refusal's message holds a control byte");
}

// Points every string "paraview_preset" where the parser looks for one
// (the scene's transfer_function and each volumes[i].transfer_function)
// at a missing file beside the scene, so no input makes the target read
// /dev/zero, a FIFO or anything else on this machine.
void defusePresetFiles(json& doc) {
  const auto defuse = [](json& tf) {
    if (tf.is_object() && tf.contains("paraview_preset") && tf["paraview_preset"].is_string())
      tf["paraview_preset"] = "missing-preset.json";
  };
  if (!doc.is_object()) return;
  if (doc.contains("transfer_function")) defuse(doc["transfer_function"]);
  if (doc.contains("volumes") && doc["volumes"].is_array())
    for (json& volume : doc["volumes"])
      if (volume.is_object() && volume.contains("transfer_function")) defuse(volume["transfer_function"]);
}

// The grid a procedural or computation volume of these dims and spacing
// has (openProcedural's rule: [-1, 1] on the longest axis unless a spacing
// is given, centred on 0), without generating it.
pvr::core::GridGeometry gridOf(const pvr::core::VolumeSpec& source) {
  pvr::core::GridGeometry grid;
  grid.dims = source.dims;
  const std::int64_t longest = std::max({source.dims.x, source.dims.y, source.dims.z});
  const double h = longest > 1 ? 2.0 / double(longest - 1) : 2.0;
  grid.spacing = source.spacing.value_or(pvr::core::Vec3{h, h, h});
  for (int a = 0; a < 3; ++a) grid.origin[a] = -double(grid.dims[a] - 1) * grid.spacing[a] / 2;
  return grid;
}

void checkDefaults(pvr::core::Scene scene) {
  const pvr::core::VolumeSpec& source = scene.volumes.front().source;
  if (!source.file.empty()) return;  // the grid is the file's: not opened here
  const pvr::core::GridGeometry grid = gridOf(source);
  try {
    pvr::core::resolveDefaults(scene, grid);
  } catch (const pvr::Error& e) {
    requireMessage(e, "resolveDefaults refused without a message");
    return;
  }
  require(!scene.camera.automatic, "the camera is still automatic after resolveDefaults");
  require(std::isfinite(scene.sampling.step) && scene.sampling.step > 0, "resolveDefaults left a bad step");
  const double diagonal = length(grid.domainMax() - grid.domainMin());
  require(diagonal / scene.sampling.step <= pvr::core::kMaxSamplesPerRay, "a step over the samples-per-ray limit");
  for (const pvr::core::SceneVolume& v : scene.volumes)
    require(v.transfer.unitDistance > 0, "resolveDefaults left a unit distance of 0");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);

  // The document, as a scene file's text is read.
  json doc;
  try {
    doc = pvr::core::parseJsonText(text, "scene.json");
  } catch (const pvr::Error& e) {
    requireMessage(e, "a JSON refusal without a message");
    return 0;
  }
  defusePresetFiles(doc);

  // The scene, or its refusal.
  pvr::core::Scene scene;
  try {
    scene = pvr::core::parseScene(doc, kBaseDir);
  } catch (const pvr::Error& e) {
    requireMessage(e, "a scene refusal without a message");
    return 0;
  }
  require(!scene.volumes.empty(), "a scene without volumes");

  // Printing is the inverse of parsing: what prints parses and prints the same.
  const json printed = pvr::core::sceneToJson(scene);
  pvr::core::Scene again;
  try {
    again = pvr::core::parseScene(printed, kBaseDir);
  } catch (const pvr::Error& e) {
    std::fprintf(stderr, "scene fuzz: printed scene refused: %s\n%s\n", e.what(), printed.dump().c_str());
    std::abort();
  }
  require(pvr::core::sceneToJson(again) == printed, "a printed scene does not print the same after parsing");

  checkDefaults(scene);
  return 0;
}
