// Scene documents: parsing, key-path errors, printing, the image limit and
// the defaults resolved from the grid (ParaView presets: paraview_preset_test.cpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "camera.h"
#include "error.h"
#include "raycast/raycaster.h"
#include "scene.h"
#include "test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// The JSON block under "## A full example" in docs/scene.md, so the
// documentation's example is the one the tests parse.
json docsFullExample() {
  const std::string doc = readText(kSourceRoot / "docs" / "scene.md");
  const std::size_t section = doc.find("## A full example");
  REQUIRE(section != std::string::npos);
  const std::size_t begin = doc.find("```json\n", section);
  REQUIRE(begin != std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  return json::parse(doc.substr(begin + 8, end - begin - 8));
}

// A small valid scene every error case starts from.
json baseDoc() {
  return json::parse(R"({
    "volume": {"procedural": "shepp-logan", "dims": [16, 16, 16]},
    "transfer_function": {"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 0.5]], "unit_distance": 0.1},
    "camera": {"projection": "perspective", "eye": [0, -5, 0], "look_at": [0, 0, 0],
               "up": [0, 0, 1], "fov_y_deg": 30},
    "image": {"width": 64, "height": 48, "background": [0, 0, 0, 1]},
    "sampling": {"step": 0.05, "preintegrated": false, "early_termination": 1},
    "shading": {"enabled": false, "ambient": 0.2, "diffuse": 0.7, "specular": 0.3,
                "shininess": 32, "light_direction": [0, 0, 1]}
  })");
}

// The message of the pvr::Error that parsing `doc` throws ("" if none).
std::string parseError(const json& doc, pvr::ErrorCode* code = nullptr) {
  try {
    parseScene(doc, "/base");
  } catch (const pvr::Error& e) {
    if (code) *code = e.code();
    return e.what();
  }
  return "";
}

void requireSameVec(Vec3 a, Vec3 b) {
  CHECK(a.x == b.x);
  CHECK(a.y == b.y);
  CHECK(a.z == b.z);
}

// Field by field, exact: a printer that forgot a key fails here even when
// printing twice agrees with itself.
void requireSameScene(const Scene& a, const Scene& b) {
  CHECK(a.volumes.front().source.file == b.volumes.front().source.file);
  CHECK(a.volumes.front().source.procedural == b.volumes.front().source.procedural);
  CHECK(a.volumes.front().source.dims == b.volumes.front().source.dims);
  REQUIRE(a.volumes.front().source.spacing.has_value() == b.volumes.front().source.spacing.has_value());
  if (a.volumes.front().source.spacing) requireSameVec(*a.volumes.front().source.spacing, *b.volumes.front().source.spacing);
  REQUIRE(a.volumes.front().transfer.points.size() == b.volumes.front().transfer.points.size());
  for (std::size_t i = 0; i < a.volumes.front().transfer.points.size(); ++i) {
    const TransferPoint &p = a.volumes.front().transfer.points[i], &q = b.volumes.front().transfer.points[i];
    CHECK(p.scalar == q.scalar);
    CHECK(p.r == q.r);
    CHECK(p.g == q.g);
    CHECK(p.b == q.b);
    CHECK(p.opacity == q.opacity);
  }
  CHECK(a.volumes.front().transfer.unitDistance == b.volumes.front().transfer.unitDistance);
  CHECK(a.camera.projection == b.camera.projection);
  requireSameVec(a.camera.eye, b.camera.eye);
  requireSameVec(a.camera.lookAt, b.camera.lookAt);
  requireSameVec(a.camera.up, b.camera.up);
  CHECK(a.camera.height == b.camera.height);
  CHECK(a.camera.fovYDeg == b.camera.fovYDeg);
  CHECK(a.camera.automatic == b.camera.automatic);
  CHECK(a.image.width == b.image.width);
  CHECK(a.image.height == b.image.height);
  CHECK(a.image.background == b.image.background);
  CHECK(a.sampling.step == b.sampling.step);
  CHECK(a.sampling.preintegrated == b.sampling.preintegrated);
  CHECK(a.sampling.earlyTermination == b.sampling.earlyTermination);
  CHECK(a.shading.enabled == b.shading.enabled);
  CHECK(a.shading.ambient == b.shading.ambient);
  CHECK(a.shading.diffuse == b.shading.diffuse);
  CHECK(a.shading.specular == b.shading.specular);
  CHECK(a.shading.shininess == b.shading.shininess);
  requireSameVec(a.shading.lightDirection, b.shading.lightDirection);
}

}  // namespace

