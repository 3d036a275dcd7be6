// Scene documents: parsing with key-path errors, printing, ParaView presets,
// and the defaults that need the volume's grid.
//
// The reader is strict on purpose: a scene is typed by hand, and a misspelt
// key that silently falls back to a default renders a plausible but wrong
// image. Every key is checked against the keys its object knows, and every
// error names the key path ("camera.fov_y_deg: must be in (0, 180), got 200").
#include "scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "error.h"
#include "io/volume_io.h"

namespace pvr::core {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr int kMaxImageSide = 16384;

// ---------------------------------------------------------------------------
// Typed access to JSON values; every failure names the key path.

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, path.empty() ? what : path + ": " + what);
}

std::string childPath(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string indexPath(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Shortest text that reads back as the same number ("0.1", "200", not "200.0").
std::string numberText(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  if (v == std::trunc(v) && std::abs(v) < 1e15) return std::to_string(std::int64_t(v));
  return json(v).dump();
}

// "string \"abc\"" / "array [1,2]": what the document held instead.
std::string describeValue(const json& v) {
  if (v.is_null()) return "null";
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(v.type_name()) + " " + text;
}

template <typename Range>
std::string joinNames(const Range& names) {
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + std::string(n);
  return list;
}

// Checks that `v` is an object and holds only keys from `known`.
void requireObject(const json& v, const std::string& path,
                   std::initializer_list<const char*> known) {
  if (!v.is_object()) fail(path.empty() ? "scene" : path, "must be an object, got " + describeValue(v));
  for (const auto& item : v.items()) {
    const bool isKnown = std::any_of(known.begin(), known.end(),
                                     [&](const char* k) { return item.key() == k; });
    if (!isKnown) fail(childPath(path, item.key()), "unknown key (known: " + joinNames(known) + ")");
  }
}

const json* find(const json& object, const char* key) {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

// Whether `object` holds key `a` rather than `b`; holding both or neither is
// an error ("volume: needs exactly one of ...").
bool holdsFirstOf(const json& object, const std::string& path, const char* a, const char* b,
                  const std::string& what) {
  const bool hasA = object.contains(a), hasB = object.contains(b);
  if (hasA == hasB) fail(path, "needs exactly one of " + what);
  return hasA;
}

double asNumber(const json& v, const std::string& path) {
  if (!v.is_number()) fail(path, "must be a number, got " + describeValue(v));
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(path, "must be finite, got " + numberText(d));
  return d;
}

std::int64_t asInteger(const json& v, const std::string& path) {
  if (!v.is_number_integer()) fail(path, "must be an integer, got " + describeValue(v));
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(INT64_MAX))
    fail(path, "is too large, got " + v.dump());
  return v.get<std::int64_t>();
}

bool asBool(const json& v, const std::string& path) {
  if (!v.is_boolean()) fail(path, "must be true or false, got " + describeValue(v));
  return v.get<bool>();
}

std::string asString(const json& v, const std::string& path) {
  if (!v.is_string()) fail(path, "must be a string, got " + describeValue(v));
  return v.get<std::string>();
}

Vec3 asVec3(const json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3) fail(path, "must be an array of 3 numbers, got " + describeValue(v));
  return {asNumber(v[0], indexPath(path, 0)), asNumber(v[1], indexPath(path, 1)),
          asNumber(v[2], indexPath(path, 2))};
}

double positive(const json& v, const std::string& path) {
  const double d = asNumber(v, path);
  if (!(d > 0)) fail(path, "must be > 0, got " + numberText(d));
  return d;
}

double nonNegative(const json& v, const std::string& path) {
  const double d = asNumber(v, path);
  if (!(d >= 0)) fail(path, "must be >= 0, got " + numberText(d));
  return d;
}

double unitInterval(const json& v, const std::string& path) {
  const double d = asNumber(v, path);
  if (!(d >= 0 && d <= 1)) fail(path, "must be in [0, 1], got " + numberText(d));
  return d;
}

json toJson(Vec3 v) { return json::array({v.x, v.y, v.z}); }

// A relative path names a file beside the scene (or preset) that mentions it.
std::string resolvePath(const std::string& file, const std::string& baseDir) {
  const fs::path p(file);
  if (p.is_absolute() || baseDir.empty()) return file;
  return (fs::path(baseDir) / p).lexically_normal().string();
}

json readJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, path + ": cannot open for reading");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::kIo, path + ": read failed");
  try {
    return json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw Error(ErrorCode::kBadFile, path + ": not valid JSON: " + e.what());
  }
}

