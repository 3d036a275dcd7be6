// ParaView presets (renderer/paraview_preset.h): one reader for the file
// form "paraview_preset": PATH and the inline form "paraview": JSON of a
// scene's transfer function, the same rules and the same result for both.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "error.h"
#include "paraview_preset.h"
#include "scene.h"
#include "test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json sceneWithTransfer(const json& transfer) {
  return {{"volume", {{"procedural", "shepp-logan"}}}, {"transfer_function", transfer}};
}

// The transfer function of a scene naming `presetText` through a file in `dir`.
TransferFunctionSpec throughFile(const std::string& presetText, const fs::path& dir, const std::string& name) {
  writeText(dir / name, presetText);
  return parseScene(sceneWithTransfer({{"paraview_preset", name}}), dir.string()).volumes.front().transfer;
}

// The same preset inline.
TransferFunctionSpec inlined(const std::string& presetText) {
  return parseScene(sceneWithTransfer({{"paraview", json::parse(presetText)}}), "").volumes.front().transfer;
}

void requireSameTransfer(const TransferFunctionSpec& a, const TransferFunctionSpec& b) {
  CHECK(a.unitDistance == b.unitDistance);
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    INFO("point " << i);
    CHECK(a.points[i].scalar == b.points[i].scalar);
    CHECK(a.points[i].r == b.points[i].r);
    CHECK(a.points[i].g == b.points[i].g);
    CHECK(a.points[i].b == b.points[i].b);
    CHECK(a.points[i].opacity == b.points[i].opacity);
  }
}

// Expected points as rows {scalar, r, g, b, opacity}.
void requirePoints(const TransferFunctionSpec& tf, const std::vector<std::array<double, 5>>& expected) {
  REQUIRE(tf.points.size() == expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    INFO("point " << i);
    const TransferPoint& p = tf.points[i];
    CHECK(p.scalar == expected[i][0]);
    CHECK(p.r == Approx(expected[i][1]).margin(1e-15));
    CHECK(p.g == Approx(expected[i][2]).margin(1e-15));
    CHECK(p.b == Approx(expected[i][3]).margin(1e-15));
    CHECK(p.opacity == Approx(expected[i][4]).margin(1e-15));
  }
}

}  // namespace

TEST_CASE("ParaView presets merge colour and opacity at the union of their scalars", "[scene][preset]") {
  SECTION("colour and opacity knots at different scalars, clamped outside their own knots") {
    // Colour knots at 0, 10, 20; opacity knots at 5, 15: opacity is 0 below
    // 5 and 1 above 15, colour interpolates between its knots.
    const TransferFunctionSpec tf = paraViewPresetFromJson(json::parse(R"([{"Name": "t", "ColorSpace": "Diverging",
      "RGBPoints": [0, 0, 0, 0,  10, 1, 0.5, 0,  20, 1, 1, 1],
      "Points": [5, 0, 0.5, 0,  15, 1, 0.5, 0]}])"), "tf");
    CHECK(tf.unitDistance == 0);
    requirePoints(tf, {{0, 0, 0, 0, 0}, {5, 0.5, 0.25, 0, 0}, {10, 1, 0.5, 0, 0.5},
                       {15, 1, 0.75, 0.5, 1}, {20, 1, 1, 1, 1}});
  }

  SECTION("opacity knots beyond the colour range take the clamped end colours") {
    const TransferFunctionSpec tf = paraViewPresetFromJson(json::parse(R"({
      "RGBPoints": [0, 0.2, 0.4, 0.6,  10, 1, 1, 1],
      "Points": [-10, 0.1, 0.5, 0,  20, 0.7, 0.5, 0]})"), "tf");
    requirePoints(tf, {{-10, 0.2, 0.4, 0.6, 0.1}, {0, 0.2, 0.4, 0.6, 0.3},
                       {10, 1, 1, 1, 0.5}, {20, 1, 1, 1, 0.7}});
  }

  SECTION("one preset object without Points ramps opacity over the colour range") {
    const TransferFunctionSpec tf =
        paraViewPresetFromJson(json::parse(R"({"RGBPoints": [-1, 1, 0, 0,  0, 0, 1, 0,  3, 0, 0, 1]})"), "tf");
    requirePoints(tf, {{-1, 1, 0, 0, 0}, {0, 0, 1, 0, 0.25}, {3, 0, 0, 1, 1}});
  }

  SECTION("a jump in colour becomes two points at one scalar") {
    const TransferFunctionSpec tf = paraViewPresetFromJson(json::parse(R"([{
      "RGBPoints": [0, 0, 0, 0,  1, 0, 0, 0,  1, 1, 1, 1,  2, 1, 1, 1],
      "Points": [0, 0, 0.5, 0,  2, 1, 0.5, 0]}])"), "tf");
    requirePoints(tf, {{0, 0, 0, 0, 0}, {1, 0, 0, 0, 0.5}, {1, 1, 1, 1, 0.5}, {2, 1, 1, 1, 1}});
  }

  SECTION("a jump in opacity of three knots keeps the first and the last") {
    const TransferFunctionSpec tf = paraViewPresetFromJson(json::parse(R"({
      "RGBPoints": [0, 1, 1, 1,  2, 1, 1, 1],
      "Points": [0, 0, 0.5, 0,  1, 0.2, 0.5, 0,  1, 0.9, 0.5, 0,  1, 0.4, 0.5, 0,  2, 0.4, 0.5, 0]})"), "tf");
    requirePoints(tf, {{0, 1, 1, 1, 0}, {1, 1, 1, 1, 0.2}, {1, 1, 1, 1, 0.4}, {2, 1, 1, 1, 0.4}});
  }

  SECTION("an array's first preset is used; the others are not read") {
    const TransferFunctionSpec tf =
        paraViewPresetFromJson(json::parse(R"([{"RGBPoints": [0, 1, 0, 0,  1, 0, 1, 0]}, {"Name": "not a colour preset"}])"), "tf");
    requirePoints(tf, {{0, 1, 0, 0, 0}, {1, 0, 1, 0, 1}});
  }
}

