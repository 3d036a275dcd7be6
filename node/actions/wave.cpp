// wave: one wave of a request, one frame per group, in one command and one
// agreement. Group g renders frames[g] (when there is one): every rank of
// each of the group's render clusters ray-casts its brick, keeping the
// scanlines of its cluster's band. Groups render their frames at the same
// time (time-space parallelism); clusters of a group split the rows
// (image-space parallelism). Then the sub-images become bands at the
// collector (wave_composite.h), which sends the frames in order
// (wave_collect.h).
//
// A failure in any step travels with the messages that step sends anyway
// (a sub-image or band carries it), so no rank waits on one that gave up.
// Every rank ends by throwing the first failure it knows of; the
// dispatcher's one world agreement then reports the lowest rank's.
#include <chrono>

#include "../cache_cluster.h"
#include "../computation_data.h"
#include "../coarse_frame.h"
#include "../data.h"
#include "../rank_watch.h"
#include "../wave_collect.h"
#include "../wave_composite.h"
#include "table.h"

namespace pvr::node::actions {

namespace {

// The steps my group shows after this wave, in order: every groups-th of
// the request's upcoming ones.
std::vector<int> myUpcoming(const std::vector<std::int32_t>& upcoming, int group, int groups) {
  std::vector<int> mine;
  for (std::size_t j = std::size_t(group); j < upcoming.size(); j += std::size_t(groups)) mine.push_back(upcoming[j]);
  return mine;
}

// Collective over each render cluster whose group has a frame, then local:
// shows the frame's time step (from the cache, or read now), starts
// reading the group's next steps ahead, and ray-casts this rank's brick.
void renderMyFrame(NodeState& state, const Wave& args, std::optional<comm::Failure>& failure) {
  if (!state.renders()) return;
  const ClusterPlan& me = *state.myCluster();
  if (me.group >= int(state.wave.size())) return;
  WaveFrame& w = state.wave[std::size_t(me.group)];
  const int width = state.scene.image.width, height = state.scene.image.height;
  try {
    {
      // A step not held is read now: the longer stall limit applies.
      const comm::LivenessScope loading(state.liveness, comm::LivenessScope::Kind::kLoading);
      showStep(state, w.timestep, StepFailure::kOwn);  // a failure travels with the wave
    }
    state.cache.classifyAhead(aheadClassifier(state));
    state.cache.readAhead(myUpcoming(args.upcoming, me.group, state.layout.groups));
    if (!state.current) throw Error(ErrorCode::kInvalidArgument, "no dataset: send SetScene with a dataset first");
    state.maybeFail("render");
    const auto start = std::chrono::steady_clock::now();
    const core::Camera camera(w.camera, width, height);
    // A cluster that shares the frame's scanlines with others casts only
    // the rays of its own band.
    const core::PixelRect band = bandRect(width, height, me.band, me.bands);
    // A Cancel stops the frame between tiles; each tile counts as progress.
    core::RenderOptions options = state.renderOptions;
    if (state.watch) options.stop = &state.watch->stop();
    if (state.liveness) options.tilesDone = &state.liveness->progress;
    w.partial = state.current->render(camera, options, *state.pool, me.bands > 1 ? &band : nullptr);
    w.rend = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } catch (...) {
    failure = comm::failureOf(std::current_exception(), state.world.rank());
    w.partial = core::Image(width, height, core::PixelRect{});  // composites as nothing
  }
}

// Cache ranks: each render cluster I serve gets its frame's step, and its
// group's next steps are read ahead (cache_cluster.h).
void serveMyClusters(NodeState& state, const Wave& args) {
  const ClusterPlan* me = state.myCluster();
  if (!me || me->role != proto::ClusterRole::kCache) return;
  for (int c : me->serves) {
    const int group = state.layout.clusters[std::size_t(c)].group;
    if (group < int(state.wave.size()))
      serveStep(state, c, state.wave[std::size_t(group)].timestep, myUpcoming(args.upcoming, group, state.layout.groups));
  }
}

}  // namespace

void Wave::run(NodeState& state, const Wave& args) {
  if (state.watch) state.watch->begin(args.request);
  state.wave.clear();
  for (const FrameView& f : args.frames) {
    WaveFrame w;
    w.number = f.number;
    w.camera = cameraSpec(f.camera);
    w.timestep = f.timestep;
    state.wave.push_back(std::move(w));
  }
  // A computation's frames compute their steps: every rank's scene shows
  // the last, as the master's does (Master::showComputedStep).
  if (computationOf(state) && !args.frames.empty())
    state.scene.volumes.front().source.timestep = args.frames.back().timestep;
  // Every step of a coarse wave works at the reduced size.
  const ReducedImage reduced(state.scene.image, std::max<std::int32_t>(1, args.reduction));
  std::optional<comm::Failure> failure;
  {
    const comm::LivenessScope loading(state.liveness, comm::LivenessScope::Kind::kLoading);
    serveMyClusters(state, args);
  }
  renderMyFrame(state, args, failure);
  compositeWave(state, args.reduction > 1, failure);
  collectWave(state, args.request, args.lastFrame, args.reduction > 1, failure);
  if (failure) throw comm::FailureError(*failure);
}

}  // namespace pvr::node::actions
