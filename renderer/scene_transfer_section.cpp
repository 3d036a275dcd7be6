// The scene's "transfer_function" section: control points, or a ParaView
// preset from a file or inline, and the unit distance.
#include "error.h"
#include "paraview_preset.h"
#include "scene_json.h"
#include "scene_sections.h"

namespace pvr::core {

using namespace scene_json;

namespace {

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
    t.scalar = asNumber(v[i][0], indexPath(p, 0));
    t.r = nonNegative(v[i][1], indexPath(p, 1));
    t.g = nonNegative(v[i][2], indexPath(p, 2));
    t.b = nonNegative(v[i][3], indexPath(p, 3));
    t.opacity = unitInterval(v[i][4], indexPath(p, 4));
    if (!points.empty() && t.scalar < points.back().scalar)
      fail(p, "scalar " + numberText(t.scalar) + " is below the previous point's " +
                  numberText(points.back().scalar) + "; points must be sorted by scalar");
    points.push_back(t);
  }
  return points;
}

// A preset file named by the scene; its errors follow the key path.
TransferFunctionSpec presetFile(const json& v, const std::string& path, const std::string& baseDir) {
  const std::string file = resolvePath(asString(v, path), baseDir);
  try {
    return loadParaViewPreset(file);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

}  // namespace

TransferFunctionSpec parseTransfer(const json& v, const std::string& baseDir, const std::string& path) {
  requireObject(v, path, {"points", "paraview_preset", "paraview", "unit_distance", "absolute"});
  const std::string form = exactlyOneOf(v, path, {"points", "paraview_preset", "paraview"},
                                        "'points', 'paraview_preset' (a preset file) or 'paraview' (a preset inline)");
  const std::string p = childPath(path, form);
  TransferFunctionSpec tf;
  if (form == "points") tf.points = parsePoints(v[form], p);
  else if (form == "paraview_preset") tf = presetFile(v[form], p, baseDir);
  else tf = paraViewPresetFromJson(v[form], p);
  if (const json* u = find(v, "unit_distance")) tf.unitDistance = positive(*u, childPath(path, "unit_distance"));
  // A preset is stretched onto the data's range unless "absolute" keeps its
  // scalars (ParaView's behaviour); control points are absolute unless
  // "absolute": false asks for the same stretch.
  bool absolute = form == "points";
  if (const json* a = find(v, "absolute")) absolute = asBool(*a, childPath(path, "absolute"));
  tf.rescaleToData = !absolute;
  return tf;
}

TransferFunctionSpec defaultTransfer() {
  // A white ramp over the data's range once it is known (resolveDataDefaults);
  // until then over [0, 1], the range of the procedural volumes.
  TransferFunctionSpec tf = rampTransfer(0, 1);
  tf.automatic = true;
  return tf;
}

json transferToJson(const TransferFunctionSpec& transfer) {
  // A preset prints as the points it produced; unit distance 0 ("one
  // voxel") is the absent key.
  json out = {{"points", json::array()}};
  for (const TransferPoint& p : transfer.points)
    out["points"].push_back(json::array({p.scalar, p.r, p.g, p.b, p.opacity}));
  if (transfer.unitDistance > 0) out["unit_distance"] = transfer.unitDistance;
  // A preset not yet stretched onto the data prints as its points, still to stretch.
  if (transfer.rescaleToData) out["absolute"] = false;
  return out;
}

}  // namespace pvr::core