TEST_CASE("the full example of docs/scene.md parses to its values", "[scene]") {
  const Scene s = parseScene(docsFullExample(), "");
  CHECK(s.volumes.front().source.procedural == "shepp-logan");
  CHECK(s.volumes.front().source.file.empty());
  CHECK(s.volumes.front().source.dims == IVec3{128, 128, 128});
  REQUIRE(s.volumes.front().source.spacing);
  CHECK(s.volumes.front().source.spacing->y == 0.015748);
  REQUIRE(s.volumes.front().transfer.points.size() == 9);
  CHECK(s.volumes.front().transfer.points[4].scalar == 0.3);
  CHECK(s.volumes.front().transfer.points[4].g == 0.8);
  CHECK(s.volumes.front().transfer.points[4].opacity == 0.15);
  CHECK(s.volumes.front().transfer.unitDistance == 0.015748);
  CHECK_FALSE(s.camera.automatic);
  CHECK(s.camera.projection == Projection::kPerspective);
  CHECK(s.camera.eye == Vec3{3.3, -5.72, 2.4});
  CHECK(s.camera.fovYDeg == 30);
  CHECK(s.image.width == 512);
  CHECK(s.image.background == std::array<double, 4>{0.1, 0.1, 0.12, 1.0});
  CHECK(s.sampling.step == 0.007874);
  CHECK(s.sampling.earlyTermination == 0.99);
  CHECK(s.shading.enabled);
  CHECK(s.shading.shininess == 32);
}

TEST_CASE("a scene with only a volume takes the defaults of scene.h", "[scene]") {
  const Scene s = parseScene(json::parse(R"({"volume": {"procedural": "shepp-logan"}})"), "");
  const Scene d;
  CHECK(s.volumes.front().source.dims == d.volumes.front().source.dims);
  CHECK_FALSE(s.volumes.front().source.spacing);
  CHECK(s.camera.automatic);
  CHECK(s.camera.projection == Projection::kPerspective);
  CHECK(s.image.width == d.image.width);
  CHECK(s.image.height == d.image.height);
  CHECK(s.image.background == d.image.background);
  CHECK(s.sampling.step == 0);
  CHECK(s.sampling.earlyTermination == kDefaultEarlyTermination);
  CHECK_FALSE(s.sampling.preintegrated);
  CHECK_FALSE(s.shading.enabled);
  CHECK(s.shading.ambient == d.shading.ambient);
  CHECK(s.shading.lightDirection == d.shading.lightDirection);
  CHECK(s.volumes.front().transfer.unitDistance == 0);
  // No transfer function: until the data's range is known, the documented
  // white ramp over [0, 1], clear below its first tenth.
  REQUIRE(s.volumes.front().transfer.points.size() == 3);
  CHECK(s.volumes.front().transfer.points[0].scalar == 0);
  CHECK(s.volumes.front().transfer.points[0].opacity == 0);
  CHECK(s.volumes.front().transfer.points[1].scalar == Approx(0.1));
  CHECK(s.volumes.front().transfer.points[1].opacity == 0);
  CHECK(s.volumes.front().transfer.points[2].scalar == 1);
  CHECK(s.volumes.front().transfer.points[2].opacity == 1);
}

TEST_CASE("a camera section turns the automatic camera off, perspective fov defaults to 30", "[scene]") {
  json doc = baseDoc();
  doc["camera"] = json::parse(R"({"eye": [1, 2, 3], "look_at": [0, 0, 0]})");
  const Scene s = parseScene(doc, "");
  CHECK_FALSE(s.camera.automatic);
  CHECK(s.camera.projection == Projection::kPerspective);
  CHECK(s.camera.fovYDeg == 30);
  CHECK(s.camera.up == Vec3{0, 0, 1});

  doc["camera"] = json::parse(R"({"projection": "orthographic", "eye": [0, -5, 0], "look_at": [0, 0, 0], "height": 2.5})");
  const Scene o = parseScene(doc, "");
  CHECK(o.camera.projection == Projection::kOrthographic);
  CHECK(o.camera.height == 2.5);
}