// ---------------------------------------------------------------------------
// Sections of the scene document.

VolumeSpec parseVolume(const json& v, const std::string& baseDir) {
  const std::string path = "volume";
  requireObject(v, path, {"file", "procedural", "dims", "spacing"});
  VolumeSpec spec;
  if (holdsFirstOf(v, path, "file", "procedural",
                   "'file' (a volume file) or 'procedural' (a generated volume)")) {
    for (const char* key : {"dims", "spacing"})
      if (find(v, key)) fail(childPath(path, key), "only for a procedural volume (a file carries its own)");
    spec.file = asString(v["file"], path + ".file");
    if (spec.file.empty()) fail(path + ".file", "must not be empty");
    spec.file = resolvePath(spec.file, baseDir);
    return spec;
  }

  spec.procedural = asString(v["procedural"], path + ".procedural");
  const std::vector<std::string> names = proceduralNames();
  if (std::find(names.begin(), names.end(), spec.procedural) == names.end())
    fail(path + ".procedural",
         "unknown procedural volume '" + spec.procedural + "' (known: " + joinNames(names) + ")");
  if (const json* dims = find(v, "dims")) {
    const std::string p = path + ".dims";
    if (!dims->is_array() || dims->size() != 3)
      fail(p, "must be an array of 3 integers, got " + describeValue(*dims));
    for (int a = 0; a < 3; ++a) {
      const std::int64_t d = asInteger((*dims)[a], indexPath(p, a));
      if (d < 1 || d > INT32_MAX)
        fail(indexPath(p, a), "must be in 1.." + std::to_string(INT32_MAX) + ", got " + std::to_string(d));
      spec.dims[a] = d;
    }
  }
  if (const json* spacing = find(v, "spacing")) {
    const std::string p = path + ".spacing";
    const Vec3 s = asVec3(*spacing, p);
    for (int a = 0; a < 3; ++a)
      if (!(s[a] > 0)) fail(indexPath(p, a), "must be > 0, got " + numberText(s[a]));
    spec.spacing = s;
  }
  return spec;
}

// Control points [[scalar, r, g, b, opacity], ...], sorted by scalar.
std::vector<TransferPoint> parsePoints(const json& v, const std::string& path) {
  if (!v.is_array()) fail(path, "must be an array of [scalar, r, g, b, opacity], got " + describeValue(v));
  if (v.empty()) fail(path, "needs at least one point");
  std::vector<TransferPoint> points;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = indexPath(path, i);
    if (!v[i].is_array() || v[i].size() != 5)
      fail(p, "must be [scalar, r, g, b, opacity], got " + describeValue(v[i]));
    TransferPoint t;
    t.scalar = asNumber(v[i][0], p + "[0]");
    t.r = nonNegative(v[i][1], p + "[1]");
    t.g = nonNegative(v[i][2], p + "[2]");
    t.b = nonNegative(v[i][3], p + "[3]");
    t.opacity = unitInterval(v[i][4], p + "[4]");
    if (!points.empty() && t.scalar < points.back().scalar)
      fail(p, "scalar " + numberText(t.scalar) + " is below the previous point's " +
                  numberText(points.back().scalar) + "; points must be sorted by scalar");
    points.push_back(t);
  }
  return points;
}

// The transfer function of a scene that names none: a white ramp over the
// range of the procedural volumes, [0, 1].
TransferFunctionSpec defaultTransfer() {
  TransferFunctionSpec tf;
  tf.points = {{0, 1, 1, 1, 0}, {1, 1, 1, 1, 1}};
  return tf;
}

