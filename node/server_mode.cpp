#include "server_mode.h"

#include <unistd.h>

#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>

#include "dispatch.h"
#include "mpi_communicator.h"
#include "node.h"
#include "pvr_protocol.h"
#include "pvrd_link.h"
#include "wave_io.h"

namespace pvr::node {
namespace {

using proto::ErrorCode;

ErrorCode wireCode(pvr::ErrorCode code) {
  switch (code) {
    case pvr::ErrorCode::kInvalidArgument: return ErrorCode::kBadArgument;
    case pvr::ErrorCode::kBadFile: return ErrorCode::kBadFile;
    case pvr::ErrorCode::kIo: return ErrorCode::kIo;
    case pvr::ErrorCode::kUnsupported: return ErrorCode::kUnsupported;
    case pvr::ErrorCode::kRemote: return ErrorCode::kRankFailed;
    case pvr::ErrorCode::kInternal: return ErrorCode::kInternal;
  }
  return ErrorCode::kInternal;
}

// v rotated by `angle` radians about unit axis k (Rodrigues).
core::Vec3 rotate(const core::Vec3& v, const core::Vec3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const core::Vec3 cross{k.y * v.z - k.z * v.y, k.z * v.x - k.x * v.z, k.x * v.y - k.y * v.x};
  const double dot = k.x * v.x + k.y * v.y + k.z * v.z;
  return {v.x * c + cross.x * s + k.x * dot * (1 - c), v.y * c + cross.y * s + k.y * dot * (1 - c),
          v.z * c + cross.z * s + k.z * dot * (1 - c)};
}

nlohmann::json clustersJson(const std::vector<proto::ClusterSpec>& specs) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : specs) out.push_back({int(c.role), c.ranks, c.group});
  return out;
}

class Master {
 public:
  Master(NodeState& state, PvrdLink& link) : state_(state), link_(link) {}
  void serve();

 private:
  void send(const proto::Message& m, std::uint32_t id, bool final = true) { link_.send(m, id, final); }
  void replyFailure(const comm::Failure& f, std::uint32_t id) {
    send(proto::ErrorMessage{wireCode(f.code), f.describe()}, id);
  }
  std::optional<proto::Decoded> next(bool wait) { return link_.next(wait); }
  void handle(const proto::Decoded& frame);
  bool handleAtOnce(const proto::Decoded& frame);  // Status/Performance/Cancel during a render
  void layout(const std::vector<proto::ClusterSpec>& clusters, std::uint32_t id);
  void setScene(const proto::SetScene& s, std::uint32_t id);
  void performance(const proto::PerformanceRequest& p, std::uint32_t id);
  void renderSequence(const std::vector<core::CameraSpec>& cameras, std::uint32_t id);

  NodeState& state_;
  PvrdLink& link_;
  std::deque<proto::Decoded> pending_;
  nlohmann::json doc_ = nlohmann::json::object();
  nlohmann::json runtime_ = nlohmann::json::object();
  std::uint32_t frames_ = 0;
  std::uint32_t running_ = 0;   // request id of the render in progress
  bool cancelled_ = false;
};

void Master::layout(const std::vector<proto::ClusterSpec>& clusters, std::uint32_t id) {
  if (auto f = invoke(state_, "set_layout", {{"clusters", clustersJson(clusters)}})) return replyFailure(*f, id);
  send(proto::SessionReady{std::uint32_t(state_.world.size()), state_.layout.specs()}, id);
}