TEST_CASE("relative paths resolve against the base directory", "[scene]") {
  json doc = baseDoc();
  doc["volume"] = {{"file", "data/ct.nhdr"}};
  CHECK(parseScene(doc, "/scenes/a").volumes.front().source.file == "/scenes/a/data/ct.nhdr");
  doc["volume"] = {{"file", "../ct.nhdr"}};
  CHECK(parseScene(doc, "/scenes/a").volumes.front().source.file == "/scenes/ct.nhdr");
  doc["volume"] = {{"file", "/abs/ct.nhdr"}};
  CHECK(parseScene(doc, "/scenes/a").volumes.front().source.file == "/abs/ct.nhdr");
  doc["volume"] = {{"file", "ct.nhdr"}};
  CHECK(parseScene(doc, "").volumes.front().source.file == "ct.nhdr");
}

TEST_CASE("unknown keys are errors naming the key path and the known keys", "[scene]") {
  struct Case { const char* pointer; const char* message; };
  const Case cases[] = {
      {"/fov", "fov: unknown key (known: volume, volumes, timestep, transfer_function, parameters, camera, image, sampling, shading)"},
      {"/camera/fov", "camera.fov: unknown key (known: projection, eye, look_at, up, height, fov_y_deg)"},
      {"/volume/dim", "volume.dim: unknown key (known: file, procedural, computation, dims, spacing)"},
      {"/transfer_function/point", "transfer_function.point: unknown key (known: points, paraview_preset, paraview, unit_distance, absolute)"},
      {"/image/size", "image.size: unknown key (known: width, height, background)"},
      {"/sampling/steps", "sampling.steps: unknown key (known: step, preintegrated, early_termination, target_psnr)"},
      {"/shading/light", "shading.light: unknown key (known: enabled, ambient, diffuse, specular, shininess, light_direction)"},
  };
  for (const Case& c : cases) {
    INFO(c.pointer);
    json doc = baseDoc();
    doc[json::json_pointer(c.pointer)] = 1;
    pvr::ErrorCode code{};
    CHECK(parseError(doc, &code) == c.message);
    CHECK(code == pvr::ErrorCode::kInvalidArgument);
  }
}