TEST_CASE("inline and file presets give identical transfer functions", "[scene][preset]") {
  const std::string presets[] = {
      R"([{"Name": "t", "RGBPoints": [0, 0, 0, 0,  10, 1, 0.5, 0,  20, 1, 1, 1],
          "Points": [5, 0, 0.5, 0,  15, 1, 0.5, 0]}])",
      R"({"RGBPoints": [-1, 1, 0, 0,  0, 0, 1, 0,  3, 0, 0, 1]})",
      R"({"RGBPoints": [0, 0, 0, 0,  1, 0, 0, 0,  1, 1, 1, 1,  2, 1, 1, 1]})",
      R"({"RGBPoints": [0.1, 0.3, 0.7, 0.2], "Points": [0.1, 0.123456789, 0.5, 0]})",
  };
  const fs::path dir = scratchDir("preset_inline_and_file");
  int n = 0;
  for (const std::string& text : presets) {
    INFO(text);
    requireSameTransfer(throughFile(text, dir, "same_" + std::to_string(n++) + ".json"), inlined(text));
  }

  // The example preset, read as pvrsh -tfpreset sends it, with a unit distance beside it.
  std::ifstream in(kSourceRoot / "examples" / "presets" / "ct_bone.json");
  const json bone = json::parse(in);
  const Scene viaFile = parseScene(
      sceneWithTransfer({{"paraview_preset", "presets/ct_bone.json"}, {"unit_distance", 0.957031}}),
      (kSourceRoot / "examples").string());
  const Scene viaInline = parseScene(sceneWithTransfer({{"paraview", bone}, {"unit_distance", 0.957031}}), "");
  requireSameTransfer(viaFile.volumes.front().transfer, viaInline.volumes.front().transfer);
  CHECK(viaInline.volumes.front().transfer.unitDistance == 0.957031);
  REQUIRE(viaInline.volumes.front().transfer.points.size() == 5);
  CHECK(viaInline.volumes.front().transfer.points.front().scalar == -1024);
  CHECK(viaInline.volumes.front().transfer.points[1].opacity == 0);  // HU 200: still transparent
  CHECK(viaInline.volumes.front().transfer.points.back().scalar == 2000);
  CHECK(viaInline.volumes.front().transfer.points.back().opacity == 0.9);
}

