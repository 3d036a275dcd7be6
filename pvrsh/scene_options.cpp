#include "scene_options.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <fstream>
#include <set>

#include "tcl_util.h"

namespace pvr::tcl {
namespace {

using nlohmann::json;

// Merges `patch` into `target` keeping nulls (they must travel to the
// server, where they delete keys), unlike json::merge_patch.
void mergeKeepingNulls(json& target, const json& patch) {
  if (!patch.is_object() || !target.is_object()) {
    target = patch;
    return;
  }
  for (const auto& [key, value] : patch.items()) {
    if (value.is_object() && target.contains(key) && target[key].is_object())
      mergeKeepingNulls(target[key], value);
    else
      target[key] = value;
  }
}

// The state one option handler works on.
struct Apply {
  Settings& settings;
  SettingsChange& change;
  const std::string& option;  // "-imagesz"
  const std::string& value;   // as given

  void scene(const json& patch) {
    mergeKeepingNulls(change.patch, patch);
    settings.scene.merge_patch(patch);
  }
  std::vector<double> numbers(int count) const { return parseNumbers(option, value, count); }
  double number() const { return numbers(1)[0]; }
  double positive() const {
    const double v = number();
    if (!(v > 0)) argsError(option.substr(1), option + " must be > 0, got '" + value + "'");
    return v;
  }
  json vec3() const {
    const auto v = numbers(3);
    return json::array({v[0], v[1], v[2]});
  }
};

// ---- One handler per option ----

void setDataset(Apply& a) {
  if (a.value.empty()) argsError("DATASET", "-dataset needs a dataset name (see list datasets)");
  a.settings.dataset = a.value;
  a.change.dataset = true;
}

// -cluster ROLE[,RANKS]: ROLE r (render), c (composite) or k (collector).
// The clusters of that role are replaced: one per -group entry, or one.
proto::ClusterRole parseRole(const std::string& option, const std::string& text) {
  const std::string role = text.substr(0, text.find(','));
  if (role == "r" || role == "render") return proto::ClusterRole::kRender;
  if (role == "c" || role == "composite") return proto::ClusterRole::kComposite;
  if (role == "k" || role == "collector") return proto::ClusterRole::kCollector;
  argsError("CLUSTER", option + " needs ROLE[,RANKS] with ROLE r, c or k, got '" + text + "'");
}

void setLayout(Settings& s, proto::ClusterRole role, std::uint32_t ranks, const std::vector<std::uint32_t>& groups) {
  std::vector<proto::ClusterSpec> kept;
  for (const auto& c : s.clusters)
    if (c.role != role) kept.push_back(c);
  for (std::uint32_t g : groups) kept.push_back({role, ranks, g});
  // Render clusters first, then compositing, then the collector.
  std::stable_sort(kept.begin(), kept.end(), [](const auto& x, const auto& y) { return x.role < y.role; });
  s.clusters = kept;
}

void setScalar(Apply& a, const char* section, const char* key, double v) { a.scene({{section, {{key, v}}}}); }

void setImageSize(Apply& a) {
  const auto v = a.numbers(2);
  for (double d : v)
    if (d != std::floor(d) || d < 1 || d > 16384)
      argsError("IMAGESZ", "-imagesz needs two integers in 1..16384 (W,H), got '" + a.value + "'");
  a.scene({{"image", {{"width", int(v[0])}, {"height", int(v[1])}}}});
}

void setBackground(Apply& a) {
  auto v = a.numbers(-1);
  if (v.size() == 3) v.push_back(1.0);
  if (v.size() != 4) argsError("BACKGROUND", "-background needs R,G,B or R,G,B,A, got '" + a.value + "'");
  for (double d : v)
    if (d < 0 || d > 1) argsError("BACKGROUND", "-background components must be in [0, 1], got '" + a.value + "'");
  a.scene({{"image", {{"background", v}}}});
}

void setTransferPoints(Apply& a) {
  const auto v = a.numbers(-1);
  if (v.empty() || v.size() % 5 != 0)
    argsError("TF", "-tf needs control points {scalar r g b opacity} ..., a multiple of 5 numbers, got " +
                        std::to_string(v.size()));
  json points = json::array();
  for (std::size_t i = 0; i < v.size(); i += 5) points.push_back({v[i], v[i + 1], v[i + 2], v[i + 3], v[i + 4]});
  a.scene({{"transfer_function", {{"points", points}}}});
}

void setTransferPreset(Apply& a) { a.scene({{"transfer_function", {{"points", presetPoints(a.value)}}}}); }

void setCamera(Apply& a) {
  if (a.value != "auto") argsError("CAMERA", "-camera takes 'auto' (set -eye, -lookat, -up for a fixed camera)");
  a.scene({{"camera", nullptr}});
}

void setProjection(Apply& a) {
  if (a.value != "perspective" && a.value != "orthographic")
    argsError("PROJECTION", "-projection takes perspective or orthographic, got '" + a.value + "'");
  a.scene({{"camera", {{"projection", a.value}}}});
}

void setStrategy(Apply& a) {
  static const std::set<std::string> known{"binary-swap", "direct-send", "tree", "radix-k", "pipeline"};
  if (!known.count(a.value))
    argsError("STRATEGY", "-strategy takes binary-swap, direct-send, tree, radix-k or pipeline, got '" + a.value + "'");
  a.scene({{"parallel", {{"strategy", a.value}}}});
}

void setDecomposition(Apply& a) {
  if (a.value != "kd" && a.value != "balanced")
    argsError("DECOMPOSITION", "-decomposition takes kd or balanced, got '" + a.value + "'");
  a.scene({{"parallel", {{"decomposition", a.value}}}});
}

struct OptionRow {
  const char* name;  // first field: Tcl_GetIndexFromObjStruct reads it
  void (*apply)(Apply&);
};

const OptionRow kOptions[] = {
    {"-dataset", setDataset},
    {"-cluster", nullptr},  // with -group: handled in applyOptions
    {"-group", nullptr},
    {"-imagesz", setImageSize},
    {"-background", setBackground},
    {"-tf", setTransferPoints},
    {"-tfpreset", setTransferPreset},
    {"-unitdist", [](Apply& a) { setScalar(a, "transfer_function", "unit_distance", a.positive()); }},
    {"-camera", setCamera},
    {"-eye", [](Apply& a) { a.scene({{"camera", {{"eye", a.vec3()}}}}); }},
    {"-lookat", [](Apply& a) { a.scene({{"camera", {{"look_at", a.vec3()}}}}); }},
    {"-up", [](Apply& a) { a.scene({{"camera", {{"up", a.vec3()}}}}); }},
    {"-fov", [](Apply& a) { setScalar(a, "camera", "fov_y_deg", a.positive()); }},
    {"-viewheight", [](Apply& a) { setScalar(a, "camera", "height", a.positive()); }},
    {"-projection", setProjection},
    {"-step", [](Apply& a) { setScalar(a, "sampling", "step", a.positive()); }},
    {"-preintegrated", [](Apply& a) { a.scene({{"sampling", {{"preintegrated", parseBoolean(a.option, a.value)}}}}); }},
    {"-earlyterm", [](Apply& a) { setScalar(a, "sampling", "early_termination", a.positive()); }},
    {"-shading", [](Apply& a) { a.scene({{"shading", {{"enabled", parseBoolean(a.option, a.value)}}}}); }},
    {"-ambient", [](Apply& a) { setScalar(a, "shading", "ambient", a.number()); }},
    {"-diffuse", [](Apply& a) { setScalar(a, "shading", "diffuse", a.number()); }},
    {"-specular", [](Apply& a) { setScalar(a, "shading", "specular", a.number()); }},
    {"-shininess", [](Apply& a) { setScalar(a, "shading", "shininess", a.positive()); }},
    {"-light", [](Apply& a) { a.scene({{"shading", {{"light_direction", a.vec3()}}}}); }},
    {"-strategy", setStrategy},
    {"-decomposition", setDecomposition},
    {nullptr, nullptr}};

void remember(Settings& s, const std::string& option, const std::string& value) {
  for (auto& [k, v] : s.shown)
    if (k == option) {
      v = value;
      return;
    }
  s.shown.emplace_back(option, value);
}

// Linear interpolation of (x, value) points at x, clamped outside; at a jump
// (equal x) `right` picks the last point of that x, otherwise the first.
std::vector<double> evaluate(const std::vector<std::pair<double, std::vector<double>>>& f, double x, bool right) {
  if (x < f.front().first) return f.front().second;
  if (x > f.back().first) return f.back().second;
  std::size_t i = 0;
  while (f[i].first < x) ++i;  // first point at or after x; one exists
  if (f[i].first == x) {
    if (right)
      while (i + 1 < f.size() && f[i + 1].first == x) ++i;
    return f[i].second;
  }
  const auto& [x0, v0] = f[i - 1];
  const auto& [x1, v1] = f[i];
  const double t = (x - x0) / (x1 - x0);
  std::vector<double> out(v0.size());
  for (std::size_t k = 0; k < v0.size(); ++k) out[k] = v0[k] + t * (v1[k] - v0[k]);
  return out;
}

}  // namespace

json presetPoints(const std::string& path) {
  std::ifstream in(path);
  if (!in) argsError("TFPRESET", "-tfpreset: cannot read " + path);
  json doc;
  try {
    doc = json::parse(in);
  } catch (const std::exception& e) {
    argsError("TFPRESET", "-tfpreset: " + path + " is not JSON: " + e.what());
  }
  if (doc.is_array() && !doc.empty()) doc = doc[0];
  const auto bad = [&](const std::string& why) { argsError("TFPRESET", "-tfpreset: " + path + ": " + why); };
  if (!doc.is_object() || !doc.contains("RGBPoints") || !doc["RGBPoints"].is_array()) bad("no RGBPoints array");
  // Colour and opacity as two piecewise-linear functions of the scalar.
  std::vector<std::pair<double, std::vector<double>>> colour, opacity;
  const auto& rgb = doc["RGBPoints"];
  if (rgb.empty() || rgb.size() % 4 != 0) bad("RGBPoints needs x, r, g, b quadruples");
  try {
    for (std::size_t i = 0; i < rgb.size(); i += 4)
      colour.push_back({rgb[i].get<double>(), {rgb[i + 1].get<double>(), rgb[i + 2].get<double>(), rgb[i + 3].get<double>()}});
    if (doc.contains("Points")) {
      const auto& pts = doc["Points"];
      if (!pts.is_array() || pts.empty() || pts.size() % 4 != 0) bad("Points needs x, opacity, midpoint, sharpness quadruples");
      for (std::size_t i = 0; i < pts.size(); i += 4) opacity.push_back({pts[i].get<double>(), {pts[i + 1].get<double>()}});
    } else {
      opacity = {{colour.front().first, {0.0}}, {colour.back().first, {1.0}}};
    }
  } catch (const json::exception&) {
    bad("RGBPoints and Points must hold numbers");
  }
  for (const auto* f : {&colour, &opacity})
    for (std::size_t i = 1; i < f->size(); ++i)
      if ((*f)[i].first < (*f)[i - 1].first) bad("points must be sorted by scalar");

  // One control point per scalar of either function; two where either jumps.
  std::set<double> xs;
  for (const auto& p : colour) xs.insert(p.first);
  for (const auto& p : opacity) xs.insert(p.first);
  json points = json::array();
  for (double x : xs) {
    const auto cl = evaluate(colour, x, false), cr = evaluate(colour, x, true);
    const auto ol = evaluate(opacity, x, false), orr = evaluate(opacity, x, true);
    points.push_back({x, cl[0], cl[1], cl[2], std::clamp(ol[0], 0.0, 1.0)});
    if (cl != cr || ol != orr) points.push_back({x, cr[0], cr[1], cr[2], std::clamp(orr[0], 0.0, 1.0)});
  }
  return points;
}

SettingsChange applyOptions(Tcl_Interp* interp, Settings& settings, int objc, Tcl_Obj* const objv[]) {
  Settings next = settings;
  SettingsChange change;
  std::optional<std::string> cluster, group;
  for (int i = 0; i < objc; i += 2) {
    int index = 0;
    if (Tcl_GetIndexFromObjStruct(interp, objv[i], kOptions, sizeof(OptionRow), "option", 0, &index) != TCL_OK)
      throw TclError({"PVR", "ARGS", "OPTION"}, Tcl_GetStringResult(interp));
    const std::string option = kOptions[index].name;
    if (i + 1 >= objc) argsError("VALUE", "value for \"" + option + "\" missing");
    const std::string value = Tcl_GetString(objv[i + 1]);
    if (option == "-cluster") {
      cluster = value;
    } else if (option == "-group") {
      group = value;
    } else {
      Apply a{next, change, option, value};
      kOptions[index].apply(a);
    }
    remember(next, option, value);
  }
  if (cluster || group) {
    // Figure 5: "-cluster r,16 -group 0,0,1,1" is four render clusters of 16
    // ranks in groups 0, 0, 1, 1; "-cluster c -group 0,0" two compositing
    // clusters sized by the master. -group alone regroups the render clusters.
    proto::ClusterRole role = proto::ClusterRole::kRender;
    std::uint32_t ranks = 0;
    if (cluster) {
      role = parseRole("-cluster", *cluster);
      const auto comma = cluster->find(',');
      if (comma != std::string::npos)
        ranks = std::uint32_t(parseInteger("-cluster", cluster->substr(comma + 1), 1, 1 << 20));
    } else {
      for (const auto& c : next.clusters)
        if (c.role == role) ranks = c.ranks;
    }
    std::vector<std::uint32_t> groups{0};
    if (group) {
      groups.clear();
      for (double g : parseNumbers("-group", *group, -1)) {
        if (g < 0 || g != std::floor(g) || g > 65535) argsError("GROUP", "-group needs group numbers 0,1,..., got '" + *group + "'");
        groups.push_back(std::uint32_t(g));
      }
      if (groups.empty()) argsError("GROUP", "-group needs at least one group number");
    }
    setLayout(next, role, ranks, groups);
    change.layout = true;
  }
  settings = std::move(next);
  return change;
}

std::string shownOption(Tcl_Interp* interp, const Settings& settings, Tcl_Obj* option) {
  int index = 0;
  if (Tcl_GetIndexFromObjStruct(interp, option, kOptions, sizeof(OptionRow), "option", 0, &index) != TCL_OK)
    throw TclError({"PVR", "ARGS", "OPTION"}, Tcl_GetStringResult(interp));
  for (const auto& [k, v] : settings.shown)
    if (k == kOptions[index].name) return v;
  return "";
}

Tcl_Obj* layoutObj(const std::vector<proto::ClusterSpec>& clusters) {
  static const char* const kRoles[] = {"render", "composite", "collector"};
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const auto& c : clusters) {
    Tcl_Obj* item[3] = {Tcl_NewStringObj(kRoles[std::min<int>(int(c.role), 2)], -1), Tcl_NewWideIntObj(c.ranks),
                        Tcl_NewWideIntObj(c.group)};
    Tcl_ListObjAppendElement(nullptr, list, Tcl_NewListObj(3, item));
  }
  return list;
}

Tcl_Obj* jsonToTcl(const nlohmann::json& value) {
  if (value.is_object()) {
    Tcl_Obj* dict = Tcl_NewDictObj();
    for (const auto& [k, v] : value.items()) Tcl_DictObjPut(nullptr, dict, Tcl_NewStringObj(k.c_str(), -1), jsonToTcl(v));
    return dict;
  }
  if (value.is_array()) {
    Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
    for (const auto& v : value) Tcl_ListObjAppendElement(nullptr, list, jsonToTcl(v));
    return list;
  }
  if (value.is_null()) return Tcl_NewObj();
  if (value.is_boolean()) return Tcl_NewBooleanObj(value.get<bool>());
  if (value.is_number_integer()) return Tcl_NewWideIntObj(Tcl_WideInt(value.get<std::int64_t>()));
  if (value.is_number()) return Tcl_NewDoubleObj(value.get<double>());
  const std::string s = value.get<std::string>();
  return Tcl_NewStringObj(s.data(), int(s.size()));
}

}  // namespace pvr::tcl