TEST_CASE("wrong types and bad values are errors naming the key path", "[scene]") {
  struct Case { const char* pointer; json value; const char* message; };
  const Case cases[] = {
      {"/image/width", 0, "image.width: must be in 1..16384, got 0"},
      {"/image/height", 16385, "image.height: must be in 1..16384, got 16385"},
      {"/image/width", "512", "image.width: must be an integer, got string \"512\""},
      {"/image/width", 512.5, "image.width: must be an integer"},
      {"/image/background", json::array({0, 0, 0}), "image.background: must be an array of 4 numbers"},
      {"/image/background/3", 2, "image.background[3]: must be in [0, 1], got 2"},
      {"/sampling/step", 0, "sampling.step: must be > 0, got 0"},
      {"/sampling/step", -0.5, "sampling.step: must be > 0, got -0.5"},
      {"/sampling/step", nullptr, "sampling.step: must be a number, got null"},
      {"/sampling/early_termination", 0, "sampling.early_termination: must be in (0, 1], got 0"},
      {"/sampling/early_termination", 1.5, "sampling.early_termination: must be in (0, 1], got 1.5"},
      {"/sampling/preintegrated", 1, "sampling.preintegrated: must be true or false, got number 1"},
      {"/sampling/target_psnr", -1, "sampling.target_psnr: must be in [0, 120] dB (0 = off), got -1"},
      {"/sampling/target_psnr", 121, "sampling.target_psnr: must be in [0, 120] dB (0 = off), got 121"},
      {"/sampling/target_psnr", "high", "sampling.target_psnr: must be a number"},
      {"/transfer_function/points/1/4", 1.5, "transfer_function.points[1][4]: must be in [0, 1], got 1.5"},
      {"/transfer_function/points/1/4", -0.1, "transfer_function.points[1][4]: must be in [0, 1], got -0.1"},
      {"/transfer_function/points/0/1", -0.1, "transfer_function.points[0][1]: must be >= 0, got -0.1"},
      {"/transfer_function/points/0/3", "red", "transfer_function.points[0][3]: must be a number"},
      {"/transfer_function/points", json::array(), "transfer_function.points: needs at least one point"},
      {"/transfer_function/points", json::parse("[[1, 0, 0, 0, 0], [0.5, 0, 0, 0, 0]]"),
       "transfer_function.points[1]: scalar 0.5 is below the previous point's 1; points must be sorted by scalar"},
      {"/transfer_function/points/0", json::array({0, 1, 1, 1}), "transfer_function.points[0]: must be [scalar, r, g, b, opacity]"},
      {"/transfer_function/points", json::object(), "transfer_function.points: must be an array"},
      {"/transfer_function/unit_distance", 0, "transfer_function.unit_distance: must be > 0, got 0"},
      {"/camera/fov_y_deg", 180, "camera.fov_y_deg: must be in (0, 180), got 180"},
      {"/camera/fov_y_deg", 0, "camera.fov_y_deg: must be in (0, 180), got 0"},
      {"/camera/height", 0, "camera.height: must be > 0, got 0"},
      {"/camera/eye", json::array({0, 0, 0}), "camera.eye: must differ from camera.look_at"},
      {"/camera/up", json::array({0, 2, 0}), "camera.up: must not be parallel to the view direction"},
      {"/camera/up", json::array({0, 0, 0}), "camera.up: must not be the zero vector"},
      {"/camera/eye", json::array({1, 2}), "camera.eye: must be an array of 3 numbers"},
      {"/camera/look_at/2", "x", "camera.look_at[2]: must be a number"},
      {"/camera/projection", "fisheye", "camera.projection: must be \"orthographic\" or \"perspective\", got \"fisheye\""},
      {"/camera", json::array(), "camera: must be an object"},
      {"/volume/dims/0", 0, "volume.dims[0]: must be in 1..2147483647, got 0"},
      {"/volume/dims", json::array({4, 4}), "volume.dims: must be an array of 3 integers"},
      {"/volume/spacing", json::array({1, 1, 0}), "volume.spacing[2]: must be > 0, got 0"},
      {"/volume/procedural", "teapot", "volume.procedural: unknown procedural volume 'teapot' (known: "},
      {"/shading/shininess", 0, "shading.shininess: must be > 0, got 0"},
      {"/shading/ambient", -1, "shading.ambient: must be >= 0, got -1"},
      {"/shading/enabled", "yes", "shading.enabled: must be true or false"},
      {"/shading/light_direction", json::array({0, 0, 0}), "shading.light_direction: must not be the zero vector"},
  };
  for (const Case& c : cases) {
    INFO(c.pointer << " = " << c.value.dump());
    json doc = baseDoc();
    doc[json::json_pointer(c.pointer)] = c.value;
    const std::string message = parseError(doc);
    INFO(message);
    CHECK(message.rfind(c.message, 0) == 0);
  }
}