TEST_CASE("a malformed preset is an error naming the key path, inline and in a file", "[scene][preset]") {
  // `at` is the key path inside the preset's JSON ("" for the JSON itself).
  struct Case { const char* text; const char* at; const char* message; };
  const Case cases[] = {
      {R"([])", "", "is an empty array (a preset file holds one preset object or an array of them)"},
      {R"("bone")", "", "must be a ParaView preset object, got string \"bone\""},
      {R"([3])", "[0]", "must be a ParaView preset object, got number 3"},
      {R"([{"Name": "x"}])", "[0]", "has no \"RGBPoints\" (not a colour transfer-function preset)"},
      {R"({"RGBPoints": [0, 1, 1]})", "RGBPoints", "must be a non-empty array of groups of 4 numbers, got array [0,1,1]"},
      {R"({"RGBPoints": []})", "RGBPoints", "must be a non-empty array of groups of 4 numbers, got array []"},
      {R"({"RGBPoints": {"x": 0}})", "RGBPoints", "must be a non-empty array of groups of 4 numbers, got object {\"x\":0}"},
      {R"({"RGBPoints": [1, 0, 0, 0, 0, 1, 1, 1]})", "RGBPoints[4]",
       "scalar 0 is below the previous point's 1; points must be sorted by scalar"},
      {R"({"RGBPoints": [0, 0, -1, 0]})", "RGBPoints[2]", "must be >= 0, got -1"},
      {R"({"RGBPoints": [0, 0, "x", 0]})", "RGBPoints[2]", "must be a number, got string \"x\""},
      {R"({"RGBPoints": ["0", 0, 0, 0]})", "RGBPoints[0]", "must be a number, got string \"0\""},
      {R"([{"RGBPoints": [0, 0, 0, 0], "Points": [0, 1.2, 0.5, 0]}])", "[0].Points[1]", "must be in [0, 1], got 1.2"},
      {R"({"RGBPoints": [0, 0, 0, 0], "Points": [0, -0.5, 0.5, 0]})", "Points[1]", "must be in [0, 1], got -0.5"},
      {R"({"RGBPoints": [0, 0, 0, 0], "Points": [0, 0.5, null, 0]})", "Points[2]", "must be a number, got null"},
      {R"({"RGBPoints": [0, 0, 0, 0], "Points": [1, 0, 0.5, 0, 0, 1, 0.5, 0]})", "Points[4]",
       "scalar 0 is below the previous point's 1; points must be sorted by scalar"},
      {R"({"RGBPoints": [0, 0, 0, 0], "Points": "linear"})", "Points",
       "must be a non-empty array of groups of 4 numbers, got string \"linear\""},
  };
  const fs::path file = fs::path(scratchDir("preset_malformed")) / "bad.json";
  for (const Case& c : cases) {
    INFO(c.text);
    const std::string at = c.at;

    // Inline: the key path continues the scene's.
    const std::string inlinePath =
        "transfer_function.paraview" + (at.empty() ? "" : at[0] == '[' ? at : "." + at);
    try {
      parseScene(sceneWithTransfer({{"paraview", json::parse(c.text)}}), "");
      FAIL("no error");
    } catch (const pvr::Error& e) {
      CHECK(std::string(e.what()) == inlinePath + ": " + c.message);
      CHECK(e.code() == pvr::ErrorCode::kInvalidArgument);
    }

    // File: the scene's key, the file, then the path inside the file.
    writeText(file, c.text);
    try {
      parseScene(sceneWithTransfer({{"paraview_preset", file.string()}}), "");
      FAIL("no error");
    } catch (const pvr::Error& e) {
      CHECK(std::string(e.what()) ==
            "transfer_function.paraview_preset: " + file.string() + ": " + (at.empty() ? "" : at + ": ") + c.message);
      CHECK(e.code() == pvr::ErrorCode::kBadFile);
    }
  }
}

TEST_CASE("a preset file that cannot be read names the file", "[scene][preset]") {
  const fs::path dir = scratchDir("preset_unreadable");
  const fs::path notJson = dir / "not_json.json";
  writeText(notJson, "[{\"RGBPoints\": ");
  try {
    loadParaViewPreset(notJson.string());
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(std::string(e.what()).rfind(notJson.string() + ": not valid JSON", 0) == 0);
    CHECK(e.code() == pvr::ErrorCode::kBadFile);
  }

  const std::string missing = (dir / "no_such_preset.json").string();
  try {
    parseScene(sceneWithTransfer({{"paraview_preset", "no_such_preset.json"}}), dir.string());
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(std::string(e.what()) == "transfer_function.paraview_preset: " + missing + ": no such file");
    CHECK(e.code() == pvr::ErrorCode::kIo);
  }
}

TEST_CASE("a transfer function takes exactly one of points, a preset file or an inline preset", "[scene][preset]") {
  const json points = json::array({json::array({0, 0, 0, 0, 0})});
  const json preset = json::parse(R"({"RGBPoints": [0, 1, 1, 1]})");
  const std::string message =
      "transfer_function: needs exactly one of 'points', 'paraview_preset' (a preset file) or 'paraview' (a preset inline)";
  for (const json& tf : {json::object(), json{{"points", points}, {"paraview", preset}},
                         json{{"paraview_preset", "x.json"}, {"paraview", preset}},
                         json{{"unit_distance", 1}}}) {
    INFO(tf.dump());
    try {
      parseScene(sceneWithTransfer(tf), "");
      FAIL("no error");
    } catch (const pvr::Error& e) {
      CHECK(std::string(e.what()) == message);
    }
  }
}