TransferFunctionSpec parseTransfer(const json& v, const std::string& baseDir) {
  const std::string path = "transfer_function";
  requireObject(v, path, {"points", "paraview_preset", "unit_distance"});
  TransferFunctionSpec tf;
  if (holdsFirstOf(v, path, "points", "paraview_preset", "'points' or 'paraview_preset'")) {
    tf.points = parsePoints(v["points"], path + ".points");
  } else {
    const std::string p = path + ".paraview_preset";
    const std::string file = resolvePath(asString(v["paraview_preset"], p), baseDir);
    try {
      tf = loadParaViewPreset(file);
    } catch (const Error& e) {
      throw Error(e.code(), p + ": " + e.what());
    }
  }
  if (const json* u = find(v, "unit_distance")) tf.unitDistance = positive(*u, path + ".unit_distance");
  return tf;
}

CameraSpec parseCamera(const json& v) {
  const std::string path = "camera";
  requireObject(v, path, {"projection", "eye", "look_at", "up", "height", "fov_y_deg"});
  CameraSpec cam;
  cam.automatic = false;

  if (const json* p = find(v, "projection")) {
    const std::string name = asString(*p, path + ".projection");
    if (name == "orthographic") cam.projection = Projection::kOrthographic;
    else if (name == "perspective") cam.projection = Projection::kPerspective;
    else fail(path + ".projection", "must be \"orthographic\" or \"perspective\", got \"" + name + "\"");
  }
  for (const char* key : {"eye", "look_at"})
    if (!find(v, key)) fail(childPath(path, key), "missing (a camera needs eye and look_at)");
  cam.eye = asVec3(v["eye"], path + ".eye");
  cam.lookAt = asVec3(v["look_at"], path + ".look_at");
  if (const json* up = find(v, "up")) cam.up = asVec3(*up, path + ".up");

  // The key the projection does not use is still checked and kept, so a
  // document can switch projection by one word and print back unchanged.
  if (const json* h = find(v, "height")) cam.height = positive(*h, path + ".height");
  if (const json* f = find(v, "fov_y_deg")) {
    cam.fovYDeg = asNumber(*f, path + ".fov_y_deg");
    if (!(cam.fovYDeg > 0 && cam.fovYDeg < 180))
      fail(path + ".fov_y_deg", "must be in (0, 180), got " + numberText(cam.fovYDeg));
  }
  if (cam.projection == Projection::kOrthographic && !find(v, "height"))
    fail(path + ".height", "missing (an orthographic camera needs its view height)");

  // Geometry the camera basis needs: a view direction and an up not along it.
  const Vec3 dir = cam.lookAt - cam.eye;
  if (!(length(dir) > 0)) fail(path + ".eye", "must differ from camera.look_at");
  if (!(length(cam.up) > 0)) fail(path + ".up", "must not be the zero vector");
  const double sine = length(cross(normalize(dir), normalize(cam.up)));
  if (!(sine > 1e-6)) fail(path + ".up", "must not be parallel to the view direction (look_at - eye)");
  return cam;
}

ImageSpec parseImage(const json& v) {
  const std::string path = "image";
  requireObject(v, path, {"width", "height", "background"});
  ImageSpec img;
  auto side = [&](const char* key, int& out) {
    const json* k = find(v, key);
    if (!k) return;
    const std::string p = childPath(path, key);
    const std::int64_t n = asInteger(*k, p);
    if (n < 1 || n > kMaxImageSide)
      fail(p, "must be in 1.." + std::to_string(kMaxImageSide) + ", got " + std::to_string(n));
    out = int(n);
  };
  side("width", img.width);
  side("height", img.height);
  if (const json* bg = find(v, "background")) {
    const std::string p = path + ".background";
    if (!bg->is_array() || bg->size() != 4)
      fail(p, "must be an array of 4 numbers [r, g, b, a], got " + describeValue(*bg));
    for (std::size_t i = 0; i < 4; ++i) img.background[i] = unitInterval((*bg)[i], indexPath(p, i));
  }
  return img;
}