TEST_CASE("structural errors name the section", "[scene]") {
  json doc = baseDoc();
  doc.erase("volume");
  CHECK(parseError(doc) == "volume: missing (every scene names its volume, or its \"volumes\")");

  doc = baseDoc();
  doc["volume"]["file"] = "ct.nhdr";
  CHECK(parseError(doc) == "volume: needs exactly one of 'file' (a volume file), 'procedural' (a generated volume) or "
                          "'computation' (a user computation on the ranks)");
  doc["volume"] = json::object();
  CHECK(parseError(doc).rfind("volume: needs exactly one of", 0) == 0);
  doc["volume"] = {{"file", "ct.nhdr"}, {"dims", {4, 4, 4}}};
  CHECK(parseError(doc) == "volume.dims: only for a procedural or computation volume (a file carries its own)");

  doc = baseDoc();
  doc["transfer_function"]["paraview_preset"] = "bone.json";
  CHECK(parseError(doc).rfind("transfer_function: needs exactly one of 'points', 'paraview_preset'", 0) == 0);

  doc = baseDoc();
  doc["camera"]["projection"] = "orthographic";
  CHECK(parseError(doc) == "camera.height: missing (an orthographic camera needs its view height)");
  doc = baseDoc();
  doc["camera"].erase("eye");
  CHECK(parseError(doc) == "camera.eye: missing (a camera needs eye and look_at)");

  CHECK(parseError(json::array()).rfind("scene: must be an object", 0) == 0);

  pvr::ErrorCode code{};
  doc = baseDoc();
  doc["transfer_function"] = {{"paraview_preset", "missing.json"}};
  CHECK(parseError(doc, &code) == "transfer_function.paraview_preset: /base/missing.json: no such file");
  CHECK(code == pvr::ErrorCode::kIo);
}

TEST_CASE("loadSceneFile names the file in every error", "[scene]") {
  const fs::path dir = scratchDir("scene_load_errors");
  const std::string bad = (dir / "bad_key.json").string();
  json doc = baseDoc();
  doc["camera"]["fov"] = 30;
  writeText(bad, doc.dump());
  try {
    loadSceneFile(bad);
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(std::string(e.what()) ==
          bad + ": camera.fov: unknown key (known: projection, eye, look_at, up, height, fov_y_deg)");
  }

  const std::string notJson = (dir / "not_json.json").string();
  writeText(notJson, "{\"volume\": ");
  try {
    loadSceneFile(notJson);
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(std::string(e.what()).rfind(notJson + ": not valid JSON", 0) == 0);
    CHECK(e.code() == pvr::ErrorCode::kBadFile);
  }

  const std::string missing = (dir / "no_such_scene.json").string();
  try {
    loadSceneFile(missing);
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(std::string(e.what()) == missing + ": no such file");
    CHECK(e.code() == pvr::ErrorCode::kIo);
  }
}

TEST_CASE("parseScene(sceneToJson(s)) gives back s", "[scene]") {
  SECTION("the full example") {
    const Scene s = parseScene(docsFullExample(), "");
    requireSameScene(parseScene(sceneToJson(s), ""), s);
  }
  SECTION("every key set away from its default, through text") {
    Scene s;
    s.volumes.front().source.file = "/data/ct.nhdr";
    s.volumes.front().transfer.points = {{-1000, 0, 0, 0, 0}, {0.1, 0.25, 1.0 / 3.0, 2.5, 0.125}, {0.1, 1, 1, 1, 1}};
    s.volumes.front().transfer.unitDistance = 0.957031;
    s.camera = {Projection::kOrthographic, {1e-3, -7, 2}, {0.5, 0.25, -1}, {0, 1, 1}, 3.75, 45, false};
    s.image = {640, 480, {0.1, 0.2, 0.3, 0.4}};
    s.sampling = {0.1 + 0.2, true, 0.95};
    s.shading = {true, 0.1, 0.6, 0.5, 7.5, {1, 2, 3}};
    const json printed = sceneToJson(s);
    requireSameScene(parseScene(json::parse(printed.dump()), "/elsewhere"), s);
    // Every key of every section is written.
    CHECK(printed["camera"].size() == 6);
    CHECK(printed["image"].size() == 3);
    CHECK(printed["sampling"].size() == 3);
    CHECK(printed["shading"].size() == 6);
    CHECK(printed["transfer_function"].size() == 2);
  }
  SECTION("a procedural volume with spacing and a perspective camera") {
    Scene s;
    s.volumes.front().source.procedural = "shepp-logan";
    s.volumes.front().source.dims = {5, 7, 1};
    s.volumes.front().source.spacing = Vec3{0.5, 0.25, 2};
    s.volumes.front().transfer.points = {{0.5, 1, 0, 0, 0.5}};
    s.camera = {Projection::kPerspective, {0, 0, 9}, {0, 0, 0}, {0, 1, 0}, 0, 12.5, false};
    requireSameScene(parseScene(sceneToJson(s), ""), s);
    CHECK_FALSE(sceneToJson(s)["camera"].contains("height"));
  }
  SECTION("unset values stay unset") {
    const Scene s = parseScene(json::parse(R"({"volume": {"procedural": "shepp-logan"}})"), "");
    const json printed = sceneToJson(s);
    CHECK_FALSE(printed.contains("camera"));
    CHECK_FALSE(printed["sampling"].contains("step"));
    // Left to the data: the transfer function and whether to shade.
    CHECK_FALSE(printed.contains("transfer_function"));
    CHECK_FALSE(printed["shading"].contains("enabled"));
    requireSameScene(parseScene(printed, ""), s);
  }
}

