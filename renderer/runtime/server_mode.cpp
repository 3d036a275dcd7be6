#include "server_mode.h"

#include <arpa/inet.h>
#include <mpi.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>

#include "camera.h"
#include "error.h"
#include "image_io.h"
#include "pvr_protocol.h"
#include "raycast/raycaster.h"
#include "scene.h"
#include "scene_volume.h"
#include "thread_pool.h"

namespace pvr::runtime {
namespace {

using proto::ErrorCode;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

ErrorCode wireCode(const std::exception& e) {
  if (const auto* pe = dynamic_cast<const pvr::Error*>(&e)) {
    switch (pe->code()) {
      case pvr::ErrorCode::kInvalidArgument: return ErrorCode::kBadArgument;
      case pvr::ErrorCode::kBadFile: return ErrorCode::kBadFile;
      case pvr::ErrorCode::kIo: return ErrorCode::kIo;
      case pvr::ErrorCode::kUnsupported: return ErrorCode::kUnsupported;
      case pvr::ErrorCode::kRemote: return ErrorCode::kRankFailed;
      case pvr::ErrorCode::kInternal: return ErrorCode::kInternal;
    }
  }
  return ErrorCode::kBadArgument;
}

// v rotated by `angle` radians about unit axis k (Rodrigues).
core::Vec3 rotate(const core::Vec3& v, const core::Vec3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const core::Vec3 cross{k.y * v.z - k.z * v.y, k.z * v.x - k.x * v.z, k.x * v.y - k.y * v.x};
  const double dot = k.x * v.x + k.y * v.y + k.z * v.z;
  return {v.x * c + cross.x * s + k.x * dot * (1 - c), v.y * c + cross.y * s + k.y * dot * (1 - c),
          v.z * c + cross.z * s + k.z * dot * (1 - c)};
}

class Master {
 public:
  Master(const ServerOptions& o, int fd) : opt_(o), fd_(fd) {
    char buf[PATH_MAX];
    if (::realpath(o.dataDir.c_str(), buf)) root_ = buf;
  }
  void serve();

 private:
  void send(const proto::Message& m, std::uint32_t id, bool final = true) {
    const auto bytes = proto::encode(m, id, final ? proto::kFlagFinal : 0);
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (n <= 0) {
        if (n < 0 && errno == EINTR) continue;
        open_ = false;
        return;
      }
      done += std::size_t(n);
    }
  }
  void handle(const proto::Decoded& frame);
  void setScene(const proto::SetScene& s);
  core::Scene resolvedScene();
  void renderOne(const core::Scene& scene, std::uint32_t frameNumber, std::uint32_t id, bool final);

