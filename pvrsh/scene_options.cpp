#include "scene_options.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <string_view>

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
  const ServerNames& serverNames;
  bool absolute = false;  // -tfpreset only: "-absolute" followed its value
  std::string parameterValue;  // -param only: the word after NAME

  void scene(const json& patch) {
    mergeKeepingNulls(change.patch, patch);
    settings.scene.merge_patch(patch);
  }
  // A camera move goes out once, in the order given; the server applies it
  // to the camera in force (docs/scene.md, "Moving the camera").
  void cameraMove(const json& move) {
    change.patch["camera_moves"].push_back(move);
    settings.cameraMoves.push_back(move);
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

// -dataset NAME: exactly this one volume (docs/pvrsh.md, "Several
// volumes"): a volume list set with `volume add` goes.
void setDataset(Apply& a) {
  if (a.value.empty()) argsError("DATASET", "-dataset needs a dataset name (see list datasets)");
  if (a.settings.scene.contains("volumes")) a.scene({{"volumes", nullptr}});
  a.settings.scene.erase("volume");  // a -computation before: the dataset replaces it
  a.settings.dataset = a.value;
  a.change.dataset = true;
  a.change.datasetName = a.value;
}

// -computation NAME?,NX,NY,NZ?: a user computation run on the ranks in
// place of a dataset (docs/steering.md), on a grid of NX x NY x NZ nodes
// (default 64 each). Which computations exist is the server's to say.
void setComputation(Apply& a) {
  const auto comma = a.value.find(',');
  const std::string name = a.value.substr(0, comma);
  if (name.empty()) argsError("COMPUTATION", "-computation needs a computation name (list status: computation)");
  json dims = nullptr;
  if (comma != std::string::npos) {
    const auto n = parseNumbers("-computation", a.value.substr(comma + 1), 3);
    dims = json::array();
    for (double d : n) {
      if (d < 1 || d != std::floor(d) || d > INT32_MAX)
        argsError("COMPUTATION", "-computation NAME,NX,NY,NZ needs whole node counts >= 1, got '" + a.value + "'");
      dims.push_back(std::int64_t(d));
    }
  }
  a.settings.dataset.clear();
  a.scene({{"volume", {{"computation", name}, {"dims", dims}, {"file", nullptr}, {"procedural", nullptr}}}});
}

// The Tcl list {name default min max help} of each parameter the server's
// computation declares (status key parameter_ranges), or nullopt.
std::optional<std::vector<std::string>> parameterRow(const ServerNames& names, const std::string& parameter) {
  const auto rows = names ? names("parameter_ranges") : std::nullopt;
  if (!rows) return std::nullopt;
  for (const std::string& row : *rows) {
    int count = 0;
    const char** items = nullptr;
    if (Tcl_SplitList(nullptr, row.c_str(), &count, &items) != TCL_OK) continue;
    std::vector<std::string> fields(items, items + count);
    Tcl_Free(reinterpret_cast<char*>(items));
    if (fields.size() == 5 && fields[0] == parameter) return fields;
  }
  return std::vector<std::string>{};
}

// -param NAME VALUE: the computation's steering parameter NAME ("parameters"
// of the scene). With a session open and idle, NAME and the range come from
// the server's status for a clear error here; otherwise the server refuses
// a name or value it does not take, naming the parameter and its range.
void setParameter(Apply& a) {
  if (a.value.empty()) argsError("PARAM", "-param needs NAME VALUE");
  const double v = parseNumbers("-param " + a.value, a.parameterValue, 1)[0];
  if (const auto row = parameterRow(a.serverNames, a.value)) {
    if (row->empty()) {
      std::string known;
      for (const std::string& r : a.serverNames("parameter_ranges").value_or(std::vector<std::string>{}))
        known += (known.empty() ? "" : ", ") + r.substr(0, r.find(' '));
      argsError("PARAM", "-param " + a.value + ": the computation has no such parameter" +
                             (known.empty() ? std::string(" (no computation volume is set)") : " (its parameters: " + known + ")"));
    }
    const double lo = std::stod((*row)[2]), hi = std::stod((*row)[3]);
    if (!(v >= lo && v <= hi))
      argsError("PARAM", "-param " + a.value + " " + a.parameterValue + ": outside the range [" + (*row)[2] + ", " +
                             (*row)[3] + "] of parameter '" + a.value + "'");
  }
  a.scene({{"parameters", {{a.value, v}}}});
}

// -cluster ROLE[,RANKS]: ROLE r (render), c (composite), k (collector) or
// m (cache: reads time steps ahead for the render clusters).
// The clusters of that role are replaced: one per -group entry, or one.
proto::ClusterRole parseRole(const std::string& option, const std::string& text) {
  const std::string role = text.substr(0, text.find(','));
  if (role == "r" || role == "render") return proto::ClusterRole::kRender;
  if (role == "c" || role == "composite") return proto::ClusterRole::kComposite;
  if (role == "k" || role == "collector") return proto::ClusterRole::kCollector;
  if (role == "m" || role == "cache") return proto::ClusterRole::kCache;
  argsError("CLUSTER", option + " needs ROLE[,RANKS] with ROLE r, c, k or m, got '" + text + "'");
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

// The frames of a session are rgba8: the node's default pixel format
// (docs/runtime.md, runtime.pixels), which pvrsh never changes.
constexpr proto::PixelFormat kSessionPixelFormat = proto::PixelFormat::kRgba8;

// -imagesz W,H: any size the protocol's one rule for image sizes accepts.
void setImageSize(Apply& a) {
  const auto v = a.numbers(2);
  for (double d : v)
    if (d != std::floor(d)) argsError("IMAGESZ", "-imagesz needs two integers (W,H), got '" + a.value + "'");
  // Past 2^53 a double is no longer every integer; checkImageSize refuses far less.
  const auto side = [](double d) { return d < 0 ? 0 : std::uint64_t(std::min(d, 9007199254740992.0)); };
  if (const auto error = proto::checkImageSize(side(v[0]), side(v[1]), kSessionPixelFormat))
    argsError("IMAGESZ", "-imagesz " + a.value + ": " + error->text);
  a.scene({{"image", {{"width", std::int64_t(v[0])}, {"height", std::int64_t(v[1])}}}});
}

void setBackground(Apply& a) {
  auto v = a.numbers(-1);
  if (v.size() == 3) v.push_back(1.0);
  if (v.size() != 4) argsError("BACKGROUND", "-background needs R,G,B or R,G,B,A, got '" + a.value + "'");
  for (double d : v)
    if (d < 0 || d > 1) argsError("BACKGROUND", "-background components must be in [0, 1], got '" + a.value + "'");
  a.scene({{"image", {{"background", v}}}});
}

// A transfer function has exactly one source (docs/scene.md): setting one
// deletes the others, so a merge patch never leaves two behind.
json transferSource(const char* key, json value) {
  json tf = {{"points", nullptr}, {"paraview_preset", nullptr}, {"paraview", nullptr}, {"absolute", nullptr}};
  tf[key] = std::move(value);
  return {{"transfer_function", tf}};
}

void setTransferPoints(Apply& a) {
  const auto v = parseListNumbers(a.option, a.value);
  if (v.empty() || v.size() % 5 != 0)
    argsError("TF", "-tf needs control points {scalar r g b opacity} ..., a multiple of 5 numbers, got " +
                        std::to_string(v.size()));
  json points = json::array();
  for (std::size_t i = 0; i < v.size(); i += 5) points.push_back({v[i], v[i + 1], v[i + 2], v[i + 3], v[i + 4]});
  a.scene(transferSource("points", points));
}

// -tfpreset FILE: the file's JSON goes to the server as it is, and the
// renderer's one preset reader reads it there (docs/scene.md, "ParaView
// presets"). A preset object is sent as a one-element array, a form the
// reader takes too, because a merge patch replaces an array whole where it
// would merge an object into the preset set before.
void setTransferPreset(Apply& a) {
  std::ifstream in(a.value);
  if (!in) argsError("TFPRESET", "-tfpreset: cannot read " + a.value);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // It goes to the server, which refuses deeper JSON: say so here.
  if (auto deep = proto::checkJsonDepth(text, "-tfpreset " + a.value)) argsError("TFPRESET", deep->text);
  json preset = json::parse(text, nullptr, false);
  if (preset.is_discarded()) argsError("TFPRESET", "-tfpreset: " + a.value + " is not JSON");
  if (!preset.is_array()) preset = json::array({std::move(preset)});
  json patch = transferSource("paraview", std::move(preset));
  // The server stretches a preset onto the data's range unless told its
  // scalars are absolute (applyOptions reads the -absolute flag).
  if (a.absolute) patch["transfer_function"]["absolute"] = true;
  a.scene(std::move(patch));
}

// -camera auto|reset: back to the automatic camera; moves given before it
// (in this call, or waiting for open) are dropped, later ones apply to it.
void setCamera(Apply& a) {
  if (a.value != "auto" && a.value != "reset")
    argsError("CAMERA", "-camera takes 'reset' or 'auto' (set -eye, -lookat, -up for a fixed camera)");
  a.scene({{"camera", nullptr}});
  a.change.patch.erase("camera_moves");
  a.settings.cameraMoves = json::array();
}

// -pan DX,DY: fractions of the view's width and height.
void setPan(Apply& a) {
  const auto v = a.numbers(2);
  a.cameraMove({{"pan", {v[0], v[1]}}});
}

void setProjection(Apply& a) {
  if (a.value != "perspective" && a.value != "orthographic")
    argsError("PROJECTION", "-projection takes perspective or orthographic, got '" + a.value + "'");
  a.scene({{"camera", {{"projection", a.value}}}});
}

// -strategy NAME, -decomposition NAME: runtime settings of the node
// (docs/runtime.md). The names are the server's; with a session open and
// idle they are checked against its list for a clear error here.
// Errors: {PVR ARGS STRATEGY}, {PVR ARGS DECOMPOSITION}.
void setRuntimeName(Apply& a, const char* key, std::string_view listKey) {
  std::string what = a.option.substr(1);
  std::transform(what.begin(), what.end(), what.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  if (a.value.empty()) argsError(what, a.option + " needs a name");
  if (const auto known = a.serverNames ? a.serverNames(listKey) : std::nullopt)
    if (std::find(known->begin(), known->end(), a.value) == known->end()) {
      std::string names;
      for (std::size_t i = 0; i < known->size(); ++i)
        names += (i == 0 ? "" : i + 1 == known->size() ? " or " : ", ") + (*known)[i];
      argsError(what, a.option + ": the server offers " + names + ", not '" + a.value + "'");
    }
  a.scene({{"runtime", {{key, a.value}}}});
}

// -timestep K: the scene's "timestep" (docs/scene.md), the 0-based step of
// a time series the session shows; the server checks it against the
// dataset's steps.
void setTimestep(Apply& a) { a.scene({{"timestep", parseInteger(a.option, a.value, 0, INT32_MAX)}}); }

// -cachemem MB: runtime.cachemem, the brick cache's budget per render rank
// (docs/runtime.md); the server checks the upper bound.
void setCacheMemory(Apply& a) { a.scene({{"runtime", {{"cachemem", parseInteger(a.option, a.value, 0, INT32_MAX)}}}}); }

// -quality DB: sampling.target_psnr (docs/scene.md), the PSNR the server
// picks each region's step to meet; 0 turns it off. The server checks the
// upper bound, as it checks every scene value.
// Errors: {PVR ARGS QUALITY}.
void setQuality(Apply& a) {
  const double db = a.number();
  if (!(db >= 0)) argsError("QUALITY", a.option + " must be a PSNR in dB, >= 0 (0 = off), got '" + a.value + "'");
  setScalar(a, "sampling", "target_psnr", db);
}

// One row per option. `value` and `byDefault` are what `:s help set` and
// `:s set` (no arguments) show: the value's form, and what is in force
// while the option was never given. A row without them is a bug that
// tests/pvrsh/help.test catches.
struct OptionRow {
  const char* name;  // first field: Tcl_GetIndexFromObjStruct reads it
  void (*apply)(Apply&);
  const char* value = nullptr;      // "W,H"
  const char* byDefault = nullptr;  // "512,512"
};

const OptionRow kOptions[] = {
    {"-dataset", setDataset, "NAME", "none (see list datasets)"},
    {"-cluster", nullptr, "ROLE?,N?", "the master's layout"},  // with -group: handled in applyOptions
    {"-group", nullptr, "G,G,...", "0"},
    {"-imagesz", setImageSize, "W,H", "512,512"},
    {"-background", setBackground, "R,G,B?,A?", "0,0,0,1"},
    {"-tf", setTransferPoints, "{S R G B A ...}",
     "a white ramp over the data's range, clear below its first tenth"},
    {"-tfpreset", setTransferPreset, "FILE", "none"},
    {"-unitdist", [](Apply& a) { setScalar(a, "transfer_function", "unit_distance", a.positive()); }, "D",
     "one voxel (the smallest spacing)"},
    {"-camera", setCamera, "auto|reset", "auto"},
    {"-eye", [](Apply& a) { a.scene({{"camera", {{"eye", a.vec3()}}}}); }, "X,Y,Z", "automatic"},
    {"-lookat", [](Apply& a) { a.scene({{"camera", {{"look_at", a.vec3()}}}}); }, "X,Y,Z",
     "automatic: the domain's centre"},
    {"-up", [](Apply& a) { a.scene({{"camera", {{"up", a.vec3()}}}}); }, "X,Y,Z", "0,0,1"},
    {"-fov", [](Apply& a) { setScalar(a, "camera", "fov_y_deg", a.positive()); }, "DEG", "30"},
    {"-viewheight", [](Apply& a) { setScalar(a, "camera", "height", a.positive()); }, "H", "none (orthographic needs it)"},
    {"-projection", setProjection, "perspective|orthographic", "perspective"},
    {"-zoom", [](Apply& a) { a.cameraMove({{"zoom", a.positive()}}); }, "F", "none: a move, applied once"},
    {"-pan", setPan, "DX,DY", "none: a move, in fractions of the view"},
    {"-azimuth", [](Apply& a) { a.cameraMove({{"azimuth", a.number()}}); }, "DEG", "none: a move about look_at"},
    {"-elevation", [](Apply& a) { a.cameraMove({{"elevation", a.number()}}); }, "DEG", "none: a move about look_at"},
    {"-view", [](Apply& a) { a.cameraMove({{"view", a.value}}); }, "+x|-x|+y|-y|+z|-z|iso", "none: a move"},
    {"-step", [](Apply& a) { setScalar(a, "sampling", "step", a.positive()); }, "H", "half the smallest spacing"},
    {"-preintegrated", [](Apply& a) { a.scene({{"sampling", {{"preintegrated", parseBoolean(a.option, a.value)}}}}); },
     "BOOLEAN", "off"},
    {"-earlyterm", [](Apply& a) { setScalar(a, "sampling", "early_termination", a.positive()); }, "A", "0.9999 (1: off)"},
    {"-quality", setQuality, "DB", "0 (off: every region at -step)"},
    {"-shading", [](Apply& a) { a.scene({{"shading", {{"enabled", parseBoolean(a.option, a.value)}}}}); }, "BOOLEAN",
     "on for 3-D data"},
    {"-ambient", [](Apply& a) { setScalar(a, "shading", "ambient", a.number()); }, "KA", "0.2"},
    {"-diffuse", [](Apply& a) { setScalar(a, "shading", "diffuse", a.number()); }, "KD", "0.7"},
    {"-specular", [](Apply& a) { setScalar(a, "shading", "specular", a.number()); }, "KS", "0.3"},
    {"-shininess", [](Apply& a) { setScalar(a, "shading", "shininess", a.positive()); }, "N", "32"},
    {"-light", [](Apply& a) { a.scene({{"shading", {{"light_direction", a.vec3()}}}}); }, "X,Y,Z",
     "0,0,1 (a headlight)"},
    {"-strategy", [](Apply& a) { setRuntimeName(a, "strategy", "strategies"); }, "NAME", "binary-swap"},
    {"-decomposition", [](Apply& a) { setRuntimeName(a, "decomposition", "decompositions"); }, "NAME", "kd"},
    {"-timestep", setTimestep, "K", "0"},
    {"-cachemem", setCacheMemory, "MB", "256"},
    {"-computation", setComputation, "NAME?,NX,NY,NZ?", "none: a dataset (64,64,64 nodes when not given)"},
    {"-param", setParameter, "NAME VALUE", "the computation's own (list status: parameter_ranges)"},
    {nullptr, nullptr}};

void remember(Settings& s, const std::string& option, const std::string& value) {
  for (auto& [k, v] : s.shown)
    if (k == option) {
      v = value;
      return;
    }
  s.shown.emplace_back(option, value);
}

}  // namespace

SettingsChange applyOptions(Tcl_Interp* interp, Settings& settings, int objc, Tcl_Obj* const objv[],
                            const ServerNames& serverNames) {
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
    // "-tfpreset FILE -absolute": a flag, the one option word without a value.
    const bool absolute = option == "-tfpreset" && i + 2 < objc && std::string_view(Tcl_GetString(objv[i + 2])) == "-absolute";
    // "-param NAME VALUE": the one option of two words.
    const bool parameter = option == "-param";
    if (parameter && i + 2 >= objc) argsError("VALUE", "-param " + value + ": the value is missing (-param NAME VALUE)");
    const std::string parameterValue = parameter ? Tcl_GetString(objv[i + 2]) : "";
    if (option == "-cluster") {
      cluster = value;
    } else if (option == "-group") {
      group = value;
    } else {
      Apply a{next, change, option, value, serverNames, absolute, parameterValue};
      kOptions[index].apply(a);
    }
    // -param shows every parameter given so far, NAME VALUE ...
    std::string shown = absolute ? value + " -absolute" : value;
    if (parameter) {
      shown.clear();
      for (const auto& [name, v] : next.scene["parameters"].items()) {
        char text[32];
        char* end = std::to_chars(text, text + sizeof text, v.get<double>()).ptr;
        shown += (shown.empty() ? "" : " ") + name + " " + std::string(text, std::size_t(end - text));
      }
    }
    remember(next, option, shown);
    change.shown.emplace_back(option, shown);
    if (absolute || parameter) ++i;
  }
  // With a volume list each volume has its own transfer function: a
  // top-level one would make the scene invalid (docs/scene.md, `volumes`).
  if (next.scene.contains("volumes") && change.patch.contains("transfer_function")) {
    std::string given;
    const auto& names = transferOptionNames();
    for (const auto& [option, unused] : change.shown)
      if (std::find(names.begin(), names.end(), option) != names.end()) given = option;
    argsError("VOLUMES", "set " + given + ": the session has a volume list (volume list); give a volume its own with "
                         "volume configure NAME " + given + " ...");
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

const std::vector<std::string>& transferOptionNames() {
  static const std::vector<std::string> kNames{"-tf", "-tfpreset", "-unitdist"};
  return kNames;
}

std::optional<json> transferOption(const std::string& option, const std::string& value, bool absolute) {
  const auto& names = transferOptionNames();
  if (std::find(names.begin(), names.end(), option) == names.end()) return std::nullopt;
  for (const OptionRow* o = kOptions; o->name; ++o)
    if (o->name == option) {
      Settings scratch;
      SettingsChange change;
      const ServerNames none;
      Apply a{scratch, change, option, value, none, absolute};
      o->apply(a);
      return change.patch["transfer_function"];
    }
  return std::nullopt;
}

std::string shownOption(Tcl_Interp* interp, const Settings& settings, Tcl_Obj* option) {
  int index = 0;
  if (Tcl_GetIndexFromObjStruct(interp, option, kOptions, sizeof(OptionRow), "option", 0, &index) != TCL_OK)
    throw TclError({"PVR", "ARGS", "OPTION"}, Tcl_GetStringResult(interp));
  for (const auto& [k, v] : settings.shown)
    if (k == kOptions[index].name) return v;
  return "";
}

std::pair<int, int> imageSize(const Settings& settings) {
  const nlohmann::json& image = settings.scene.contains("image") ? settings.scene["image"] : nlohmann::json::object();
  for (const OptionRow& row : kOptions)
    if (std::string_view(row.name) == "-imagesz") {
      int width = 0, height = 0;
      std::sscanf(row.byDefault, "%d,%d", &width, &height);
      return {image.value("width", width), image.value("height", height)};
    }
  return {0, 0};
}

// A list whose elements are one per line, so that an interactive shell
// prints it as a table and a script reads it as any list.
Tcl_Obj* linedList(const std::vector<Tcl_Obj*>& rows) {
  std::string text;
  for (Tcl_Obj* row : rows) {
    Tcl_Obj* one = Tcl_NewListObj(1, &row);  // quotes the row as a list element
    Tcl_IncrRefCount(one);
    text += (text.empty() ? "" : "\n") + std::string(Tcl_GetString(one));
    Tcl_DecrRefCount(one);
  }
  return Tcl_NewStringObj(text.c_str(), -1);
}

Tcl_Obj* optionListing(const Settings& settings) {
  std::vector<Tcl_Obj*> rows;
  for (const OptionRow* o = kOptions; o->name; ++o) {
    std::string given;
    for (const auto& [k, v] : settings.shown)
      if (k == o->name) given = v;
    Tcl_Obj* row[3] = {Tcl_NewStringObj(o->name, -1), Tcl_NewStringObj(given.c_str(), -1),
                       Tcl_NewStringObj(o->byDefault ? o->byDefault : "", -1)};
    rows.push_back(Tcl_NewListObj(3, row));
  }
  return linedList(rows);
}

std::string optionsHelp() {
  std::string text;
  for (const OptionRow* o = kOptions; o->name; ++o) {
    std::string left = std::string("  ") + o->name + " " + (o->value ? o->value : "?");
    left.resize(std::max<std::size_t>(left.size() + 1, 36), ' ');
    text += left + "default: " + (o->byDefault ? o->byDefault : "?") + "\n";
  }
  return text;
}

void applyChange(Settings& settings, const SettingsChange& change) {
  if (change.dataset) settings.dataset = change.datasetName;
  json patch = change.patch;
  if (patch.is_object()) patch.erase("camera_moves");
  settings.scene.merge_patch(patch);
  for (const auto& option : change.forgotten)
    settings.shown.erase(std::remove_if(settings.shown.begin(), settings.shown.end(),
                                        [&](const auto& shown) { return shown.first == option; }),
                         settings.shown.end());
  for (const auto& [option, value] : change.shown) remember(settings, option, value);
}

SettingsChange wholeChange(const Settings& settings) {
  SettingsChange change;
  change.dataset = !settings.dataset.empty();
  change.datasetName = settings.dataset;
  change.patch = openingScene(settings);
  change.shown = settings.shown;
  return change;
}

json openingScene(const Settings& settings) {
  json scene = settings.scene;
  if (!settings.cameraMoves.empty()) scene["camera_moves"] = settings.cameraMoves;
  return scene;
}

Tcl_Obj* layoutObj(const std::vector<proto::ClusterSpec>& clusters) {
  static const char* const kRoles[] = {"render", "composite", "collector", "cache"};
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const auto& c : clusters) {
    Tcl_Obj* item[3] = {Tcl_NewStringObj(kRoles[std::min<int>(int(c.role), 3)], -1), Tcl_NewWideIntObj(c.ranks),
                        Tcl_NewWideIntObj(c.group)};
    Tcl_ListObjAppendElement(nullptr, list, Tcl_NewListObj(3, item));
  }
  return list;
}

}  // namespace pvr::tcl