SamplingSpec parseSampling(const json& v) {
  const std::string path = "sampling";
  requireObject(v, path, {"step", "preintegrated", "early_termination"});
  SamplingSpec s;
  if (const json* k = find(v, "step")) s.step = positive(*k, path + ".step");
  if (const json* k = find(v, "preintegrated")) s.preintegrated = asBool(*k, path + ".preintegrated");
  if (const json* k = find(v, "early_termination")) {
    s.earlyTermination = asNumber(*k, path + ".early_termination");
    if (!(s.earlyTermination > 0 && s.earlyTermination <= 1))
      fail(path + ".early_termination", "must be in (0, 1], got " + numberText(s.earlyTermination));
  }
  return s;
}

ShadingSpec parseShading(const json& v) {
  const std::string path = "shading";
  requireObject(v, path, {"enabled", "ambient", "diffuse", "specular", "shininess", "light_direction"});
  ShadingSpec s;
  if (const json* k = find(v, "enabled")) s.enabled = asBool(*k, path + ".enabled");
  if (const json* k = find(v, "ambient")) s.ambient = nonNegative(*k, path + ".ambient");
  if (const json* k = find(v, "diffuse")) s.diffuse = nonNegative(*k, path + ".diffuse");
  if (const json* k = find(v, "specular")) s.specular = nonNegative(*k, path + ".specular");
  if (const json* k = find(v, "shininess")) s.shininess = positive(*k, path + ".shininess");
  if (const json* k = find(v, "light_direction")) {
    s.lightDirection = asVec3(*k, path + ".light_direction");
    if (!(length(s.lightDirection) > 0)) fail(path + ".light_direction", "must not be the zero vector");
  }
  return s;
}

// ---------------------------------------------------------------------------
// ParaView presets.

// A piecewise-linear function of the scalar with K components, given by
// knots sorted by x. Equal x are allowed and make a jump; outside the knots
// the function is clamped. left/right are the limits from below and above,
// equal except at a jump.
template <std::size_t K>
struct PiecewiseLinear {
  std::vector<double> x;
  std::vector<std::array<double, K>> y;

  std::array<double, K> left(double s) const {
    if (s <= x.front()) return y.front();
    if (s > x.back()) return y.back();
    const std::size_t i = std::size_t(std::lower_bound(x.begin(), x.end(), s) - x.begin());
    return x[i] == s ? y[i] : lerp(i - 1, s);
  }
  std::array<double, K> right(double s) const {
    if (s < x.front()) return y.front();
    if (s >= x.back()) return y.back();
    const std::size_t j = std::size_t(std::upper_bound(x.begin(), x.end(), s) - x.begin()) - 1;
    return x[j] == s ? y[j] : lerp(j, s);
  }

 private:
  // Between knots i and i + 1, which differ in x.
  std::array<double, K> lerp(std::size_t i, double s) const {
    const double t = (s - x[i]) / (x[i + 1] - x[i]);
    std::array<double, K> out;
    for (std::size_t c = 0; c < K; ++c) out[c] = y[i][c] + t * (y[i + 1][c] - y[i][c]);
    return out;
  }
};

// Reads a flat array of groups of `stride` numbers ("RGBPoints", "Points").
std::vector<std::vector<double>> readGroups(const json& preset, const char* key, std::size_t stride,
                                            const std::string& where) {
  const json& v = preset[key];
  const std::string p = where + key;
  if (!v.is_array() || v.empty() || v.size() % stride != 0)
    throw Error(ErrorCode::kBadFile, p + ": must be a non-empty array of " + std::to_string(stride) +
                                         "-number groups, got " + describeValue(v));
  std::vector<std::vector<double>> groups;
  for (std::size_t i = 0; i < v.size(); i += stride) {
    std::vector<double> g;
    for (std::size_t c = 0; c < stride; ++c) {
      if (!v[i + c].is_number() || !std::isfinite(v[i + c].get<double>()))
        throw Error(ErrorCode::kBadFile, indexPath(p, i + c) + ": must be a finite number, got " +
                                             describeValue(v[i + c]));
      g.push_back(v[i + c].get<double>());
    }
    if (!groups.empty() && g[0] < groups.back()[0])
      throw Error(ErrorCode::kBadFile, indexPath(p, i) + ": scalar " + numberText(g[0]) +
                                           " is below the previous one; points must be sorted");
    groups.push_back(std::move(g));
  }
  return groups;
}

}  // namespace