TEST_CASE("every example scene parses", "[scene]") {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kSourceRoot / "examples" / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    INFO(entry.path().string());
    const Scene s = loadSceneFile(entry.path().string());
    CHECK_FALSE(s.volumes.front().transfer.points.empty());
    CHECK((s.volumes.front().source.file.empty() || fs::path(s.volumes.front().source.file).is_absolute()));
    ++count;
  }
  CHECK(count >= 6);

  // The CT scene's relative path reaches the shared data set beside the checkout.
  const Scene ct = loadSceneFile((kSourceRoot / "examples" / "scenes" / "ct_head_bone.json").string());
  const fs::path shared = fs::path(PVR_SHARED_DATA) / "ct_head_cranium" / "ct_head_cranium.json";
  if (fs::exists(shared)) {
    CHECK(fs::equivalent(ct.volumes.front().source.file, shared));
  } else {
    WARN("shared data missing (" << shared.string() << "): path resolution not checked against it");
  }
  CHECK(ct.shading.enabled);
  CHECK(ct.camera.automatic);
}

TEST_CASE("resolveDefaults fills unit distance, step and the automatic camera", "[scene]") {
  GridGeometry grid;
  grid.dims = {65, 33, 17};
  grid.origin = {-1, 2, 3};
  grid.spacing = {0.5, 1, 2};
  const Vec3 center = grid.center();
  const double radius = 0.5 * length(grid.domainMax() - grid.domainMin());

  SECTION("from a scene with only a volume") {
    Scene s = parseScene(json::parse(R"({"volume": {"procedural": "shepp-logan"}})"), "");
    resolveDefaults(s, grid);
    CHECK(s.volumes.front().transfer.unitDistance == 0.5);
    CHECK(s.sampling.step == 0.25);
    CHECK_FALSE(s.camera.automatic);
    CHECK(s.camera.projection == Projection::kPerspective);
    CHECK(s.camera.fovYDeg == 30);
    CHECK(s.camera.up == Vec3{0, 0, 1});
    CHECK(s.camera.lookAt == center);

    // From -y, 30 degrees of azimuth towards +x, 20 degrees up.
    const Vec3 d = s.camera.eye - center;
    const double deg = 180 / std::numbers::pi;
    CHECK(std::asin(d.z / length(d)) * deg == Approx(20));
    CHECK(std::atan2(d.x, -d.y) * deg == Approx(30));
    // Square image: the bounding sphere plus 5 % just fills the 15-degree half angle.
    CHECK(length(d) * std::sin(15 / deg) == Approx(1.05 * radius));
  }

  SECTION("a tall image fits the narrower horizontal field of view") {
    Scene s = parseScene(json::parse(R"({"volume": {"procedural": "shepp-logan"}, "image": {"width": 100, "height": 200}})"), "");
    resolveDefaults(s, grid);
    const double halfFovX = std::atan(std::tan(15 * std::numbers::pi / 180) * 0.5);
    CHECK(length(s.camera.eye - center) * std::sin(halfFovX) == Approx(1.05 * radius));
  }

  SECTION("resolveDefaults and automaticCamera place the same camera") {
    Scene s = parseScene(json::parse(R"({"volume": {"procedural": "shepp-logan"}, "image": {"width": 300, "height": 100}})"), "");
    resolveDefaults(s, grid);
    const CameraSpec a = automaticCamera(grid, 300, 100);
    CHECK(s.camera.eye == a.eye);
    CHECK(s.camera.lookAt == a.lookAt);
    CHECK(s.camera.up == a.up);
    CHECK(s.camera.fovYDeg == a.fovYDeg);
    CHECK(s.camera.projection == a.projection);
    CHECK_FALSE(a.automatic);
  }

  SECTION("given values are kept") {
    Scene s = parseScene(baseDoc(), "");
    const CameraSpec before = s.camera;
    resolveDefaults(s, grid);
    CHECK(s.volumes.front().transfer.unitDistance == 0.1);
    CHECK(s.sampling.step == 0.05);
    CHECK(s.camera.eye == before.eye);
    CHECK(s.camera.lookAt == before.lookAt);
  }

  SECTION("a one-node grid still gets a camera outside it") {
    GridGeometry point;
    Scene s = parseScene(json::parse(R"({"volume": {"procedural": "shepp-logan"}})"), "");
    resolveDefaults(s, point);
    CHECK(length(s.camera.eye - s.camera.lookAt) > 0);
    CHECK(s.sampling.step == 0.5);
  }
}