void Master::setScene(const proto::SetScene& s, std::uint32_t id) {
  nlohmann::json doc = doc_;
  nlohmann::json runtime = runtime_;
  if (!s.sceneJson.empty()) {
    nlohmann::json patch = nlohmann::json::parse(s.sceneJson, nullptr, false);
    if (patch.is_discarded() || !patch.is_object())
      return send(proto::ErrorMessage{ErrorCode::kBadArgument, "scene: not a JSON object"}, id);
    if (patch.contains("runtime")) {
      runtime.merge_patch(patch["runtime"]);
      patch.erase("runtime");
    }
    // Files come only through the dataset name, which the handler resolved.
    if (patch.contains("volume") && patch["volume"].is_object() && patch["volume"].contains("file"))
      return send(proto::ErrorMessage{ErrorCode::kBadArgument, "scene: name a dataset, not a volume file"}, id);
    doc.merge_patch(patch);
  }
  if (!s.dataset.empty()) {
    char buf[PATH_MAX];
    const std::string wanted = s.dataset[0] == '/' ? s.dataset : state_.dataDir + "/" + s.dataset;
    const bool inside = ::realpath(wanted.c_str(), buf) && !state_.dataDir.empty() &&
                        std::strncmp(buf, state_.dataDir.c_str(), state_.dataDir.size()) == 0 &&
                        buf[state_.dataDir.size()] == '/';
    if (!inside)
      return send(proto::ErrorMessage{ErrorCode::kDatasetNotFound, "no dataset '" + s.dataset + "' in the data directory"}, id);
    doc["volume"] = nlohmann::json{{"file", buf}};
  }
  if (!doc.contains("volume")) {  // nothing to render yet: keep the settings for later
    doc_ = std::move(doc);
    runtime_ = std::move(runtime);
    return send(proto::Ok{}, id);
  }
  const bool newVolume = !doc_.contains("volume") || doc_["volume"] != doc["volume"];
  const auto failure = invoke(state_, newVolume ? "load_dataset" : "set_scene", {{"scene", doc}, {"runtime", runtime}});
  if (failure) return replyFailure(*failure, id);
  doc_ = std::move(doc);
  runtime_ = std::move(runtime);
  send(proto::Ok{}, id);
}

void Master::performance(const proto::PerformanceRequest& p, std::uint32_t id) {
  const int cluster = p.cluster == proto::kAllClusters ? -1 : int(p.cluster);
  const char* action = p.query == proto::PerformanceQuery::kMemory ? "report_memory" : "comp_latency";
  if (auto f = invoke(state_, action, {{"cluster", cluster}})) return replyFailure(*f, id);
  send(proto::PerformanceReply{p.query, state_.reply.dump()}, id);
}

bool Master::handleAtOnce(const proto::Decoded& frame) {
  const std::uint32_t id = frame.info.requestId;
  if (std::holds_alternative<proto::StatusRequest>(frame.message)) {
    handle(frame);
    return true;
  }
  if (const auto* p = std::get_if<proto::PerformanceRequest>(&frame.message)) {
    performance(*p, id);
    return true;
  }
  if (const auto* c = std::get_if<proto::Cancel>(&frame.message)) {
    if (c->target == running_) cancelled_ = true;
    send(proto::Ok{}, id);
    return true;
  }
  return false;
}

// Frames go out in waves of one frame per group: the groups render their
// frames at once, composite, and the collector sends them in order. Between
// waves the master answers Status, Performance and Cancel.
void Master::renderSequence(const std::vector<core::CameraSpec>& cameras, std::uint32_t id) {
  running_ = id;
  cancelled_ = false;
  const int last = int(cameras.size()) - 1;
  state_.sendFrame = [&](proto::ImageFrame&& f, bool final) {
    ++frames_;
    send(f, id, final);
  };
  const std::size_t groups = std::size_t(state_.layout.groups);
  for (std::size_t first = 0; first < cameras.size() && link_.open(); first += groups) {
    nlohmann::json frames = nlohmann::json::array();
    for (std::size_t k = first; k < std::min(cameras.size(), first + groups); ++k)
      frames.push_back({{"frame", k}, {"camera", cameraToJson(cameras[k])}});
    double dist = 0;
    auto failure = invoke(state_, "render", {{"frames", frames}}, &dist);
    if (!failure) failure = invoke(state_, "composite");
    if (!failure) failure = invoke(state_, "collect", {{"request", id}, {"last_frame", last}, {"dist", dist}});
    if (failure) {
      replyFailure(*failure, id);
      break;
    }
    // Between waves: answer what must not wait; keep the rest for later.
    while (auto frame = next(false)) {
      if (!handleAtOnce(*frame)) pending_.push_back(std::move(*frame));
    }
    if (cancelled_ && first + groups < cameras.size()) {
      send(proto::ErrorMessage{ErrorCode::kCancelled, "cancelled after " + std::to_string(first + groups) + " frames"}, id);
      break;
    }
  }
  state_.sendFrame = nullptr;
  running_ = 0;
}