TransferFunctionSpec loadParaViewPreset(const std::string& path) {
  const json doc = readJsonFile(path);
  const std::string where = path + ": ";

  // Pick the preset: the document itself, or the first of an array.
  if (doc.is_array() && doc.empty()) throw Error(ErrorCode::kBadFile, where + "empty preset array");
  const json& preset = doc.is_array() ? doc.front() : doc;
  if (!preset.is_object())
    throw Error(ErrorCode::kBadFile, where + "not a ParaView preset (need an object or an array of objects)");
  if (!preset.contains("RGBPoints"))
    throw Error(ErrorCode::kBadFile, where + "no \"RGBPoints\": not a colour transfer-function preset");

  // Colour: x, r, g, b groups.
  PiecewiseLinear<3> colour;
  for (const auto& g : readGroups(preset, "RGBPoints", 4, where)) {
    for (std::size_t c = 1; c < 4; ++c)
      if (g[c] < 0)
        throw Error(ErrorCode::kBadFile, where + "RGBPoints: colour component " + numberText(g[c]) +
                                             " at scalar " + numberText(g[0]) + " is negative");
    colour.x.push_back(g[0]);
    colour.y.push_back({g[1], g[2], g[3]});
  }

  // Opacity: x, opacity, midpoint, sharpness groups. Midpoint and sharpness
  // shape ParaView's curve between points; here every segment is linear.
  PiecewiseLinear<1> opacity;
  if (preset.contains("Points")) {
    for (const auto& g : readGroups(preset, "Points", 4, where)) {
      if (!(g[1] >= 0 && g[1] <= 1))
        throw Error(ErrorCode::kBadFile, where + "Points: opacity " + numberText(g[1]) + " at scalar " +
                                             numberText(g[0]) + " is outside [0, 1]");
      opacity.x.push_back(g[0]);
      opacity.y.push_back({g[1]});
    }
  } else {
    opacity.x = {colour.x.front(), colour.x.back()};
    opacity.y = {{0.0}, {1.0}};
  }

  // Merge: both functions evaluated at the union of their knots; a jump in
  // either becomes two points at the same scalar.
  std::vector<double> xs = colour.x;
  xs.insert(xs.end(), opacity.x.begin(), opacity.x.end());
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  TransferFunctionSpec tf;
  for (double s : xs) {
    const auto cl = colour.left(s), cr = colour.right(s);
    const auto ol = opacity.left(s), orr = opacity.right(s);
    tf.points.push_back({s, cl[0], cl[1], cl[2], ol[0]});
    if (cl != cr || ol != orr) tf.points.push_back({s, cr[0], cr[1], cr[2], orr[0]});
  }
  return tf;
}

Scene parseScene(const json& doc, const std::string& baseDir) {
  requireObject(doc, "", {"volume", "transfer_function", "camera", "image", "sampling", "shading"});
  Scene scene;
  const json* volume = find(doc, "volume");
  if (!volume) fail("volume", "missing (every scene names its volume)");
  scene.volume = parseVolume(*volume, baseDir);
  const json* tf = find(doc, "transfer_function");
  scene.transfer = tf ? parseTransfer(*tf, baseDir) : defaultTransfer();
  if (const json* v = find(doc, "camera")) scene.camera = parseCamera(*v);
  if (const json* v = find(doc, "image")) scene.image = parseImage(*v);
  if (const json* v = find(doc, "sampling")) scene.sampling = parseSampling(*v);
  if (const json* v = find(doc, "shading")) scene.shading = parseShading(*v);
  return scene;
}