  const ServerOptions& opt_;
  int fd_;
  bool open_ = true;
  std::string root_;
  nlohmann::json doc_ = nlohmann::json::object();
  std::string volumePath_;
  std::unique_ptr<core::VolumeSource> source_;
  std::unique_ptr<core::Brick> brick_;
  std::unique_ptr<core::BrickRenderer> renderer_;
  core::ThreadPool pool_{0};
  std::uint32_t frames_ = 0;
};

void Master::setScene(const proto::SetScene& s) {
  nlohmann::json doc = doc_;
  if (!s.sceneJson.empty()) doc.merge_patch(nlohmann::json::parse(s.sceneJson));
  std::string path = volumePath_;
  if (!s.dataset.empty()) {
    char buf[PATH_MAX];
    const std::string wanted = s.dataset[0] == '/' ? s.dataset : root_ + "/" + s.dataset;
    const bool ok = ::realpath(wanted.c_str(), buf) && !root_.empty() &&
                    std::strncmp(buf, root_.c_str(), root_.size()) == 0 && buf[root_.size()] == '/';
    if (!ok) throw pvr::Error(pvr::ErrorCode::kInvalidArgument, "no dataset '" + s.dataset + "' in the data directory");
    path = buf;
  }
  if (!path.empty()) doc["volume"] = nlohmann::json{{"file", path}};
  if (doc.contains("volume")) core::parseScene(doc, root_);  // throws on a bad scene: the old one stays
  if (path != volumePath_) {
    auto source = core::openVolumeFile(path);
    auto brick = std::make_unique<core::Brick>(source->readAll());
    renderer_ = std::make_unique<core::BrickRenderer>(*brick);
    brick_ = std::move(brick);
    source_ = std::move(source);
    volumePath_ = path;
  }
  doc_ = std::move(doc);
}

core::Scene Master::resolvedScene() {
  if (!source_) throw pvr::Error(pvr::ErrorCode::kInvalidArgument, "no dataset: send SetScene with a dataset first");
  core::Scene scene = core::parseScene(doc_, root_);
  core::resolveDefaults(scene, source_->grid());
  return scene;
}

void Master::renderOne(const core::Scene& scene, std::uint32_t frameNumber, std::uint32_t id, bool final) {
  proto::ImageFrame f;
  f.frameNumber = frameNumber;
  f.width = std::uint32_t(scene.image.width);
  f.height = std::uint32_t(scene.image.height);
  f.format = proto::PixelFormat::kRgba8;
  f.compression = proto::Compression::kZlib;
  auto t = Clock::now();
  const core::RenderOptions options = core::renderOptionsFor(scene);
  renderer_->classify(scene.transfer, options);
  const core::Camera camera(scene.camera, scene.image.width, scene.image.height);
  const core::Image image = renderer_->render(camera, options, pool_);
  f.timing.render = secondsSince(t);
  t = Clock::now();
  const std::vector<std::uint8_t> raw = core::toSrgbRgba8(image, scene.image.background);
  uLongf size = compressBound(uLong(raw.size()));
  f.pixels.resize(size);
  if (compress2(f.pixels.data(), &size, raw.data(), uLong(raw.size()), Z_BEST_SPEED) != Z_OK)
    throw pvr::Error(pvr::ErrorCode::kInternal, "zlib compression failed");
  f.pixels.resize(size);
  f.timing.send = secondsSince(t);
  ++frames_;
  send(f, id, final);
}

void Master::handle(const proto::Decoded& frame) {
  const std::uint32_t id = frame.info.requestId;
  try {
    std::visit(
        [&](const auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, proto::Hello>) {
            send(proto::Welcome{"pvr-node 0.1", std::uint32_t(opt_.ranks), false}, id);
          } else if constexpr (std::is_same_v<T, proto::SessionOpen> || std::is_same_v<T, proto::SetLayout>) {
            send(proto::SessionReady{std::uint32_t(opt_.ranks), {{proto::ClusterRole::kRender, std::uint32_t(opt_.ranks), 0}}},
                 id);
          } else if constexpr (std::is_same_v<T, proto::StatusRequest>) {
            send(proto::StatusReply{{{"state", "session open"},
                                     {"ranks", std::to_string(opt_.ranks)},
                                     {"master_pid", std::to_string(::getpid())},
                                     {"dataset", volumePath_},
                                     {"frames_rendered", std::to_string(frames_)}}},
                 id);
          } else if constexpr (std::is_same_v<T, proto::SetScene>) {
            setScene(m);
            send(proto::Ok{}, id);
          } else if constexpr (std::is_same_v<T, proto::RenderFrame>) {
            renderOne(resolvedScene(), 0, id, true);
          } else if constexpr (std::is_same_v<T, proto::RenderRotation>) {
            if (m.stepsPerTurn == 0 || m.end < m.start || m.end - m.start >= 100000)
              throw pvr::Error(pvr::ErrorCode::kInvalidArgument, "rotation needs start <= end and stepsPerTurn >= 1");
            const double len = std::sqrt(m.axis[0] * m.axis[0] + m.axis[1] * m.axis[1] + m.axis[2] * m.axis[2]);
            if (!(len > 0)) throw pvr::Error(pvr::ErrorCode::kInvalidArgument, "rotation axis is zero");
            const core::Vec3 axis{m.axis[0] / len, m.axis[1] / len, m.axis[2] / len};
            const core::Scene base = resolvedScene();
            for (std::int32_t k = m.start; k <= m.end && open_; ++k) {
              core::Scene scene = base;
              const double angle = 2 * M_PI * double(k) / double(m.stepsPerTurn);
              const core::Vec3 c = base.camera.lookAt;
              const core::Vec3 e = rotate({base.camera.eye.x - c.x, base.camera.eye.y - c.y, base.camera.eye.z - c.z}, axis, angle);
              scene.camera.eye = {c.x + e.x, c.y + e.y, c.z + e.z};
              scene.camera.up = rotate(base.camera.up, axis, angle);
              renderOne(scene, std::uint32_t(k - m.start), id, k == m.end);
            }
          } else if constexpr (std::is_same_v<T, proto::Cancel>) {
            send(proto::Ok{}, id);  // requests run one at a time: the target has finished
          } else if constexpr (std::is_same_v<T, proto::Close>) {
            open_ = false;
          } else {
            send(proto::ErrorMessage{ErrorCode::kUnsupported, std::string(T::kWire.name) + " is not served by pvr-node"}, id);
          }
        },
        frame.message);
  } catch (const std::exception& e) {
    send(proto::ErrorMessage{wireCode(e), e.what()}, id);
  }
}

void Master::serve() {
  proto::FrameDecoder decoder;
  std::vector<std::uint8_t> buf(64 << 10);
  while (open_) {
    const ssize_t n = ::read(fd_, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    decoder.feed(std::span(buf.data(), std::size_t(n)));
    while (auto frame = decoder.pop()) {
      handle(*frame);
      if (!open_) break;
    }
    if (decoder.error()) {
      send(proto::ErrorMessage{decoder.error()->code, decoder.error()->text}, 0);
      break;
    }
  }
}

int connectTo(const std::string& host, int port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(std::uint16_t(port));
  if (::inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1) return -1;
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
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
  int status = 0;
  if (options.rank == 0) {
    const int fd = connectTo(options.host, options.port);
    if (fd < 0) {
      std::fprintf(stderr, "pvr-node: rank 0 cannot connect to %s:%d: %s\n", options.host.c_str(), options.port,
                   std::strerror(errno));
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    Master(options, fd).serve();
    ::close(fd);
  }
  // The other ranks wait without spinning a core until the master is done.
  MPI_Request request;
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  int finished = 0;
  while (!finished) {
    MPI_Test(&request, &finished, MPI_STATUS_IGNORE);
    if (!finished) ::usleep(20000);
  }
  return status;
}

}  // namespace pvr::runtime