void Master::handle(const proto::Decoded& frame) {
  const std::uint32_t id = frame.info.requestId;
  try {
    std::visit(
        [&](const auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, proto::Hello>) {
            send(proto::Welcome{"pvr-node 0.2", std::uint32_t(state_.world.size()), false}, id);
          } else if constexpr (std::is_same_v<T, proto::SessionOpen> || std::is_same_v<T, proto::SetLayout>) {
            layout(m.clusters, id);
          } else if constexpr (std::is_same_v<T, proto::StatusRequest>) {
            std::vector<proto::KeyValue> entries{{"state", running_ ? "rendering" : "session open"},
                                                 {"ranks", std::to_string(state_.world.size())},
                                                 {"master_pid", std::to_string(::getpid())},
                                                 {"clusters", std::to_string(state_.layout.clusters.size())},
                                                 {"groups", std::to_string(state_.layout.groups)},
                                                 {"dataset", state_.source ? state_.source->describe() : ""},
                                                 {"frames_rendered", std::to_string(frames_)},
                                                 {"rebalances", std::to_string(state_.rebalances)},
                                                 {"imbalance", std::to_string(state_.imbalance)}};
            send(proto::StatusReply{entries}, id);
          } else if constexpr (std::is_same_v<T, proto::SetScene>) {
            setScene(m, id);
          } else if constexpr (std::is_same_v<T, proto::RenderFrame>) {
            if (!state_.source) throw Error(pvr::ErrorCode::kInvalidArgument, "no dataset: send SetScene with a dataset first");
            renderSequence({state_.scene.camera}, id);
          } else if constexpr (std::is_same_v<T, proto::RenderRotation>) {
            if (m.stepsPerTurn == 0 || m.end < m.start || std::int64_t(m.end) - m.start >= 100000)
              throw Error(pvr::ErrorCode::kInvalidArgument, "rotation needs start <= end and stepsPerTurn >= 1");
            const double len = std::sqrt(m.axis[0] * m.axis[0] + m.axis[1] * m.axis[1] + m.axis[2] * m.axis[2]);
            if (!(len > 0) || !std::isfinite(len)) throw Error(pvr::ErrorCode::kInvalidArgument, "rotation axis is zero");
            if (!state_.source) throw Error(pvr::ErrorCode::kInvalidArgument, "no dataset: send SetScene with a dataset first");
            const core::Vec3 axis{m.axis[0] / len, m.axis[1] / len, m.axis[2] / len};
            const core::CameraSpec base = state_.scene.camera;
            std::vector<core::CameraSpec> cameras;
            for (std::int32_t k = m.start; k <= m.end; ++k) {
              core::CameraSpec c = base;
              const double angle = 2 * M_PI * double(k) / double(m.stepsPerTurn);
              const core::Vec3 e = rotate(base.eye - base.lookAt, axis, angle);
              c.eye = base.lookAt + e;
              c.up = rotate(base.up, axis, angle);
              cameras.push_back(c);
            }
            renderSequence(cameras, id);
          } else if constexpr (std::is_same_v<T, proto::PerformanceRequest>) {
            performance(m, id);
          } else if constexpr (std::is_same_v<T, proto::Cancel>) {
            send(proto::Ok{}, id);  // requests run one at a time: the target has finished
          } else if constexpr (std::is_same_v<T, proto::Close>) {
            link_.close();
          } else {
            send(proto::ErrorMessage{ErrorCode::kUnsupported, std::string(T::kWire.name) + " is not served by pvr-node"}, id);
          }
        },
        frame.message);
  } catch (const Error& e) {
    send(proto::ErrorMessage{wireCode(e.code()), e.what()}, id);
  } catch (const std::exception& e) {
    send(proto::ErrorMessage{ErrorCode::kInternal, e.what()}, id);
  }
}