Scene loadSceneFile(const std::string& path) {
  const json doc = readJsonFile(path);
  // Absolute, so the paths it resolves stay valid wherever the scene goes next.
  const std::string baseDir = fs::absolute(fs::path(path)).parent_path().string();
  try {
    return parseScene(doc, baseDir);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

json sceneToJson(const Scene& s) {
  json doc;

  // Volume.
  json& volume = doc["volume"];
  if (!s.volume.file.empty()) {
    volume["file"] = s.volume.file;
  } else {
    volume["procedural"] = s.volume.procedural;
    volume["dims"] = json::array({s.volume.dims.x, s.volume.dims.y, s.volume.dims.z});
    if (s.volume.spacing) volume["spacing"] = toJson(*s.volume.spacing);
  }

  // Transfer function; unit distance 0 ("one voxel") is the absent key.
  json& tf = doc["transfer_function"];
  tf["points"] = json::array();
  for (const TransferPoint& p : s.transfer.points)
    tf["points"].push_back(json::array({p.scalar, p.r, p.g, p.b, p.opacity}));
  if (s.transfer.unitDistance > 0) tf["unit_distance"] = s.transfer.unitDistance;

  // Camera; an automatic camera is the absent section. Height 0 of a
  // perspective camera means "not given".
  if (!s.camera.automatic) {
    json& cam = doc["camera"];
    cam["projection"] = s.camera.projection == Projection::kOrthographic ? "orthographic" : "perspective";
    cam["eye"] = toJson(s.camera.eye);
    cam["look_at"] = toJson(s.camera.lookAt);
    cam["up"] = toJson(s.camera.up);
    cam["fov_y_deg"] = s.camera.fovYDeg;
    if (s.camera.height > 0 || s.camera.projection == Projection::kOrthographic)
      cam["height"] = s.camera.height;
  }

  doc["image"] = {{"width", s.image.width},
                  {"height", s.image.height},
                  {"background", s.image.background}};

  // Sampling; step 0 ("half a voxel") is the absent key.
  json& sampling = doc["sampling"];
  if (s.sampling.step > 0) sampling["step"] = s.sampling.step;
  sampling["preintegrated"] = s.sampling.preintegrated;
  sampling["early_termination"] = s.sampling.earlyTermination;

  doc["shading"] = {{"enabled", s.shading.enabled},
                    {"ambient", s.shading.ambient},
                    {"diffuse", s.shading.diffuse},
                    {"specular", s.shading.specular},
                    {"shininess", s.shading.shininess},
                    {"light_direction", toJson(s.shading.lightDirection)}};
  return doc;
}

void resolveDefaults(Scene& scene, const GridGeometry& grid) {
  grid.validate("volume");
  const double voxel = grid.minSpacing();
  if (scene.transfer.unitDistance == 0) scene.transfer.unitDistance = voxel;
  if (scene.sampling.step == 0) scene.sampling.step = 0.5 * voxel;
  if (!scene.camera.automatic) return;

  // Fit the domain's bounding sphere, plus a margin, into the narrower of
  // the two fields of view. A one-node domain is a point: give it half a voxel.
  constexpr double kFovYDeg = 30, kElevationDeg = 20, kAzimuthDeg = 30, kMargin = 1.05;
  constexpr double kDeg = std::numbers::pi / 180;
  const double radius = kMargin * std::max(0.5 * length(grid.domainMax() - grid.domainMin()), 0.5 * voxel);
  const double halfFovY = 0.5 * kFovYDeg * kDeg;
  const double aspect = double(scene.image.width) / double(scene.image.height);
  const double halfFovX = std::atan(std::tan(halfFovY) * aspect);
  const double distance = radius / std::sin(std::min(halfFovY, halfFovX));

  // From the -y side, turned by the azimuth about +z towards +x, raised by the elevation.
  const double el = kElevationDeg * kDeg, az = kAzimuthDeg * kDeg;
  const Vec3 towardsEye{std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az), std::sin(el)};

  CameraSpec& cam = scene.camera;
  cam.projection = Projection::kPerspective;
  cam.fovYDeg = kFovYDeg;
  cam.lookAt = grid.center();
  cam.eye = cam.lookAt + towardsEye * distance;
  cam.up = {0, 0, 1};
  cam.height = 0;
  cam.automatic = false;
}

}  // namespace pvr::core