TEST_CASE("the renderer's image limit: scenes and cameras refuse a side beyond kMaxImageSide", "[scene]") {
  json doc = baseDoc();
  doc["image"]["width"] = kMaxImageSide;
  CHECK(parseScene(doc, "").image.width == kMaxImageSide);
  doc["image"]["width"] = kMaxImageSide + 1;
  CHECK(parseError(doc) == "image.width: must be in 1.." + std::to_string(kMaxImageSide) + ", got " +
                               std::to_string(kMaxImageSide + 1));

  // A program that sizes the image itself (pvr-render --size) meets the same limit in Camera.
  const CameraSpec spec = parseScene(baseDoc(), "").camera;
  CHECK(Camera(spec, kMaxImageSide, 1).width() == kMaxImageSide);
  for (const auto& [w, h] : {std::pair{kMaxImageSide + 1, 1}, std::pair{1, kMaxImageSide + 1}, std::pair{0, 1}}) {
    try {
      Camera(spec, w, h);
      FAIL("no error for " << w << " x " << h);
    } catch (const pvr::Error& e) {
      CHECK(std::string(e.what()) == "camera: image of " + std::to_string(w) + " x " + std::to_string(h) +
                                         " pixels: each side must be in 1.." + std::to_string(kMaxImageSide));
    }
  }
}

TEST_CASE("parseCameraSection(cameraSectionToJson(c)) gives back c", "[scene]") {
  for (const CameraSpec& c : {CameraSpec{Projection::kOrthographic, {1, 2, 3}, {0, 0.5, 0}, {0, 0, 1}, 4.5, 30, false},
                              CameraSpec{Projection::kPerspective, {0, -3, 0}, {0, 0, 0}, {1, 0, 1}, 0, 12.5, false}}) {
    const CameraSpec back = parseCameraSection(json::parse(cameraSectionToJson(c).dump()));
    CHECK(back.projection == c.projection);
    CHECK(back.eye == c.eye);
    CHECK(back.lookAt == c.lookAt);
    CHECK(back.up == c.up);
    CHECK(back.height == c.height);
    CHECK(back.fovYDeg == c.fovYDeg);
    CHECK_FALSE(back.automatic);
  }
}

TEST_CASE("a scene without a transfer function gets a white ramp over the data's range", "[scene]") {
  Scene s = parseScene(json::parse(R"({"volume": {"file": "ct.nhdr"}})"), "");
  TransferFunctionSpec& tf = s.volumes.front().transfer;
  CHECK(tf.automatic);
  // Printed, it stays left to the data.
  CHECK_FALSE(sceneToJson(s).contains("transfer_function"));
  // A CT in Hounsfield units: transparent air, opaque metal.
  resolveDataDefaults(tf, -1024, 2986);
  CHECK_FALSE(tf.automatic);
  REQUIRE(tf.points.size() == 3);
  CHECK(tf.points[0].scalar == -1024);
  CHECK(tf.points[0].opacity == 0);
  // Clear up to the first tenth of the range (air and noise), then rising.
  CHECK(tf.points[1].scalar == Approx(-1024 + 401));
  CHECK(tf.points[1].opacity == 0);
  CHECK(tf.points[2].scalar == 2986);
  CHECK(tf.points[2].opacity == 1);
  CHECK((tf.points[2].r == 1 && tf.points[2].g == 1 && tf.points[2].b == 1));
  // Once resolved it stays: another range changes nothing.
  resolveDataDefaults(tf, 0, 1);
  CHECK(tf.points[2].scalar == 2986);
  // A constant volume still gets a ramp that rises.
  CHECK(rampTransfer(5, 5).points[2].scalar == 6);
}

