#include "status.h"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <optional>
#include <initializer_list>
#include <string>
#include <string_view>

#include "computation_data.h"
#include "hosts.h"
#include "strategy.h"

namespace pvr::node {

namespace {

// The shortest text that reads back as the same double: full precision.
std::string number(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

// Appends `item` to the Tcl list `out`.
void append(std::string& out, std::string_view item) {
  if (!out.empty()) out += ' ';
  out += item;
}

// Numbers as a Tcl list.
std::string list(std::initializer_list<double> values) {
  std::string out;
  for (double v : values) append(out, number(v));
  return out;
}

std::string list(const core::Vec3& v) { return list({v.x, v.y, v.z}); }

std::string strategyNames() {
  std::string out;
  for (const auto& s : composite::strategies()) append(out, s.name);
  return out;
}

std::string decompositionNames() {
  std::string out;
  for (const auto& d : decompositions()) append(out, d.name);
  return out;
}

// The dataset's grid, scalar type and histogram (data_summary.h): what
// `:s info` answers and the GUI's transfer-function editor draws.
void addGrid(const NodeState& state, std::vector<proto::KeyValue>& out) {
  const core::GridGeometry& grid = state.source->grid();
  out.push_back({"dims", list({double(grid.dims.x), double(grid.dims.y), double(grid.dims.z)})});
  out.push_back({"spacing", list(grid.spacing)});
  out.push_back({"origin", list(grid.origin)});
  out.push_back({"dtype", std::string(core::scalarName(state.source->type()))});
  std::string bins;
  for (std::uint64_t n : state.histogram) append(bins, std::to_string(n));
  out.push_back({"histogram", bins});
}

// The keys that describe the loaded dataset as it is rendered.
void addDataset(const NodeState& state, std::vector<proto::KeyValue>& out) {
  const core::CameraSpec& camera = state.scene.camera;  // resolved: the automatic camera is filled in
  const bool perspective = camera.projection == core::Projection::kPerspective;
  out.push_back({"camera_projection", perspective ? "perspective" : "orthographic"});
  out.push_back({"camera_eye", list(camera.eye)});
  out.push_back({"camera_look_at", list(camera.lookAt)});
  out.push_back({"camera_up", list(camera.up)});
  if (perspective) out.push_back({"camera_fov_y_deg", number(camera.fovYDeg)});
  if (!perspective || camera.height > 0) out.push_back({"camera_height", number(camera.height)});
  out.push_back({"image_size", list({double(state.scene.image.width), double(state.scene.image.height)})});
  const core::GridGeometry& grid = state.source->grid();
  const core::Vec3 lo = grid.domainMin(), hi = grid.domainMax();
  out.push_back({"bounds", list({lo.x, lo.y, lo.z, hi.x, hi.y, hi.z})});
  // What the image does not show as the file says (an oblique scan on the
  // nearest axes); the catalog lists the same text as the dataset's note.
  if (const std::string caveat = state.source->caveat(); !caveat.empty()) out.push_back({"warning", caveat});
  addGrid(state, out);
  if (state.valueRange) out.push_back({"value_range", list({(*state.valueRange)[0], (*state.valueRange)[1]})});
  std::string points;
  for (const core::TransferPoint& p : state.scene.volumes.front().transfer.points)
    append(points, list({p.scalar, p.r, p.g, p.b, p.opacity}));
  out.push_back({"transfer_function", points});
}

// Megabytes (2^20 bytes) with one decimal: "8.4".
std::string megabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", double(bytes) / double(1 << 20));
  return text;
}

// The bytes of the largest brick one rank of the master's render cluster
// holds for one step (owned nodes plus ghosts): what the cache holds per step.
std::uint64_t oneStepBytes(const NodeState& state) {
  const core::GridGeometry& grid = state.source->grid();
  std::optional<core::KdTree> tree = state.tree;
  if (!tree) {
    // A master outside the render clusters: the first one's tree.
    for (const ClusterPlan& c : state.layout.clusters)
      if (c.role == proto::ClusterRole::kRender) {
        tree = core::KdTree::build(grid, int(c.ranks.size()), splitAxisRule(state.settings.decomposition));
        break;
      }
  }
  if (!tree) return 0;
  std::uint64_t most = 0;
  for (int r = 0; r < tree->rankCount(); ++r)
    most = std::max(most, std::uint64_t(core::storedBox(*tree, r, state.ghost).nodeCount()));
  return most * core::scalarSize(state.source->type());
}

// How the render ranks get the steps of a series (brick_cache.h).
std::string cacheText(const NodeState& state, const RuntimeSettings& settings) {
  if (state.several()) return "several volumes: each step shown is read again (no read-ahead)";
  const core::VolumeSource& source = *state.source;
  const std::uint64_t budget = cacheBudgetBytes(settings), step = oneStepBytes(state);
  const std::string budgetText = "budget " + std::to_string(settings.cacheMegabytes) + " MB";
  if (source.steps() == 1) return "single volume: nothing to read ahead";
  if (!source.canReadPartially()) return "on demand: each step is read whole and scattered (no read-ahead)";
  if (budget < step) return "on demand: " + budgetText + " is below one step's " + megabytes(step) + " MB";
  const std::uint64_t fits = step > 0 ? budget / step : std::uint64_t(source.steps());
  return "read-ahead: " + budgetText + " holds " + std::to_string(std::min<std::uint64_t>(fits, source.steps())) +
         " of " + std::to_string(source.steps()) + " steps of " + megabytes(step) + " MB per rank";
}

// Tcl-list quoting of one element (braces; the texts here hold none unbalanced).
std::string element(const std::string& text) {
  if (!text.empty() && text.find_first_of(" \t\n{}\"\\$[];") == std::string::npos) return text;
  return "{" + text + "}";
}

// Every volume of the scene as a Tcl dict, in the scene's order: what
// `:s volume list` shows (docs/protocol.md, StatusReply).
std::string volumesText(const NodeState& state) {
  const std::vector<const core::VolumeSource*> sources = state.sources();
  std::string out;
  for (std::size_t i = 0; i < state.scene.volumes.size() && i < sources.size(); ++i) {
    const core::SceneVolume& v = state.scene.volumes[i];
    const core::GridGeometry& grid = sources[i]->grid();
    std::optional<std::array<double, 2>> range = i == 0 ? state.valueRange : std::nullopt;
    if (i < state.volumeRanges.size() && state.volumeRanges[i]) range = state.volumeRanges[i];
    std::string dict = "name " + element(v.name) + " source " + element(sources[i]->describe()) + " dims {" +
                       list({double(grid.dims.x), double(grid.dims.y), double(grid.dims.z)}) + "} dtype " +
                       std::string(core::scalarName(sources[i]->type())) + " visible " + (v.visible ? "1" : "0") +
                       " value_range {" + (range ? list({(*range)[0], (*range)[1]}) : "") + "}";
    append(out, "{" + dict + "}");
  }
  return out;
}

// The time steps of the dataset and the one shown.
void addTimeSteps(const NodeState& state, const RuntimeSettings& settings, std::vector<proto::KeyValue>& out) {
  const core::VolumeSource& source = *state.source;
  out.push_back({"timestep", std::to_string(state.scene.volumes.front().source.timestep)});
  out.push_back({"timesteps", std::to_string(source.steps())});
  std::string times;
  for (int k = 0; k < source.steps(); ++k) append(times, number(source.stepTime(k)));
  out.push_back({"timestep_times", times});
  out.push_back({"cache", cacheText(state, settings)});
}

}  // namespace

std::vector<proto::KeyValue> statusEntries(const NodeState& state, const SessionStatus& session) {
  const RuntimeSettings& settings = session.settings;
  std::vector<proto::KeyValue> out{
      {"state", session.rendering ? "rendering" : "session open"},
      {"ranks", std::to_string(state.world.size())},
      {"hosts", hostList(state.hosts)},
      {"master_pid", std::to_string(::getpid())},
      {"clusters", std::to_string(state.layout.clusters.size())},
      {"groups", std::to_string(state.layout.groups)},
      {"dataset", state.source ? state.source->describe() : ""},
      {"frames_rendered", std::to_string(session.framesSent)},
      {"rebalances", std::to_string(state.rebalances)},
      {"imbalance", number(state.imbalance)},
      {"strategies", strategyNames()},
      {"decompositions", decompositionNames()},
      {"strategy", settings.strategy},
      {"decomposition", std::string(decompositionName(settings.decomposition))},
  };
  if (state.source) {
    addDataset(state, out);
    out.push_back({"volumes", volumesText(state)});
    out.push_back({"camera_automatic", session.cameraSet ? "0" : "1"});
    if (const ComputationSource* computation = computationOf(state)) {
      const auto entries = computationStatus(state, *computation);
      out.insert(out.end(), entries.begin(), entries.end());
    } else {
      addTimeSteps(state, settings, out);
    }
  }
  return out;
}

}  // namespace pvr::node
