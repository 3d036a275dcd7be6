// render {"frames": [{"frame": k, "camera": {...}}, ...]}: one wave of a
// sequence. Group g renders frames[g] (when there is one): every rank of
// each of the group's render clusters ray-casts its brick and keeps the
// scanlines of its cluster's band. Groups render their frames at the same
// time (time-space parallelism); clusters of a group split the rows
// (image-space parallelism). Purely local: no messages.
#include <chrono>

#include "../node.h"
#include "../wave_io.h"

namespace pvr::node::actions {

void render(NodeState& state, const ActionArgs& args) {
  state.wave.clear();
  state.bands.clear();
  for (const auto& f : args.at("frames")) {
    WaveFrame w;
    w.frame = f.at("frame").get<int>();
    w.camera = cameraFromJson(f.at("camera"));
    state.wave.push_back(std::move(w));
  }
  if (!state.renders()) return;
  const ClusterPlan& me = *state.myCluster();
  if (me.group >= int(state.wave.size())) return;
  WaveFrame& w = state.wave[std::size_t(me.group)];
  w.mine = true;
  if (!state.renderer) throw Error(ErrorCode::kInvalidArgument, "no dataset: send SetScene with a dataset first");
  state.maybeFail("render");

  const auto start = std::chrono::steady_clock::now();
  const int width = state.scene.image.width, height = state.scene.image.height;
  const core::Camera camera(w.camera, width, height);
  // A cluster that shares the frame's scanlines with others casts only the
  // rays of its own band.
  const core::PixelRect band = bandRect(width, height, me.band, me.bands);
  w.partial = state.renderer->render(camera, state.renderOptions, *state.pool, nullptr,
                                     me.bands > 1 ? &band : nullptr);
  w.rend = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace pvr::node::actions