TEST_CASE("control points are absolute, a preset is stretched onto the data unless absolute", "[scene]") {
  const json preset = json::parse(R"([{"RGBPoints": [0, 0, 0, 0, 0.5, 1, 0, 0, 1, 1, 1, 1]}])");
  Scene stretched = parseScene({{"volume", {{"file", "ct.nhdr"}}}, {"transfer_function", {{"paraview", preset}}}}, "");
  resolveDataDefaults(stretched.volumes.front().transfer, -1000, 3000);
  const auto& p = stretched.volumes.front().transfer.points;
  REQUIRE(p.size() == 3);
  CHECK(p[0].scalar == -1000);
  CHECK(p[1].scalar == Approx(1000));
  CHECK(p[2].scalar == 3000);

  Scene absolute = parseScene(
      {{"volume", {{"file", "ct.nhdr"}}}, {"transfer_function", {{"paraview", preset}, {"absolute", true}}}}, "");
  resolveDataDefaults(absolute.volumes.front().transfer, -1000, 3000);
  CHECK(absolute.volumes.front().transfer.points.back().scalar == 1);

  Scene points = parseScene(
      json::parse(R"({"volume": {"file": "ct.nhdr"}, "transfer_function": {"points": [[0, 1, 1, 1, 0], [1, 1, 1, 1, 1]]}})"), "");
  resolveDataDefaults(points.volumes.front().transfer, -1000, 3000);
  CHECK(points.volumes.front().transfer.points.back().scalar == 1);

  // Printed before the data is known, a preset still to stretch says so and reads back the same.
  const Scene again = parseScene(sceneToJson(parseScene({{"volume", {{"file", "ct.nhdr"}}},
                                                         {"transfer_function", {{"paraview", preset}}}}, "")), "");
  CHECK(again.volumes.front().transfer.rescaleToData);
}

TEST_CASE("shading left to the data is on for 3-D volumes, off for a slice, as set when set", "[scene]") {
  GridGeometry volume;
  volume.dims = {8, 8, 8};
  GridGeometry slice;
  slice.dims = {8, 8, 1};
  Scene s = parseScene(json::parse(R"({"volume": {"file": "ct.nhdr"}})"), "");
  CHECK(s.shading.automatic);
  CHECK_FALSE(sceneToJson(s)["shading"].contains("enabled"));
  Scene a = s, b = s;
  resolveDefaults(a, volume);
  CHECK(a.shading.enabled);
  resolveDefaults(b, slice);
  CHECK_FALSE(b.shading.enabled);
  Scene off = parseScene(json::parse(R"({"volume": {"file": "ct.nhdr"}, "shading": {"enabled": false}})"), "");
  resolveDefaults(off, volume);
  CHECK_FALSE(off.shading.enabled);
}

// sampling.target_psnr: read, printed back, and refused beside pre-integration.
TEST_CASE("sampling.target_psnr is read, printed and not combined with preintegrated", "[scene]") {
  json doc = baseDoc();
  doc["sampling"]["target_psnr"] = 50;
  const Scene s = parseScene(doc, "");
  CHECK(s.sampling.targetPsnr == 50);
  CHECK(sceneToJson(s)["sampling"]["target_psnr"] == 50);
  CHECK(renderOptionsFor(s).targetPsnr == 50);
  CHECK_FALSE(sceneToJson(parseScene(baseDoc(), ""))["sampling"].contains("target_psnr"));
  doc["sampling"]["preintegrated"] = true;
  CHECK(parseError(doc).rfind("sampling.target_psnr: chooses the step of plain sampling; it cannot be combined "
                              "with preintegrated", 0) == 0);
}
