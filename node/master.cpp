#include "master.h"

#include <algorithm>

#include "camera_request.h"
#include "computation_data.h"
#include "dispatch.h"
#include "rotation.h"
#include "status.h"
#include "steering_patch.h"
#include "wire_error.h"

namespace pvr::node {

namespace {

using proto::ErrorCode;

// How many frames per group a wave names for reading ahead: more than a
// cache holds is no use, and the list travels with every wave.
constexpr int kReadAheadFrames = 32;

// Requests the master answers between the waves of a sequence (Status and
// Cancel the link thread answers at once); steering takes effect there.
bool answeredBetweenWaves(const proto::Message& m) {
  return proto::isQuery(m) || isSteeringPatch(m);
}

void requireDataset(const NodeState& state) {
  if (!state.source) throw Error(pvr::ErrorCode::kInvalidArgument, "no dataset: send SetScene with a dataset first");
}

}  // namespace

void Master::serve() {
  publishStatus();
  while (auto frame = link_.take()) {
    handle(*frame);
    publishStatus();
  }
}

proto::StatusReply Master::status() const {
  return proto::StatusReply{
      statusEntries(state_, {running_ != 0, framesSent_, scene_.settings, scene_.doc.contains("camera")})};
}

void Master::publishStatus() { link_.publishStatus(status()); }

void Master::handle(const proto::Decoded& frame) {
  try {
    std::visit([&](const auto& m) { on(m, frame.info.requestId); }, frame.message);
  } catch (const Error& e) {
    sendError(wireError(e), frame.info.requestId);
  } catch (const std::exception& e) {
    send(proto::ErrorMessage{ErrorCode::kInternal, e.what()}, frame.info.requestId);
  }
}

void Master::on(const proto::Hello&, std::uint32_t id) {
  send(proto::Welcome{"pvr-node 0.2", std::uint32_t(state_.world.size()), false}, id);
}

void Master::on(const proto::SessionOpen& m, std::uint32_t id) { layout(m.clusters, id); }

void Master::on(const proto::SetLayout& m, std::uint32_t id) { layout(m.clusters, id); }

void Master::layout(const std::vector<proto::ClusterSpec>& clusters, std::uint32_t id) {
  if (auto f = invoke(state_, actions::SetLayout{clusters})) return sendError(wireError(*f, state_.hosts), id);
  send(proto::SessionReady{std::uint32_t(state_.world.size()), state_.layout.specs()}, id);
}

void Master::on(const proto::SetScene& request, std::uint32_t id) {
  // A camera part that needs the camera in force (camera_request.h) goes
  // after the rest of the patch, which may load the dataset that places it.
  std::optional<CameraRequest> camera;
  proto::SetScene rest = request;
  if (!request.sceneJson.empty() && !proto::checkJsonDepth(request.sceneJson, "scene")) {
    nlohmann::json patch = nlohmann::json::parse(request.sceneJson, nullptr, false);
    if (patch.is_object()) {  // anything else patchScene refuses in its words
      CameraRequest taken = takeCameraRequest(patch);
      if (!taken.empty() && !mergesIntoDocument(taken, scene_.doc)) {
        camera = std::move(taken);
        rest.sceneJson = patch.empty() ? std::string() : patch.dump();
      }
    }
  }
  if (!camera || !rest.sceneJson.empty() || !rest.dataset.empty())
    if (auto refused = applyScene(camera ? rest : request)) return sendError(*refused, id);
  if (camera) {
    if (!state_.source)
      throw Error(pvr::ErrorCode::kInvalidArgument,
                  "camera: this change moves the camera in force, which is placed once a dataset is loaded; "
                  "set a dataset first (or give eye and look_at)");
    const core::ImageSpec& image = state_.scene.image;
    const core::CameraSpec automatic = core::automaticCamera(state_.source->grid(), image.width, image.height);
    const nlohmann::json section =
        cameraSectionAfter(*camera, state_.scene.camera, automatic, double(image.width) / double(image.height));
    if (auto refused = applyScene(proto::SetScene{"", nlohmann::json{{"camera", section}}.dump()}))
      return sendError(*refused, id);
  }
  // Steering is answered between the waves of a sequence, when the link
  // thread answers Status from its snapshot: the snapshot shows the change
  // before the client learns it was made.
  publishStatus();
  send(proto::Ok{}, id);
}

std::optional<proto::ProtocolError> Master::applyScene(const proto::SetScene& request) {
  auto patched = patchScene(scene_, request, state_.dataDir);
  if (const auto* refused = std::get_if<proto::ProtocolError>(&patched)) return *refused;
  SessionScene& next = std::get<SessionScene>(patched);
  if (auto refused = checkSteering(request, next, state_.dataDir)) return *refused;
  // Without a volume there is nothing for the ranks to load yet: the
  // checked scene waits for the dataset.
  if (next.hasVolume()) {
    if (auto f = invoke(state_, actions::SetScene{next.doc.dump(), next.settings})) return wireError(*f, state_.hosts);
  }
  scene_ = std::move(next);
  return std::nullopt;
}

void Master::on(const proto::StatusRequest&, std::uint32_t id) {
  // The histogram a load left uncounted, now that someone asks (the link
  // thread answers from its snapshot, without it, while renders run ahead).
  if (state_.histogramPending)
    if (auto f = invoke(state_, actions::CountHistogram{})) return sendError(wireError(*f, state_.hosts), id);
  send(status(), id);
}

void Master::on(const proto::RenderFrame&, std::uint32_t id) {
  requireDataset(state_);
  const core::CameraSpec camera = state_.scene.camera;
  const int step = state_.scene.volumes.front().source.timestep;
  renderSequence(1, [&](int) { return camera; }, [&](int) { return step; }, id);
}

// The coarse frame, then the same view at full quality (a wave of its
// own, which a newer request stops or skips).
void Master::on(const proto::RenderInteractive& m, std::uint32_t id) {
  requireDataset(state_);
  const core::CameraSpec camera = m.turn == 0 ? state_.scene.camera : Rotation(state_.scene.camera, m.rotation()).camera(0);
  const int step = state_.scene.volumes.front().source.timestep;
  renderSequence(2, [&](int) { return camera; }, [&](int) { return step; }, id, int(m.reduction));
}

// A rotation shows the session's time step.
void Master::on(const proto::RenderRotation& m, std::uint32_t id) {
  const Rotation rotation(state_.scene.camera, m);
  requireDataset(state_);
  const int step = state_.scene.volumes.front().source.timestep;
  renderSequence(rotation.frames(), [&](int k) { return rotation.camera(k); }, [&](int) { return step; }, id);
}

// Frame k shows step first + k * stride at the session's view. The
// session's time step stays what the scene says (set -timestep): a time
// request changes only what its own frames show.
void Master::on(const proto::RenderTimeSteps& m, std::uint32_t id) {
  requireDataset(state_);
  const int steps = state_.source->steps();
  if (m.last >= std::uint32_t(steps))
    throw Error(pvr::ErrorCode::kInvalidArgument,
                "render time " + std::to_string(m.first) + "," + std::to_string(m.last) + ": step " +
                    std::to_string(m.last) + " is past the last step " + std::to_string(steps - 1) + " of '" +
                    state_.source->describe() + "'");
  if (const int now = state_.scene.volumes.front().source.timestep; computationOf(state_) && int(m.first) < now)
    throw Error(pvr::ErrorCode::kInvalidArgument, "render time " + std::to_string(m.first) + "," +
                                                      std::to_string(m.last) + ": '" + state_.source->describe() +
                                                      "' is at step " + std::to_string(now) +
                                                      " and cannot go back (docs/steering.md)");
  const core::CameraSpec camera = state_.scene.camera;
  renderSequence(int(m.frameCount()), [&](int) { return camera; },
                 [&](int k) { return int(m.first + std::uint32_t(k) * m.stride); }, id);
}

// A computation volume advances `steps` steps; frame k shows step
// s0 + min((k + 1) * every, steps), the last the final step.
void Master::on(const proto::RenderSteps& m, std::uint32_t id) {
  requireDataset(state_);
  if (!computationOf(state_))
    throw Error(pvr::ErrorCode::kInvalidArgument,
                "render steps: '" + state_.source->describe() +
                    "' is not a computation volume (docs/steering.md); render time shows a dataset's steps");
  const std::int64_t first = state_.scene.volumes.front().source.timestep;
  if (first + std::int64_t(m.steps) > ComputationSource::kSteps)
    throw Error(pvr::ErrorCode::kInvalidArgument, "render steps " + std::to_string(m.steps) + ": past step " +
                                                      std::to_string(ComputationSource::kSteps));
  const core::CameraSpec camera = state_.scene.camera;
  renderSequence(int(m.frameCount()), [&](int) { return camera; },
                 [&](int k) { return int(first + std::min<std::int64_t>(std::int64_t(k + 1) * m.every, m.steps)); }, id);
}

void Master::showComputedStep(int step) {
  scene_.doc["timestep"] = step;
  state_.scene.volumes.front().source.timestep = step;
}

void Master::on(const proto::PerformanceRequest& p, std::uint32_t id) {
  const std::int32_t cluster = p.cluster == proto::kAllClusters ? -1 : std::int32_t(p.cluster);
  std::optional<comm::Failure> failure;
  switch (p.query) {
    case proto::PerformanceQuery::kMemory: failure = invoke(state_, actions::ReportMemory{cluster}); break;
    case proto::PerformanceQuery::kCompositing: failure = invoke(state_, actions::CompLatency{cluster}); break;
    case proto::PerformanceQuery::kCache: failure = invoke(state_, actions::ReportCache{cluster}); break;
  }
  if (failure) return sendError(wireError(*failure, state_.hosts), id);
  send(proto::PerformanceReply{p.query, state_.reply.dump()}, id);
}

// The link thread answers Cancel itself (pvrd_link_thread.h); one that
// reaches here named nothing running.
void Master::on(const proto::Cancel&, std::uint32_t id) { send(proto::Ok{}, id); }

void Master::on(const proto::Close&, std::uint32_t) { link_.close(); }

template <class M>
void Master::on(const M&, std::uint32_t id) {
  send(proto::ErrorMessage{ErrorCode::kUnsupported, std::string(M::kWire.name) + " is not served by pvr-node"}, id);
}

void Master::renderSequence(int count, const std::function<core::CameraSpec(int)>& cameraOf,
                            const std::function<int(int)>& stepOf, std::uint32_t id, int coarse) {
  running_ = id;
  publishStatus();
  link_.setRendering(id);
  std::uint32_t sent = 0;  // frames of this request
  state_.sendFrame = [&](proto::ImageFrame&& f, bool final) {
    ++framesSent_;
    ++sent;
    // The snapshot a Status is answered from during the render shows what
    // the frame's wave loaded (an interactive render's coarse frame is
    // followed by more rendering, while its client asks).
    publishStatus();
    send(f, id, final);
  };
  const auto sendCancelled = [&] {
    send(proto::ErrorMessage{ErrorCode::kCancelled, "cancelled after " + std::to_string(sent) + " frames"}, id);
  };
  // Groups would compute the steps of their frames apart: a computation's
  // frames go one at a time, to the first group; so do a progressive
  // request's, which gives its later frames up for a newer request.
  const bool computed = computationOf(state_) != nullptr;
  const bool progressive = coarse > 1;
  const int groups = computed || progressive ? 1 : state_.layout.groups;
  for (int first = 0; first < count && link_.open(); first += groups) {
    if (progressive && first > 0 && link_.giveWayToNewer(id)) {
      sendCancelled();
      break;
    }
    actions::Wave wave;
    wave.request = id;
    wave.reduction = progressive && first == 0 ? coarse : 1;
    wave.lastFrame = std::uint32_t(count - 1);
    for (int k = first; k < std::min(count, first + groups); ++k)
      wave.frames.push_back({std::uint32_t(k), cameraArgs(cameraOf(k)), stepOf(k)});
    for (int k = first + groups; k < std::min(count, first + groups + kReadAheadFrames * groups) && !computed; ++k)
      wave.upcoming.push_back(stepOf(k));
    // The ranks reach the step before they render it, even if the frame fails.
    if (computed) {
      showComputedStep(wave.frames.back().timestep);
      publishStatus();  // what the link thread answers while the wave runs
    }
    if (auto f = invoke(state_, wave)) {
      // A frame stopped by the Cancel fails the wave on every rank alike.
      if (link_.cancelled(id)) sendCancelled();
      else sendError(wireError(*f, state_.hosts), id);
      break;
    }
    publishStatus();
    // Between waves: answer what must not wait; the rest stays queued.
    while (auto frame = link_.takeIf(answeredBetweenWaves)) handle(*frame);
    if (link_.cancelled(id) && first + groups < count) {
      sendCancelled();
      break;
    }
  }
  state_.sendFrame = nullptr;
  link_.setRendering(0);
  running_ = 0;
}

}  // namespace pvr::node