void Master::serve() {
  while (link_.open()) {
    std::optional<proto::Decoded> frame;
    if (!pending_.empty()) {
      frame = std::move(pending_.front());
      pending_.pop_front();
    } else {
      frame = next(true);
    }
    if (!frame) break;
    handle(*frame);
  }
}

}  // namespace

bool parseServerOptions(int argc, char** argv, ServerOptions& options, std::string& error) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--server") continue;
    if (i + 1 >= argc) {
      error = a + " needs a value";
      return false;
    }
    const std::string v = argv[++i];
    if (a == "--connect") {
      const auto colon = v.rfind(':');
      if (colon == std::string::npos) {
        error = "--connect takes HOST:PORT";
        return false;
      }
      options.host = v.substr(0, colon);
      options.port = std::atoi(v.c_str() + colon + 1);
    } else if (a == "--data-dir") {
      options.dataDir = v;
    } else if (a == "--fail-once") {
      if (v.find('@') == std::string::npos) {
        error = "--fail-once takes ACTION@RANK";
        return false;
      }
      options.failOnce = v;
    } else if (a == "--dump-frames") {
      options.dumpFrames = v;
    } else {
      error = "unknown option " + a;
      return false;
    }
  }
  if (options.host.empty() || options.port <= 0 || options.dataDir.empty()) {
    error = "server mode needs --connect HOST:PORT and --data-dir DIR";
    return false;
  }
  return true;
}

int runServer(const ServerOptions& options) {
  comm::MpiEnvironment mpi(nullptr, nullptr);
  comm::Communicator& world = mpi.world();
  char real[PATH_MAX];
  NodeState state(world, mpi.commands(), ::realpath(options.dataDir.c_str(), real) ? real : "");
  if (const auto at = options.failOnce.find('@'); at != std::string::npos) {
    state.failAction = options.failOnce.substr(0, at);
    state.failRank = std::atoi(options.failOnce.c_str() + at + 1);
  }
  state.dumpDir = options.dumpFrames;

  std::unique_ptr<PvrdLink> link;
  if (world.rank() == 0) {
    try {
      link = std::make_unique<PvrdLink>(options.host, options.port);
    } catch (const Error& e) {
      std::fprintf(stderr, "pvr-node: rank 0: %s\n", e.what());
      std::fflush(stderr);
      mpi.commands().abortJob(1);  // the other ranks wait for commands that will not come
    }
  }
  // Same table everywhere, or nobody starts.
  try {
    checkActionTables(world);
  } catch (const Error& e) {
    if (link) {
      link->send(proto::ErrorMessage{ErrorCode::kInternal, e.what()}, 0);
      std::fprintf(stderr, "pvr-node: %s\n", e.what());
    }
    return 1;
  }
  if (world.rank() != 0) {
    serveSlave(state);
    return 0;
  }
  // The default layout (one render cluster of every rank) and the
  // compositing model's calibration; SessionOpen's layout follows.
  int status = 0;
  if (auto f = invoke(state, "set_layout", {{"clusters", nlohmann::json::array()}})) {
    std::fprintf(stderr, "pvr-node: %s\n", f->describe().c_str());
    status = 1;
  } else if (auto g = invoke(state, "calibrate")) {
    std::fprintf(stderr, "pvr-node: %s\n", g->describe().c_str());
    status = 1;
  } else {
    Master(state, *link).serve();
  }
  invoke(state, "shutdown");
  return status;
}

}  // namespace pvr::node
