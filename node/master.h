// The master rank's side of a session: it takes protocol requests from its
// link thread (pvrd_link_thread.h) and answers each, turning the work into
// actions every rank runs (dispatch.h, actions/table.h). Requests run one
// at a time, in order. While a sequence renders, the link thread answers
// Status and Cancel at once; between waves the master answers queued
// Performance requests and keeps any other request for after the sequence.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>

#include "node.h"
#include "pvrd_link_thread.h"
#include "scene_patch.h"

namespace pvr::node {

class Master {
 public:
  Master(NodeState& state, LinkThread& link) : state_(state), link_(link) {}
  // Serves until the link closes or the client sends Close.
  void serve();

 private:
  void send(const proto::Message& m, std::uint32_t id, bool final = true) { link_.send(m, id, final); }
  void sendError(const proto::ProtocolError& e, std::uint32_t id) { send(proto::ErrorMessage{e.code, e.text}, id); }
  // Answers one request; an error it throws becomes the request's Error.
  void handle(const proto::Decoded& frame);
  // What the link thread answers a Status with while a render runs.
  // The session's status, one answer whoever asks: a StatusRequest the
  // master serves, or the snapshot the link thread answers during a render.
  proto::StatusReply status() const;
  void publishStatus();

  // One handler per message the master serves, `id` the request's; the
  // template answers every other message with Error UNSUPPORTED.
  void on(const proto::Hello& m, std::uint32_t id);
  void on(const proto::SessionOpen& m, std::uint32_t id);
  void on(const proto::SetLayout& m, std::uint32_t id);
  void on(const proto::SetScene& m, std::uint32_t id);
  void on(const proto::StatusRequest& m, std::uint32_t id);
  void on(const proto::RenderFrame& m, std::uint32_t id);
  void on(const proto::RenderRotation& m, std::uint32_t id);
  void on(const proto::RenderTimeSteps& m, std::uint32_t id);
  void on(const proto::RenderSteps& m, std::uint32_t id);
  void on(const proto::RenderInteractive& m, std::uint32_t id);
  void on(const proto::PerformanceRequest& m, std::uint32_t id);
  void on(const proto::Cancel& m, std::uint32_t id);
  void on(const proto::Close& m, std::uint32_t id);
  template <class M>
  void on(const M& m, std::uint32_t id);

  void layout(const std::vector<proto::ClusterSpec>& clusters, std::uint32_t id);
  // Checks and applies one scene patch (patchScene, then the ranks); the
  // error that refuses it, and then nothing changed.
  std::optional<proto::ProtocolError> applyScene(const proto::SetScene& request);
  // Renders frames 0 .. count - 1, frame k seen by cameraOf(k) at time
  // step stepOf(k), in waves of one frame per group; the request's frames
  // go out in order, the last FINAL. Each wave names the steps of the
  // frames after it, for the render ranks to read ahead. A computation
  // volume is computed, not read: one frame per wave, and the session's
  // step follows the frames (showComputedStep). `coarse` > 1:
  // progressively (proto::RenderInteractive), one frame per wave, frame 0
  // at 1/coarse of the pixels per axis, and every later frame given up
  // for a newer request (LinkThread::giveWayToNewer).
  void renderSequence(int count, const std::function<core::CameraSpec(int)>& cameraOf,
                      const std::function<int(int)>& stepOf, std::uint32_t id, int coarse = 1);

  // A computation volume: the session's time step becomes `step`, the one
  // the ranks compute up to (docs/steering.md); the wave that computes it
  // sets the same on every rank, so their scenes stay alike.
  void showComputedStep(int step);

  NodeState& state_;
  LinkThread& link_;
  SessionScene scene_;
  std::uint32_t framesSent_ = 0;
  std::uint32_t running_ = 0;  // request id of the sequence in progress; 0: none
};

}  // namespace pvr::node
