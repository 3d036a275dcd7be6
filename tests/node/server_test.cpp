// pvr-node --server under real mpirun, driven by this test as the session
// handler would: listen on loopback, start the job, speak the protocol.
// Every frame must equal an in-process BrickRenderer rendering of the same
// view within 1e-5 (the job writes its float frames with --dump-frames),
// in order, for each layout of the session; failures injected on one rank
// (--fail-once STEP@RANK) reach the client and leave the session serving.
// The master's first frame is JobHello with the job's PVR_JOB_SECRET; a
// rank that cannot read the data names its host and the file.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <list>
#include <map>
#include <sstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "../proc_files.h"
#include "camera.h"
#include "computation_run.h"
#include "frame_pixels.h"
#include "in_process_communicator.h"
#include "io/volume_io.h"
#include "pvr_protocol.h"
#include "raycast/raycaster.h"
#include "raycast/scene_renderer.h"
#include "scene_volume.h"
#include "scene.h"
#include "secure_channel.h"
#include "strategy.h"
#include "thread_pool.h"
#include "value_histogram.h"

namespace {

using namespace pvr;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using proto::ClusterRole;

const fs::path kTmp = PVR_TEST_TMP;
constexpr int kDims[3] = {40, 36, 33};
// A directory of the data directory that the last rank of a job may be
// made to see empty (Launch::hiddenFromLastRank).
const fs::path kHidden = kTmp / "data" / "hidden";

// ctest runs several of these test processes at once, each writing the
// same data files while the others' ranks read them: every file is
// written under a scratch directory of this process and renamed into place,
// so a reader sees a whole file (the same bytes from every writer).
template <typename Write>
void writeAtomically(const fs::path& dir, Write write) {
  const fs::path scratch = dir / (".scratch-" + std::to_string(::getpid()));
  fs::create_directories(scratch);
  write(scratch);
  for (const auto& entry : fs::directory_iterator(scratch)) fs::rename(entry.path(), dir / entry.path().filename());
  fs::remove_all(scratch);
}

// A float32 raw volume with its JSON sidecar in `dir`.
void writeVolume(const fs::path& dir) {
  fs::create_directories(dir);
  const core::Brick whole = core::openProcedural("shepp-logan", {kDims[0], kDims[1], kDims[2]})->readAll();
  const auto nodes = whole.stored().nodeCount();
  REQUIRE(whole.byteSize() == std::size_t(nodes) * 4);
  auto writeRaw = [&](const fs::path& path) {
    std::ofstream raw(path, std::ios::binary);
    raw.write(reinterpret_cast<const char*>(whole.bytes()), std::streamsize(whole.byteSize()));
  };
  writeAtomically(dir, [&](const fs::path& scratch) {
    writeRaw(scratch / "phantom.raw");
    std::ofstream(scratch / "phantom.json") << nlohmann::json{{"dims", {kDims[0], kDims[1], kDims[2]}},
                                                              {"dtype", "float32"},
                                                              {"spacing", {1.0, 1.0, 1.25}},
                                                              {"raw_file", "phantom.raw"}}
                                                   .dump();
    std::ofstream(scratch / "split.json") << nlohmann::json{{"dims", {kDims[0], kDims[1], kDims[2]}},
                                                            {"dtype", "float32"},
                                                            {"spacing", {1.0, 1.0, 1.25}},
                                                            {"raw_file", "hidden/split.raw"}}
                                                 .dump();
  });
  // The same volume with its voxels under kHidden, which one rank may be
  // made not to see.
  fs::create_directories(kHidden);
  writeAtomically(kHidden, [&](const fs::path& scratch) { writeRaw(scratch / "split.raw"); });
}

// Early termination off: each brick stops its own part of a ray, so with
// it several ranks' frames equal one process's only to 1e-4 a brick
// (scene.h kDefaultEarlyTermination), and these tests compare them to 1e-5.
const char* kScene = R"({
  "transfer_function": {"points": [[0, 0, 0, 0, 0], [0.15, 0.3, 0.5, 1, 0.05], [0.3, 1, 0.8, 0.3, 0.3], [1, 1, 1, 1, 0.6]]},
  "image": {"width": 64, "height": 64, "background": [0, 0, 0, 1]},
  "sampling": {"early_termination": 1},
  "shading": {"enabled": true}})";

// What pvrd would hand a job: a 64-hex-digit one-time secret.
const std::string kSecret = "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff";

// This host's name, as every rank of a job on it reports it.
std::string thisHost() {
  char name[256] = {};
  REQUIRE(::gethostname(name, sizeof name - 1) == 0);
  return name;
}

// True when this process may make mount namespaces (root, or a system
// that allows unprivileged ones).
bool canUnshareMounts() { return std::system("unshare -m true 2>/dev/null") == 0; }

// How the handler starts a job besides its rank count and options.
struct Launch {
  std::optional<std::string> secret = kSecret;  // PVR_JOB_SECRET; nullopt: not set
  // The last rank runs in a mount namespace of its own where kHidden is an
  // empty tmpfs: a host of a cluster whose copy of the data lacks files.
  bool hiddenFromLastRank = false;
};

// The handler's side of one job, as pvrd's: every byte inside the secure
// channel keyed by the job secret. The constructor checks the handshake
// and the master's first frame: JobHello with the secret the job was
// given. Without a secret the master refuses to connect at all.
class Job {
 public:
  // `extra`: more pvr-node options.
  explicit Job(int ranks, const std::vector<std::string>& extra = {}, const Launch& launch = {}) {
    dumpDir_ = kTmp / ("frames-" + std::to_string(ranks) + "-" + std::to_string(::getpid()));
    fs::remove_all(dumpDir_);
    fs::create_directories(dumpDir_);
    listen_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(::bind(listen_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
    REQUIRE(::listen(listen_, 1) == 0);
    socklen_t len = sizeof addr;
    ::getsockname(listen_, reinterpret_cast<sockaddr*>(&addr), &len);
    std::vector<std::string> node{PVR_NODE_PATH, "--server", "--connect",
                                  "127.0.0.1:" + std::to_string(ntohs(addr.sin_port)), "--data-dir",
                                  (kTmp / "data").string(), "--dump-frames", dumpDir_.string()};
    node.insert(node.end(), extra.begin(), extra.end());
    // As pvrd does: the secret in mpirun's environment and passed on with
    // -x (a remote rank 0 would not inherit it otherwise), never in argv.
    std::vector<std::string> args{PVR_MPIRUN, "--oversubscribe", "--bind-to", "none"};
    if (launch.secret) args.insert(args.end(), {"-x", "PVR_JOB_SECRET"});
    if (launch.hiddenFromLastRank) {
      // Two application contexts: ranks 0 .. N-2 as usual, then rank N-1
      // through unshare, which mounts the empty tmpfs and execs pvr-node.
      args.insert(args.end(), {"-np", std::to_string(ranks - 1)});
      args.insert(args.end(), node.begin(), node.end());
      args.insert(args.end(), {":", "-np", "1", "unshare", "-m", "sh", "-c",
                               "mount -t tmpfs pvr-test-hidden \"$0\" && exec \"$@\"", kHidden.string()});
    } else {
      args.insert(args.end(), {"-np", std::to_string(ranks)});
    }
    args.insert(args.end(), node.begin(), node.end());
    pid_ = ::fork();
    if (pid_ == 0) {
      ::setpgid(0, 0);
      ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
      ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
      if (launch.secret) ::setenv("PVR_JOB_SECRET", launch.secret->c_str(), 1);
      else ::unsetenv("PVR_JOB_SECRET");
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execvp(argv[0], argv.data());
      ::_exit(127);
    }
    ::setpgid(pid_, pid_);
    if (!launch.secret) return;
    channel_ = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kServer, *launch.secret,
                                                      proto::kConnectBackPurpose);
    pollfd p{listen_, POLLIN, 0};
    REQUIRE(::poll(&p, 1, 60000) == 1);
    fd_ = ::accept4(listen_, nullptr, nullptr, SOCK_CLOEXEC);
    REQUIRE(fd_ >= 0);
    // The first frame: the secret, answering no request.
    auto hello = receive();
    REQUIRE(hello);
    REQUIRE(std::holds_alternative<proto::JobHello>(hello->message));
    CHECK(hello->info.requestId == 0);
    CHECK(std::get<proto::JobHello>(hello->message).secret == *launch.secret);
    CHECK(channel_->established());
  }
  ~Job() {
    if (fd_ >= 0) ::close(fd_);
    ::close(listen_);
    if (pid_ > 0 && !reaped_) {
      // Close makes the job end by itself; kill what is left after 20 s.
      const auto until = Clock::now() + std::chrono::seconds(20);
      int status = 0;
      while (::waitpid(pid_, &status, WNOHANG) == 0) {
        if (Clock::now() > until) {
          ::kill(-pid_, SIGKILL);
          ::waitpid(pid_, &status, 0);
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
  }
  pid_t pid() const { return pid_; }
  const fs::path& dumpDir() const { return dumpDir_; }

  std::uint32_t send(const proto::Message& m) {
    REQUIRE_FALSE(channel_->send(proto::encode(m, ++id_, proto::kFlagFinal)));
    flush();
    return id_;
  }
  // Sends `messages` in one write, so that the master's link reads them
  // together; their request ids.
  std::vector<std::uint32_t> sendTogether(const std::vector<proto::Message>& messages) {
    std::vector<std::uint32_t> ids;
    for (const auto& m : messages) {
      REQUIRE_FALSE(channel_->send(proto::encode(m, ++id_, proto::kFlagFinal)));
      ids.push_back(id_);
    }
    flush();
    return ids;
  }
  // True when a connection came to the handler's socket within `seconds`.
  bool connected(int seconds) {
    pollfd p{listen_, POLLIN, 0};
    return fd_ >= 0 || ::poll(&p, 1, seconds * 1000) == 1;
  }
  // The next message from the master, Heartbeats dropped and counted as
  // pvrd drops them; nullopt when the connection ended.
  std::optional<proto::Decoded> receive(int timeoutSeconds = 60) {
    for (;;) {
      auto d = receiveAny(timeoutSeconds);
      if (!d || !std::holds_alternative<proto::Heartbeat>(d->message)) return d;
      ++heartbeats_;
    }
  }
  int heartbeats() const { return heartbeats_; }
  // The next frame from the master, Heartbeats included.
  std::optional<proto::Decoded> receiveAny(int timeoutSeconds = 60) {
    const auto until = Clock::now() + std::chrono::seconds(timeoutSeconds);
    for (;;) {
      if (auto d = decoder_.pop()) return d;
      REQUIRE_FALSE(decoder_.error());
      const int left = int(std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count());
      REQUIRE(left > 0);
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, left) <= 0) continue;
      std::uint8_t buf[1 << 16];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) return std::nullopt;
      const auto failure = channel_->receive(std::span(buf, std::size_t(n)));
      flush();
      if (failure) FAIL("secure channel: " << failure->text);
      decoder_.feed(channel_->takeIncoming());
    }
  }
  template <typename T>
  T expect() {
    auto d = receive();
    REQUIRE(d);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) FAIL("Error from the master: " << e->text);
    REQUIRE(std::holds_alternative<T>(d->message));
    return std::get<T>(d->message);
  }
  proto::ErrorMessage expectError() {
    auto d = receive();
    REQUIRE(d);
    REQUIRE(std::holds_alternative<proto::ErrorMessage>(d->message));
    return std::get<proto::ErrorMessage>(d->message);
  }
  // Closes the session; true if the job then ended by itself within 30 s.
  bool close() {
    send(proto::Close{"done"});
    return reap(30);
  }
  // Waits for mpirun to exit; true if it did within `seconds`.
  bool reap(int seconds) {
    const auto until = Clock::now() + std::chrono::seconds(seconds);
    int status = 0;
    while (Clock::now() < until) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) return reaped_ = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

 private:
  void flush() {
    const std::vector<std::uint8_t> bytes = channel_->takeOutgoing();
    REQUIRE(::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) == ssize_t(bytes.size()));
  }

  int listen_ = -1, fd_ = -1;
  std::unique_ptr<proto::SecureChannel> channel_;
  pid_t pid_ = -1;
  bool reaped_ = false;
  std::uint32_t id_ = 0;
  int heartbeats_ = 0;
  proto::FrameDecoder decoder_;
  fs::path dumpDir_;
};

// The reference: the whole volume rendered in this process.
class Reference {
 public:
  // `file`: the volume in the data directory.
  explicit Reference(const nlohmann::json& patch, const std::string& file = "phantom.json") {
    nlohmann::json doc = nlohmann::json::parse(kScene);
    doc.merge_patch(patch);
    doc["volume"] = {{"file", (kTmp / "data" / file).string()}};
    scene_ = core::parseScene(doc, "");
    source_ = core::openVolumeFile((kTmp / "data" / file).string());
    core::resolveDefaults(scene_, source_->grid());
    brick_ = source_->readAll();
    renderer_ = std::make_unique<core::BrickRenderer>(brick_);
    options_ = core::renderOptionsFor(scene_);
    renderer_->classify(scene_.volumes.front().transfer, options_);
  }
  const core::Scene& scene() const { return scene_; }
  const core::ValueRange& valueRange() const { return brick_.valueRange(); }
  // Frame k of RenderRotation{axis (0,1,0) or given, 0.., steps}: eye and
  // up turned about look_at (docs/protocol.md), written out here apart
  // from the node's rotation.cpp.
  core::Image frame(int k, int steps, core::Vec3 axis = {0, 1, 0}) const {
    core::CameraSpec c = scene_.camera;
    const double angle = 2 * M_PI * double(k) / double(steps);
    const auto rotate = [&](const core::Vec3& v) {
      const double co = std::cos(angle), s = std::sin(angle);
      const core::Vec3 cross{axis.y * v.z - axis.z * v.y, axis.z * v.x - axis.x * v.z, axis.x * v.y - axis.y * v.x};
      const double dot = axis.x * v.x + axis.y * v.y + axis.z * v.z;
      return core::Vec3{v.x * co + cross.x * s + axis.x * dot * (1 - co), v.y * co + cross.y * s + axis.y * dot * (1 - co),
                        v.z * co + cross.z * s + axis.z * dot * (1 - co)};
    };
    if (k != 0) {
      c.eye = scene_.camera.lookAt + rotate(scene_.camera.eye - scene_.camera.lookAt);
      c.up = rotate(scene_.camera.up);
    }
    const core::Camera camera(c, scene_.image.width, scene_.image.height);
    return renderer_->render(camera, options_, pool_).toFullFrame();
  }

 private:
  core::Scene scene_;
  std::unique_ptr<core::VolumeSource> source_;
  core::Brick brick_;
  std::unique_ptr<core::BrickRenderer> renderer_;
  core::RenderOptions options_;
  mutable core::ThreadPool pool_{1};
};

// The reference for a scene of several volumes: the whole volumes mixed
// in one SceneRenderer (a scene of one goes through its BrickRenderer
// there, as the ranks' one-volume path does). `doc` names data files by
// "dataset" as a client does; they are the data directory's.
class SceneReference {
 public:
  explicit SceneReference(nlohmann::json doc) {
    for (auto& v : doc["volumes"])
      if (v.contains("dataset")) {
        v["file"] = (kTmp / "data" / v["dataset"].get<std::string>()).string();
        v.erase("dataset");
      }
    scene_ = core::parseScene(doc, "");
    std::vector<core::GridGeometry> grids;
    for (const core::SceneVolume& v : scene_.volumes) {
      bricks_.push_back(core::openSceneVolume(v.source)->readAll());
      grids.push_back(bricks_.back().grid());
    }
    core::resolveDefaults(scene_, grids);
    std::vector<const core::Brick*> whole;
    for (const core::Brick& b : bricks_) whole.push_back(&b);
    renderer_ = std::make_unique<core::SceneRenderer>(whole);
    options_ = core::renderOptionsFor(scene_);
    renderer_->classify(scene_.volumes, options_);
  }
  core::Image frame() const {
    const core::Camera camera(scene_.camera, scene_.image.width, scene_.image.height);
    return renderer_->render(camera, options_, pool_).toFullFrame();
  }

 private:
  core::Scene scene_;
  std::list<core::Brick> bricks_;
  std::unique_ptr<core::SceneRenderer> renderer_;
  core::RenderOptions options_;
  mutable core::ThreadPool pool_{1};
};

core::Image dumped(const Job& job, std::uint32_t request, int frame) {
  const fs::path path = job.dumpDir() / ("frame-" + std::to_string(request) + "-" + std::to_string(frame) + ".f32");
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  std::int32_t size[2];
  in.read(reinterpret_cast<char*>(size), sizeof size);
  core::Image image = core::Image::fullFrame(size[0], size[1]);
  in.read(reinterpret_cast<char*>(image.pixels().data()), std::streamsize(image.pixels().size() * sizeof(core::Rgba)));
  REQUIRE(in);
  return image;
}

// A sequence's frames: in order, the last FINAL, frame k equal to want(k).
// `timings`, when given, gets each frame's timing.
void checkFrames(Job& job, std::uint32_t request, int frames, const std::function<core::Image(int)>& want,
                 std::vector<proto::FrameTiming>* timings = nullptr) {
  for (int k = 0; k < frames; ++k) {
    auto d = job.receive();
    REQUIRE(d);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) FAIL("frame " << k << ": " << e->text);
    const auto& f = std::get<proto::ImageFrame>(d->message);
    CHECK(d->info.requestId == request);
    CHECK(f.frameNumber == std::uint32_t(k));
    CHECK(d->info.final() == (k == frames - 1));
    CHECK(f.timing.render > 0);
    if (timings) timings->push_back(f.timing);
    const double diff = core::maxAbsDifference(dumped(job, request, k), want(k));
    INFO("frame " << k);
    CHECK(diff <= 1e-5);
  }
}

// A rotation of `steps` steps per turn: frame k is the reference turned k steps.
void checkSequence(Job& job, std::uint32_t request, int frames, int steps, const Reference& ref) {
  checkFrames(job, request, frames, [&](int k) { return ref.frame(k, steps); });
}

// A status reply's entries as a map.
std::map<std::string, std::string> entriesOf(const proto::StatusReply& reply) {
  std::map<std::string, std::string> out;
  for (const auto& kv : reply.entries) out[kv.key] = kv.value;
  return out;
}

// "list status" as a map.
std::map<std::string, std::string> statusOf(Job& job) {
  job.send(proto::StatusRequest{});
  return entriesOf(job.expect<proto::StatusReply>());
}

// The numbers of a Tcl list of numbers.
std::vector<double> numbers(const std::string& list) {
  std::istringstream in(list);
  std::vector<double> out;
  for (std::string word; in >> word;) out.push_back(std::stod(word));
  return out;
}

// A time series of kSteps steps (docs/scene.md, series sidecar): step k is
// the phantom with its values times 1 - 0.2 k, in series_K.json + .raw,
// listed by series.series.json.
constexpr int kSteps = 4;
const char* kSeries = "series.series.json";
std::string stepFile(int k) { return "series_" + std::to_string(k) + ".json"; }

void writeSeries(const fs::path& dir) {
  const core::Brick whole = core::openProcedural("shepp-logan", {kDims[0], kDims[1], kDims[2]})->readAll();
  writeAtomically(dir, [&](const fs::path& scratch) {
    nlohmann::json steps = nlohmann::json::array();
    for (int k = 0; k < kSteps; ++k) {
      core::Brick step = whole;
      float* v = step.as<float>();
      for (std::int64_t i = 0; i < step.stored().nodeCount(); ++i) v[i] *= float(1 - 0.2 * k);
      core::writeRawJsonVolume(step, scratch.string(), "series_" + std::to_string(k), "step " + std::to_string(k));
      steps.push_back({{"time", 0.5 * k}, {"file", stepFile(k)}});
    }
    std::ofstream(scratch / kSeries) << nlohmann::json{{"series", steps}}.dump();
  });
}

struct Fixture {
  Fixture() {
    static bool written = false;
    if (!written) {
      writeVolume(kTmp / "data");
      writeSeries(kTmp / "data");
    }
    written = true;
  }
};

}  // namespace

TEST_CASE_METHOD(Fixture, "clusters, groups and a compositing cluster all render what pvr-render renders") {
  Job job(4, {"--fail-once", "render@2"});
  job.send(proto::Hello{"runtime test"});
  job.expect<proto::Welcome>();
  job.send(proto::SessionOpen{4, {}, ""});
  const auto ready = job.expect<proto::SessionReady>();
  REQUIRE(ready.clusters.size() == 1);
  CHECK(ready.clusters[0].ranks == 4);
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  const Reference ref(nlohmann::json::object());
  // An action failing on one rank: the client reads that rank's error and
  // the next render works.
  job.send(proto::RenderFrame{});
  const auto e = job.expectError();
  CHECK_THAT(e.text, Catch::Contains("rank 2 on " + thisHost() + ": injected failure in render"));

  SECTION("one cluster compositing itself; memory and latency reports") {
    const auto id = job.send(proto::RenderFrame{});
    checkSequence(job, id, 1, 1, ref);

    // Memory: each of the 4 ranks at most 1/4 of the volume plus ghosts plus 10 %.
    job.send(proto::PerformanceRequest{proto::PerformanceQuery::kMemory, proto::kAllClusters});
    const auto memory = nlohmann::json::parse(job.expect<proto::PerformanceReply>().json);
    const double volume = memory["volume_bytes"].get<double>();
    const int ghost = memory["ghost_layers"].get<int>();
    const double faces = 2.0 * ghost * (kDims[0] * kDims[1] + kDims[1] * kDims[2] + kDims[0] * kDims[2]) * 4;
    REQUIRE(memory["clusters"].size() == 1);
    for (const auto& b : memory["clusters"][0]["bytes_per_rank"]) {
      CHECK(b.get<double>() > 0);
      CHECK(b.get<double>() <= volume / 4 * 1.1 + faces);
    }
    // The latency model beside the measured value.
    job.send(proto::PerformanceRequest{proto::PerformanceQuery::kCompositing, proto::kAllClusters});
    const auto latency = nlohmann::json::parse(job.expect<proto::PerformanceReply>().json);
    REQUIRE(latency["clusters"].size() == 1);
    CHECK(latency["clusters"][0]["model_seconds"].get<double>() > 0);
    CHECK(latency["clusters"][0]["measured_seconds"].get<double>() > 0);
    CHECK(latency["calibration"]["latency_seconds"].get<double>() > 0);
  }
  SECTION("two clusters in one group split the scanlines") {
    job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kRender, 2, 0}}});
    CHECK(job.expect<proto::SessionReady>().clusters.size() == 2);
    const auto id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 2, 12});
    checkSequence(job, id, 3, 12, ref);
  }
  SECTION("two groups pipeline a 12-frame rotation, frames in order") {
    job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kRender, 2, 1}}});
    job.expect<proto::SessionReady>();
    const auto id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 11, 12});
    checkSequence(job, id, 12, 12, ref);
  }
  SECTION("a separate compositing cluster; then rank 0 as a dedicated collector") {
    job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 2, 0}}});
    job.expect<proto::SessionReady>();
    auto id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 2, 12});
    checkSequence(job, id, 3, 12, ref);
    job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 1, 0}}});
    const auto ready3 = job.expect<proto::SessionReady>();
    CHECK(ready3.clusters[0].role == ClusterRole::kCollector);
    id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 2, 12});
    checkSequence(job, id, 3, 12, ref);
  }
  SECTION("content balance: a new transfer function rebalances; RGB8 with RLE decodes") {
    job.send(proto::SetScene{"", R"({"runtime": {"decomposition": "balanced", "rebalance_threshold": 1.0001, "pixels": "rgb8", "compression": "rle"}})"});
    job.expect<proto::Ok>();
    // Only the inner structures, which the phantom places off-centre.
    const char* narrow =
        R"({"transfer_function": {"points": [[0, 0, 0, 0, 0], [0.22, 0, 0, 0, 0], [0.3, 1, 0.9, 0.8, 0.8], [0.38, 0, 0, 0, 0], [1, 0, 0, 0, 0]]}})";
    job.send(proto::SetScene{"", narrow});
    job.expect<proto::Ok>();
    job.send(proto::StatusRequest{});
    for (const auto& kv : job.expect<proto::StatusReply>().entries)
      if (kv.key == "rebalances") CHECK(std::stoi(kv.value) >= 1);
    const auto id = job.send(proto::RenderFrame{});
    auto d = job.receive();
    REQUIRE(d);
    REQUIRE(std::holds_alternative<proto::ImageFrame>(d->message));
    const auto& f = std::get<proto::ImageFrame>(d->message);
    CHECK(f.format == proto::PixelFormat::kRgb8);
    const auto decoded = proto::decompressPixels(f);
    REQUIRE(std::holds_alternative<std::vector<std::uint8_t>>(decoded));
    CHECK(std::get<std::vector<std::uint8_t>>(decoded).size() == 64 * 64 * 3);
    const Reference narrowRef(nlohmann::json::parse(narrow));
    CHECK(core::maxAbsDifference(dumped(job, id, 0), narrowRef.frame(0, 1)) <= 1e-5);
  }
  CHECK(job.close());
}

// Frames of RenderTimeSteps k = 0.., each the in-process rendering of its
// step's own volume file at the session's view.
void checkTimeSequence(Job& job, std::uint32_t request, const std::vector<int>& steps) {
  checkFrames(job, request, int(steps.size()), [&](int k) {
    return Reference(nlohmann::json::object(), stepFile(steps[std::size_t(k)])).frame(0, 1);
  });
}

// A session of the job's ranks showing the series.
void openSeries(Job& job) {
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{kSeries, kScene});
  job.expect<proto::Ok>();
}

// The 256-bin histogram of a serial count of the volume `file` (in the
// data directory) over its own range, as status reports it.
std::vector<double> serialHistogram(const std::string& file) {
  const core::Brick whole = core::openVolumeFile((kTmp / "data" / file).string())->readAll();
  REQUIRE(whole.fineHistogram());
  const auto bins = core::binHistogram(*whole.fineHistogram(), whole.valueRange().min, whole.valueRange().max);
  return {bins.begin(), bins.end()};
}

// performance cache summed over the render ranks: {hits, misses}.
std::pair<std::uint64_t, std::uint64_t> cacheCounts(Job& job) {
  job.send(proto::PerformanceRequest{proto::PerformanceQuery::kCache, proto::kAllClusters});
  const auto reply = nlohmann::json::parse(job.expect<proto::PerformanceReply>().json);
  std::uint64_t hits = 0, misses = 0;
  for (const auto& r : reply["ranks"]) {
    hits += r["hits"].get<std::uint64_t>();
    misses += r["misses"].get<std::uint64_t>();
    CHECK(r["bytes"].get<std::uint64_t>() <= reply["budget_bytes"].get<std::uint64_t>());
    CHECK(r["read_ahead_s"].get<double>() >= 0);
    // One thread's CPU over the reads it timed: within their wall time.
    CHECK(r["read_ahead_cpu_s"].get<double>() >= 0);
    CHECK(r["read_ahead_cpu_s"].get<double>() <= r["read_ahead_s"].get<double>() + 1e-3);
  }
  return {hits, misses};
}

TEST_CASE_METHOD(Fixture, "render time: each frame equals its step's volume, and the cache hits on a second pass", "[series]") {
  Job job(2, {});
  openSeries(job);
  auto status = statusOf(job);
  CHECK(status["timestep"] == "0");
  CHECK(status["timesteps"] == std::to_string(kSteps));
  CHECK(numbers(status["timestep_times"]) == std::vector<double>{0, 0.5, 1, 1.5});
  CHECK_THAT(status["cache"], Catch::StartsWith("read-ahead: budget 256 MB holds 4 of 4 steps"));

  auto id = job.send(proto::RenderTimeSteps{0, 3, 1});
  checkTimeSequence(job, id, {0, 1, 2, 3});
  const auto [hits1, misses1] = cacheCounts(job);
  // Every step is now held: a second pass reads nothing.
  id = job.send(proto::RenderTimeSteps{1, 3, 2});
  checkTimeSequence(job, id, {1, 3});
  const auto [hits2, misses2] = cacheCounts(job);
  CHECK(misses2 == misses1);
  CHECK(hits2 == hits1 + 2 * 2);  // two steps on two ranks

  // The session's step stays 0 after a time request; set -timestep picks
  // another, and a rotation keeps it.
  CHECK(statusOf(job)["timestep"] == "0");
  job.send(proto::SetScene{"", R"({"timestep": 2})"});
  job.expect<proto::Ok>();
  status = statusOf(job);
  CHECK(status["timestep"] == "2");
  // Steps are read without the histogram's counts (node/data.cpp,
  // countHistogram): the step the session moved to, taken from the cache,
  // reports the histogram of a serial count of its volume when asked.
  CHECK(numbers(status["histogram"]) == serialHistogram(stepFile(2)));
  const core::ValueRange range2 = core::openVolumeFile((kTmp / "data" / stepFile(2)).string())->readAll().valueRange();
  CHECK(numbers(status["value_range"]) == std::vector<double>{range2.min, range2.max});
  id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 2, 12});
  const Reference step2(nlohmann::json::object(), stepFile(2));
  checkSequence(job, id, 3, 12, step2);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "steps read ahead are classified ahead, and again when the transfer function changes", "[series]") {
  Job job(2, {});
  openSeries(job);
  // Steps 1-3 are read ahead while the frame before renders, and
  // classified there: their frames charge no reading and no preprocessing.
  std::vector<proto::FrameTiming> timings;
  auto id = job.send(proto::RenderTimeSteps{0, 3, 1});
  checkFrames(job, id, 4, [&](int k) { return Reference(nlohmann::json::object(), stepFile(k)).frame(0, 1); },
              &timings);
  REQUIRE(timings.size() == 4);
  for (int k = 1; k < 4; ++k) {
    INFO("frame " << k);
    CHECK(timings[std::size_t(k)].read == 0);
    CHECK(timings[std::size_t(k)].preprocess == 0);
  }
  // A transfer function set after they were read ahead: held steps 1 and
  // 2 were classified under the old one and are classified again when
  // shown; step 3, on screen when it changed, was classified then.
  const char* narrow =
      R"({"transfer_function": {"points": [[0, 0, 0, 0, 0], [0.22, 0, 0, 0, 0], [0.3, 1, 0.9, 0.8, 0.8], [0.38, 0, 0, 0, 0], [1, 0, 0, 0, 0]]}})";
  job.send(proto::SetScene{"", narrow});
  job.expect<proto::Ok>();
  timings.clear();
  id = job.send(proto::RenderTimeSteps{1, 3, 1});
  checkFrames(job, id, 3,
              [&](int k) { return Reference(nlohmann::json::parse(narrow), stepFile(1 + k)).frame(0, 1); }, &timings);
  REQUIRE(timings.size() == 3);
  CHECK(timings[0].preprocess > 0);
  CHECK(timings[1].preprocess > 0);
  CHECK(timings[2].preprocess == 0);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a caching cluster renders the same frames, and its render ranks read no step after the first", "[series]") {
  // Rank 0 the dedicated master, ranks 1-2 render, rank 3 caches for them.
  Job job(4, {});
  job.send(proto::SessionOpen{4, {{ClusterRole::kRender, 2, 0}, {ClusterRole::kCache, 1, 0}}, ""});
  const auto ready = job.expect<proto::SessionReady>();
  REQUIRE(ready.clusters.size() == 3);
  CHECK(ready.clusters[2].role == ClusterRole::kCache);
  job.send(proto::SetScene{kSeries, kScene});
  job.expect<proto::Ok>();
  // performance cache by role: {hits, misses} of the cache rank, misses of the render ranks.
  const auto counts = [&] {
    job.send(proto::PerformanceRequest{proto::PerformanceQuery::kCache, proto::kAllClusters});
    const auto reply = nlohmann::json::parse(job.expect<proto::PerformanceReply>().json);
    std::uint64_t hits = 0, misses = 0, renderMisses = 0;
    for (const auto& r : reply["ranks"]) {
      if (r["role"] == "cache") {
        hits += r["hits"].get<std::uint64_t>();
        misses += r["misses"].get<std::uint64_t>();
      } else {
        renderMisses += r["misses"].get<std::uint64_t>();
      }
    }
    return std::array<std::uint64_t, 3>{hits, misses, renderMisses};
  };
  auto id = job.send(proto::RenderTimeSteps{0, 3, 1});
  checkTimeSequence(job, id, {0, 1, 2, 3});
  const auto first = counts();
  CHECK(first[0] + first[1] == 3 * 2);  // steps 1-3 for two render ranks
  CHECK(first[2] == 0);
  // Every step the cache rank sent is still held: a second pass hits.
  id = job.send(proto::RenderTimeSteps{1, 3, 2});
  checkTimeSequence(job, id, {1, 3});
  const auto second = counts();
  CHECK(second[0] == first[0] + 2 * 2);
  CHECK(second[1] == first[1]);
  CHECK(second[2] == 0);
  // set -timestep goes through the cache rank too; a rotation keeps the step.
  job.send(proto::SetScene{"", R"({"timestep": 2})"});
  job.expect<proto::Ok>();
  // The render ranks preprocess a step they receive without the
  // histogram's counts; the step moved to reports a serial count's.
  CHECK(numbers(statusOf(job)["histogram"]) == serialHistogram(stepFile(2)));
  id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 1, 12});
  checkSequence(job, id, 2, 12, Reference(nlohmann::json::object(), stepFile(2)));
  CHECK(counts()[2] == 0);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a bad step is a clear error and the session serves on, and a budget below one step reads on demand", "[series]") {
  Job job(2, {});
  openSeries(job);

  job.send(proto::RenderTimeSteps{0, 9, 1});
  auto e = job.expectError();
  CHECK(e.code == proto::ErrorCode::kBadArgument);
  CHECK_THAT(e.text, Catch::Contains("step 9 is past the last step 3"));
  job.send(proto::SetScene{"", R"({"timestep": 7})"});
  e = job.expectError();
  CHECK_THAT(e.text, Catch::Contains("timestep 7") && Catch::Contains("has 4 time steps"));
  CHECK(statusOf(job)["timestep"] == "0");

  // A budget of 0 MB holds no step: every step is read when shown.
  job.send(proto::SetScene{"", R"({"runtime": {"cachemem": 0}})"});
  job.expect<proto::Ok>();
  CHECK_THAT(statusOf(job)["cache"], Catch::StartsWith("on demand: budget 0 MB is below one step's"));
  const auto [hits0, misses0] = cacheCounts(job);
  auto id = job.send(proto::RenderTimeSteps{1, 3, 1});
  checkTimeSequence(job, id, {1, 2, 3});
  id = job.send(proto::RenderTimeSteps{1, 3, 1});
  checkTimeSequence(job, id, {1, 2, 3});
  const auto [hits1, misses1] = cacheCounts(job);
  CHECK(hits1 == hits0);
  CHECK(misses1 == misses0 + 2 * 6);  // six steps shown on two ranks, none held
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a step that one rank fails to read fails its frame, and the next request shows every step", "[series]") {
  // A wave's step is taken per rank without an agreement (showStep,
  // StepFailure::kOwn): rank 0 shows step 1 while rank 1 failed to, the
  // failure reaches the client with rank 1's sub-image, and rank 1 reads
  // the step again when it is next shown.
  Job job(2, {"--fail-once", "step@1"});
  openSeries(job);
  job.send(proto::RenderTimeSteps{1, 3, 1});
  CHECK_THAT(job.expectError().text, Catch::Contains("rank 1 on " + thisHost() + ": injected failure in step"));
  auto id = job.send(proto::RenderTimeSteps{1, 3, 1});
  checkTimeSequence(job, id, {1, 2, 3});
  id = job.send(proto::RenderTimeSteps{0, 1, 1});
  checkTimeSequence(job, id, {0, 1});
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a failure on a rank that sends to a compositing cluster, or on a compositing rank, reaches the client") {
  Job job(4, {"--fail-once", "render@1", "--fail-once", "composite@2"});
  job.send(proto::SessionOpen{4, {{ClusterRole::kRender, 3, 0}, {ClusterRole::kComposite, 1, 0}}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  const Reference ref(nlohmann::json::object());
  // Ranks 0-2 render and send their sub-images to rank 3, which sends the
  // band to the collector: rank 1's failure travels with its sub-image.
  job.send(proto::RenderFrame{});
  CHECK_THAT(job.expectError().text, Catch::Contains("rank 1 on " + thisHost() + ": injected failure in render"));
  // Ranks 2 and 3 composite: rank 2 fails, still takes its run and rank
  // 3's image, and sends the failure as the band.
  job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 2, 0}}});
  job.expect<proto::SessionReady>();
  job.send(proto::RenderFrame{});
  CHECK_THAT(job.expectError().text, Catch::Contains("rank 2 on " + thisHost() + ": injected failure in composite"));
  const auto id = job.send(proto::RenderRotation{{0, 1, 0}, 0, 2, 12});
  checkSequence(job, id, 3, 12, ref);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "scene patches are checked whole before and after the dataset, and status reports the session") {
  Job job(2, {});
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();

  // Before any dataset: the lists a client offers and the settings.
  auto status = statusOf(job);
  std::string strategies;
  for (const auto& entry : composite::strategies()) {
    if (!strategies.empty()) strategies += ' ';
    strategies += entry.name;
  }
  CHECK(status["strategies"] == strategies);
  CHECK(status["decompositions"] == "kd balanced slabs");
  CHECK(status["strategy"] == "binary-swap");
  CHECK(status["decomposition"] == "kd");
  CHECK(status["hosts"] == thisHost() + " " + thisHost());
  for (const char* key : {"camera_eye", "image_size", "bounds", "value_range", "transfer_function"})
    CHECK(status.count(key) == 0);

  // A misspelt key, an unknown strategy, an image too big for a frame: each
  // refused with what was wrong, none kept for the dataset load that follows.
  job.send(proto::SetScene{"", R"({"shading": {"enabeld": true}})"});
  auto e = job.expectError();
  CHECK(e.code == proto::ErrorCode::kBadArgument);
  CHECK_THAT(e.text, Catch::Contains("shading.enabeld"));
  job.send(proto::SetScene{"", R"({"runtime": {"strategy": "swap-binary"}})"});
  CHECK_THAT(job.expectError().text, Catch::Contains("runtime.strategy") && Catch::Contains("direct-send"));
  const char* huge = R"({"image": {"width": 16384, "height": 16384}})";
  job.send(proto::SetScene{"", huge});
  e = job.expectError();
  CHECK(e.code == proto::ErrorCode::kLimitExceeded);
  CHECK_THAT(e.text, Catch::Contains(std::to_string(proto::Limits{}.maxImagePixels)));
  job.send(proto::SetScene{"", R"({"runtime": {"decomposition": "balanced"}})"});
  job.expect<proto::Ok>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  const Reference ref(nlohmann::json::object());
  auto id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, ref);

  // With the dataset open: refused alike, and the next frame is as before.
  job.send(proto::SetScene{"", huge});
  CHECK(job.expectError().code == proto::ErrorCode::kLimitExceeded);
  id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, ref);

  // The camera in use (the resolved automatic one), image, domain, data
  // range and transfer function, at full precision.
  status = statusOf(job);
  const core::Scene& scene = ref.scene();
  CHECK(status["decomposition"] == "balanced");
  CHECK(status["camera_projection"] == "perspective");
  CHECK(numbers(status["camera_eye"]) == std::vector{scene.camera.eye.x, scene.camera.eye.y, scene.camera.eye.z});
  CHECK(numbers(status["camera_look_at"]) == std::vector{scene.camera.lookAt.x, scene.camera.lookAt.y, scene.camera.lookAt.z});
  CHECK(numbers(status["camera_up"]) == std::vector{scene.camera.up.x, scene.camera.up.y, scene.camera.up.z});
  CHECK(numbers(status["camera_fov_y_deg"]) == std::vector{scene.camera.fovYDeg});
  CHECK(status["image_size"] == "64 64");
  CHECK(numbers(status["bounds"]) == std::vector<double>{0, 0, 0, kDims[0] - 1, kDims[1] - 1, (kDims[2] - 1) * 1.25});
  CHECK(numbers(status["value_range"]) == std::vector{ref.valueRange().min, ref.valueRange().max});
  std::vector<double> points;
  for (const auto& p : scene.volumes.front().transfer.points) points.insert(points.end(), {p.scalar, p.r, p.g, p.b, p.opacity});
  CHECK(points.size() == 20);
  CHECK(numbers(status["transfer_function"]) == points);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "requests flooding in during a sequence are kept up to a bound and the rest refused, each answered") {
  Job job(2, {});
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  const auto rotation = job.send(proto::RenderRotation{{0, 1, 0}, 0, 199, 200});
  constexpr int kFlood = 100;
  for (int i = 0; i < kFlood; ++i) job.send(proto::RenderFrame{});
  int frames = 0, refused = 0, rendered = 0;
  while (frames < 200 || rendered + refused < kFlood) {
    auto d = job.receive();
    REQUIRE(d);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) {
      CHECK(e->code == proto::ErrorCode::kLimitExceeded);
      CHECK_THAT(e->text, Catch::Contains("requests wait for the sequence in progress"));
      ++refused;
    } else if (std::holds_alternative<proto::ImageFrame>(d->message)) {
      if (d->info.requestId == rotation) ++frames;
      else ++rendered;
    }
  }
  // Kept ones render after the rotation; none is lost without an answer.
  // 64 wait at most, the rotation among them when the flood arrives before
  // the main thread took it (the Ok of SetScene leaves the main thread
  // itself, so the client may answer it that soon).
  CHECK(rendered >= 63);
  CHECK(refused > 0);
  CHECK(rendered + refused == kFlood);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "without PVR_JOB_SECRET the master does not connect back, and the job ends") {
  // No secret, no key for the secure channel: nothing to connect with.
  Job job(2, {}, {.secret = std::nullopt});
  CHECK(job.reap(30));
  CHECK_FALSE(job.connected(0));
}

TEST_CASE_METHOD(Fixture, "a rank whose host lacks the data names its host and the file, and the session serves on") {
  if (!canUnshareMounts()) {
    WARN("skipped: this process may not make mount namespaces (unshare -m), so no rank can be given its own view of the data");
    return;
  }
  Job job(2, {}, {.hiddenFromLastRank = true});
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  // Rank 1 sees hidden/ empty: split.json's voxels are not there for it.
  job.send(proto::SetScene{"split.json", kScene});
  // A data file missing is refused as one outside the data directory is,
  // in the same words (io/data_directory.h), naming the rank's host.
  const auto e = job.expectError();
  CHECK(e.code == proto::ErrorCode::kBadArgument);
  const std::string raw = (fs::canonical(kTmp / "data") / "hidden" / "split.raw").string();
  CHECK_THAT(e.text, Catch::StartsWith("rank 1 on " + thisHost() + ": ") && Catch::Contains(raw) &&
                         Catch::Contains("is not a regular file inside the data directory"));
  // The next request works: a dataset every rank sees, rendered.
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  const Reference ref(nlohmann::json::object());
  const auto id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, ref);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a rank killed mid-sequence: the handler side sees the end and nothing is left running") {
  Job job(3, {});
  job.send(proto::SessionOpen{3, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  job.send(proto::RenderRotation{{0, 1, 0}, 0, 5000, 5000});
  job.expect<proto::ImageFrame>();
  // The ranks are mpirun's children; kill one that is not the master.
  std::vector<pid_t> ranks;
  for (const pid_t pid : pvr::testing::allPids())
    if (const auto stat = pvr::testing::procStat(pid); stat && stat->parent == job.pid()) ranks.push_back(pid);
  REQUIRE(ranks.size() == 3);
  std::sort(ranks.begin(), ranks.end());
  REQUIRE(::kill(ranks.back(), SIGKILL) == 0);
  // Frames stop: the connection ends (or an Error arrives) within 30 s.
  bool ended = false;
  for (int i = 0; i < 6000 && !ended; ++i) {
    auto d = job.receive(30);
    ended = !d || std::holds_alternative<proto::ErrorMessage>(d->message);
  }
  CHECK(ended);
  CHECK(job.reap(30));
  // Gone, or a zombie waiting for init: nothing runs (mpirun reaps the
  // ranks it killed; their process groups are their own).
  const auto running = pvr::testing::processRuns;
  for (int i = 0; i < 100 && std::any_of(ranks.begin(), ranks.end(), running); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  for (pid_t r : ranks) CHECK_FALSE(running(r));
}

// ---- Liveness (issue 15, finding 8): the master answers while a frame
// renders, Cancel stops the frame in progress, a stopped rank is named and
// the job ends. Orderings are asserted, not times (bench/liveness measures
// the latencies).

namespace {

// A frame that takes seconds on two ranks: a small step with early ray
// termination off, so that every ray crosses the whole volume.
const nlohmann::json kSlowPatch = nlohmann::json::parse(R"({
  "image": {"width": 192, "height": 192},
  "sampling": {"step": 0.004, "early_termination": 1}})");

// Opens a session of `ranks` ranks on the phantom with kSlowPatch.
void openSlowSession(Job& job, std::uint32_t ranks) {
  job.send(proto::SessionOpen{ranks, {}, ""});
  job.expect<proto::SessionReady>();
  nlohmann::json scene = nlohmann::json::parse(kScene);
  scene.merge_patch(kSlowPatch);
  job.send(proto::SetScene{"phantom.json", scene.dump()});
  job.expect<proto::Ok>();
}

using pvr::testing::processRuns;

// The job's ranks by world rank: mpirun's children, each told its rank in
// its environment (OMPI_COMM_WORLD_RANK).
std::map<int, pid_t> rankPids(const Job& job) {
  std::map<int, pid_t> ranks;
  for (const pid_t pid : pvr::testing::allPids()) {
    const auto stat = pvr::testing::procStat(pid);
    if (!stat || stat->parent != job.pid()) continue;
    const std::string key = "OMPI_COMM_WORLD_RANK=";
    for (const std::string& e : pvr::testing::procEntries(pid, "environ"))
      if (e.rfind(key, 0) == 0) ranks[std::atoi(e.c_str() + key.size())] = pid;
  }
  return ranks;
}

}  // namespace

TEST_CASE_METHOD(Fixture, "a StatusRequest sent during a long frame is answered before the frame, the histogram counted by the next") {
  Job job(2);
  openSlowSession(job, 2);
  const auto render = job.send(proto::RenderFrame{});
  const auto status = job.send(proto::StatusRequest{});
  // The link thread answers from the session's snapshot; the frame follows.
  auto first = job.receive();
  REQUIRE(first);
  CHECK(first->info.requestId == status);
  REQUIRE(std::holds_alternative<proto::StatusReply>(first->message));
  // The load counted no histogram (the first frame does not need it).
  auto snapshot = entriesOf(std::get<proto::StatusReply>(first->message));
  CHECK(snapshot["histogram"].empty());
  CHECK_FALSE(snapshot["value_range"].empty());
  auto frame = job.receive(120);
  REQUIRE(frame);
  CHECK(frame->info.requestId == render);
  CHECK(std::holds_alternative<proto::ImageFrame>(frame->message));
  // The master answers the next status and counts first: each voxel once.
  const auto bins = numbers(statusOf(job)["histogram"]);
  CHECK(bins.size() == std::size_t(core::kHistogramBins));
  double counted = 0;
  for (double n : bins) counted += n;
  CHECK(counted == double(kDims[0]) * kDims[1] * kDims[2]);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "Cancel stops the frame in progress with Error CANCELLED, and the next frame renders") {
  Job job(2);
  openSlowSession(job, 2);
  const auto render = job.send(proto::RenderFrame{});
  // Until Status says the frame renders (answered at once meanwhile).
  bool rendering = false;
  for (int i = 0; i < 10000 && !rendering; ++i) {
    job.send(proto::StatusRequest{});
    const auto d = job.receive();
    REQUIRE(d);
    REQUIRE(std::holds_alternative<proto::StatusReply>(d->message));  // not the frame: it is slow
    for (const auto& kv : std::get<proto::StatusReply>(d->message).entries)
      rendering |= kv.key == "state" && kv.value == "rendering";
  }
  REQUIRE(rendering);
  const auto cancel = job.send(proto::Cancel{render});
  // The frame ends with CANCELLED instead of its pixels.
  std::optional<proto::ErrorMessage> ended;
  bool ok = false;
  while (!ended || !ok) {
    auto d = job.receive(120);
    REQUIRE(d);
    if (d->info.requestId == cancel) {
      CHECK(std::holds_alternative<proto::Ok>(d->message));
      ok = true;
    } else {
      REQUIRE(d->info.requestId == render);
      REQUIRE(std::holds_alternative<proto::ErrorMessage>(d->message));
      ended = std::get<proto::ErrorMessage>(d->message);
    }
  }
  CHECK(ended->code == proto::ErrorCode::kCancelled);
  CHECK(ended->text == "cancelled after 0 frames");
  // The session serves on: the next frame renders, and right.
  const auto id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, Reference(kSlowPatch));
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a rank stopped mid-frame is reported by number and host, and the job ends with nothing left running") {
  Job job(2, {"--stall-timeout", "2"});
  openSlowSession(job, 2);
  const auto ranks = rankPids(job);
  REQUIRE(ranks.size() == 2);
  REQUIRE(ranks.count(1) == 1);
  // Whatever happens, nothing stays stopped or running after the test.
  struct Cleanup {
    const std::map<int, pid_t>& ranks;
    ~Cleanup() {
      for (const auto& [rank, pid] : ranks)
        if (processRuns(pid)) {
          ::kill(pid, SIGCONT);
          ::kill(pid, SIGKILL);
        }
    }
  } cleanup{ranks};
  const auto rotation = job.send(proto::RenderRotation{{0, 1, 0}, 0, 99, 100});
  REQUIRE(::kill(ranks.at(1), SIGSTOP) == 0);
  std::optional<proto::Decoded> d;
  do d = job.receive(120);
  while (d && std::holds_alternative<proto::ImageFrame>(d->message));
  REQUIRE(d);
  REQUIRE(std::holds_alternative<proto::ErrorMessage>(d->message));
  const auto& e = std::get<proto::ErrorMessage>(d->message);
  CHECK(d->info.requestId == rotation);
  CHECK(e.code == proto::ErrorCode::kRankFailed);
  CHECK_THAT(e.text, Catch::StartsWith("rank 1 on " + thisHost() + " made no progress for ") &&
                         Catch::EndsWith("s (stopped or hung); the job ends"));
  // Then the link closes and the whole job ends, the stopped rank too.
  CHECK_FALSE(job.receive(60));
  CHECK(job.reap(60));
  for (int i = 0; i < 200 && processRuns(ranks.at(1)); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  for (const auto& [rank, pid] : ranks) CHECK_FALSE(processRuns(pid));
}

TEST_CASE_METHOD(Fixture, "the master sends Heartbeat frames to the handler, request id 0, for the whole session") {
  Job job(2);
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  // An idle session: the beats go on with nothing asked.
  int heartbeats = job.heartbeats();
  for (const int until = heartbeats + 3; heartbeats < until;) {
    auto d = job.receiveAny(30);
    REQUIRE(d);
    REQUIRE(std::holds_alternative<proto::Heartbeat>(d->message));
    CHECK(d->info.requestId == 0);
    CHECK(d->info.final());
    ++heartbeats;
  }
  CHECK(job.close());
}

// Several volumes through SetScene (docs/protocol.md): the data file of
// the phantom and a procedural Marschner-Lobb box of another spacing that
// overlaps one corner of it. Each frame equals the whole scene mixed in
// one process within 1e-5 (the rendering contract's tolerance for bricks,
// tests/renderer/raycast_mixed_bricks_test.cpp), on 1, 3 and 4 ranks; a
// volume hidden, then removed, by name, then the last one hidden and
// shown again; status lists the volumes.
TEST_CASE_METHOD(Fixture, "several volumes render as one process mixes them, and patches by name hide and remove them", "[volumes]") {
  nlohmann::json doc = nlohmann::json::parse(R"({
    "volumes": [
      {"name": "phantom", "dataset": "phantom.json",
       "transfer_function": {"points": [[0, 0, 0, 0, 0], [0.15, 0.3, 0.5, 1, 0.05], [0.3, 1, 0.8, 0.3, 0.3], [1, 1, 1, 1, 0.6]]}},
      {"name": "field", "procedural": "marschner-lobb", "dims": [20, 20, 20], "spacing": [1.5, 1.5, 1.5],
       "transfer_function": {"points": [[0, 0.1, 0.3, 0.9, 0], [0.55, 0.1, 0.3, 0.9, 0], [0.7, 0.3, 0.6, 1, 0.05], [1, 0.8, 0.9, 1, 0.2]]}}],
    "image": {"width": 64, "height": 64, "background": [0, 0, 0, 1]},
    "shading": {"enabled": true}})");
  for (int ranks : {1, 3, 4}) {
    INFO(ranks << " ranks");
    Job job(ranks, {});
    job.send(proto::SessionOpen{std::uint32_t(ranks), {}, ""});
    job.expect<proto::SessionReady>();
    job.send(proto::SetScene{"", doc.dump()});
    job.expect<proto::Ok>();
    auto id = job.send(proto::RenderFrame{});
    const SceneReference both(doc);
    checkFrames(job, id, 1, [&](int) { return both.frame(); });

    if (ranks == 4) {
      // Render ranks beside a compositing cluster: the ranks that hold no
      // data take part in every volume's agreements.
      job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 2, 0}}});
      job.expect<proto::SessionReady>();
      id = job.send(proto::RenderFrame{});
      checkFrames(job, id, 1, [&](int) { return both.frame(); });
    }

    auto status = statusOf(job);
    CHECK_THAT(status["volumes"], Catch::StartsWith("{name phantom source ") && Catch::Contains("visible 1") &&
                                      Catch::Contains("{name field source ") && Catch::Contains("dims {20 20 20}"));
    // The first volume's histogram counts each of its voxels once, however
    // the ranks' bricks overlap.
    double counted = 0;
    for (double n : numbers(status["histogram"])) counted += n;
    CHECK(counted == double(kDims[0]) * kDims[1] * kDims[2]);

    // Hidden: the phantom alone, through the mixed path's one-volume case.
    job.send(proto::SetScene{"", R"({"volumes": {"field": {"visible": false}}})"});
    job.expect<proto::Ok>();
    id = job.send(proto::RenderFrame{});
    nlohmann::json hidden = doc;
    hidden["volumes"][1]["visible"] = false;
    const SceneReference phantom(hidden);
    checkFrames(job, id, 1, [&](int) { return phantom.frame(); });
    // Each volume shows in the frames: hiding one changes the image.
    CHECK(core::maxAbsDifference(both.frame(), phantom.frame()) > 0.05);
    CHECK(core::maxAbsDifference(phantom.frame(), core::Image::fullFrame(64, 64)) > 0.2);
    CHECK_THAT(statusOf(job)["volumes"], Catch::Contains("visible 0"));

    // Removed: a scene of one volume again, on the one-volume path.
    job.send(proto::SetScene{"", R"({"volumes": {"field": null}})"});
    job.expect<proto::Ok>();
    id = job.send(proto::RenderFrame{});
    nlohmann::json alone = doc;
    alone["volumes"].erase(1);
    const SceneReference one(alone);
    checkFrames(job, id, 1, [&](int) { return one.frame(); });

    // The last volume hidden shows nothing; shown again, it is back.
    job.send(proto::SetScene{"", R"({"volumes": {"phantom": {"visible": false}}})"});
    job.expect<proto::Ok>();
    id = job.send(proto::RenderFrame{});
    checkFrames(job, id, 1, [&](int) { return core::Image::fullFrame(64, 64); });
    job.send(proto::SetScene{"", R"({"volumes": {"phantom": {"visible": true}}})"});
    job.expect<proto::Ok>();
    id = job.send(proto::RenderFrame{});
    checkFrames(job, id, 1, [&](int) { return one.frame(); });
    CHECK(job.close());
  }
}

// A time series among several volumes (docs/scene.md, "Several volumes"):
// the series shows the scene's timestep and each frame of a time request
// its own step, the single volume beside it every time; a timestep past
// the longest series is refused with checkTimestep's words.
TEST_CASE_METHOD(Fixture, "a series among several volumes shows each step beside the other volume", "[volumes][series]") {
  const auto docAt = [](const std::string& run) {
    return nlohmann::json{
        {"volumes",
         {{{"name", "run"}, {"dataset", run},
           {"transfer_function", {{"points", {{0, 0, 0, 0, 0}, {0.15, 0.3, 0.5, 1, 0.05}, {0.3, 1, 0.8, 0.3, 0.3}, {1, 1, 1, 1, 0.6}}}}}},
          {{"name", "field"}, {"procedural", "marschner-lobb"}, {"dims", {20, 20, 20}}, {"spacing", {1.5, 1.5, 1.5}},
           {"transfer_function", {{"points", {{0, 0.1, 0.3, 0.9, 0}, {0.55, 0.1, 0.3, 0.9, 0}, {0.7, 0.3, 0.6, 1, 0.05}, {1, 0.8, 0.9, 1, 0.2}}}}}}}},
        {"image", {{"width", 48}, {"height", 48}}},
        {"shading", {{"enabled", true}}}};
  };
  Job job(3, {});
  job.send(proto::SessionOpen{3, {}, ""});
  job.expect<proto::SessionReady>();
  nlohmann::json doc = docAt(kSeries);
  doc["timestep"] = 2;
  job.send(proto::SetScene{"", doc.dump()});
  job.expect<proto::Ok>();
  auto id = job.send(proto::RenderFrame{});
  const SceneReference step2(docAt(stepFile(2)));
  checkFrames(job, id, 1, [&](int) { return step2.frame(); });

  id = job.send(proto::RenderTimeSteps{0, 3, 1});
  checkFrames(job, id, 4, [&](int k) { return SceneReference(docAt(stepFile(k))).frame(); });

  job.send(proto::SetScene{"", R"({"timestep": 4})"});
  CHECK_THAT(job.expectError().text, Catch::Contains("timestep 4: series.series.json has 4 time steps (0..3)"));
  CHECK(job.close());
}

// A setting that changes the ghost layers (shading off: none needed)
// re-reads the bricks; every rank takes part, those of a compositing
// cluster too, which hold no brick (they once waited for the others for ever).
TEST_CASE_METHOD(Fixture, "new ghost layers are read with a compositing cluster beside the render ranks") {
  Job job(4, {});
  job.send(proto::SessionOpen{4, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetLayout{{{ClusterRole::kRender, 2, 0}, {ClusterRole::kComposite, 2, 0}}});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  auto id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, Reference(nlohmann::json::object()));
  job.send(proto::SetScene{"", R"({"shading": {"enabled": false}})"});
  job.expect<proto::Ok>();
  id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, Reference(nlohmann::json::parse(R"({"shading": {"enabled": false}})")));
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a quality target set on an open session reads the ghost layers its step levels need") {
  Job job(2);
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  auto id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, Reference(nlohmann::json::object()));
  const char* quality = R"({"sampling": {"target_psnr": 45}})";
  job.send(proto::SetScene{"", quality});
  job.expect<proto::Ok>();
  id = job.send(proto::RenderFrame{});
  checkSequence(job, id, 1, 1, Reference(nlohmann::json::parse(quality)));
  CHECK(job.close());
}

// ---- Steering: a computation volume (docs/steering.md) ----

namespace {

// The Gray-Scott computation of the steering tests, and the field it draws (v).
const char* kComputationScene = R"({
  "volume": {"computation": "gray-scott", "dims": [22, 20, 18], "file": null},
  "transfer_function": {"points": [[0, 0, 0, 0, 0], [0.05, 0.2, 0.5, 1, 0.1], [0.3, 1, 0.9, 0.4, 0.9]]},
  "image": {"width": 64, "height": 64, "background": [0, 0, 0, 1]},
  "shading": {"enabled": false}})";

// The computation run serially in this process, one rank holding the
// whole grid; `at` dumps its drawn field as a raw volume with a JSON
// sidecar in the data directory, for Reference to render as pvr-render would.
class SerialComputation {
 public:
  SerialComputation() : world_(1), comm_(world_, 0), run_(node::computationNamed("gray-scott"), grid()) {
    run_.place(comm_, {0}, {run_.grid().allNodes()}, 1);
  }
  // Runs to `step` with `parameters`; returns the dumped file's name.
  std::string at(int step, const std::map<std::string, double>& parameters = {}) {
    const node::Parameters p(run_.entry(), parameters);
    while (run_.steps() < step) run_.step(comm_, p);
    const std::string stem = "gray-scott-" + std::to_string(::getpid()) + "-" + std::to_string(step);
    core::writeRawJsonVolume(run_.brick(comm_, p, run_.grid().allNodes()), (kTmp / "data").string(), stem,
                             "gray-scott step " + std::to_string(step));
    return stem + ".json";
  }

 private:
  static core::GridGeometry grid() { return core::generatedGrid({22, 20, 18}, std::nullopt, "gray-scott"); }
  comm::InProcessWorld world_;
  comm::InProcessCommunicator comm_;
  node::ComputationRun run_;
};

// The frames of a computation's request: frame k equals Reference of the
// serial run's field dumped at steps[k].
void checkComputedFrames(Job& job, std::uint32_t request, SerialComputation& serial, const std::vector<int>& steps,
                         const std::map<std::string, double>& parameters = {}) {
  const nlohmann::json patch = nlohmann::json::parse(kComputationScene);
  checkFrames(job, request, int(steps.size()), [&](int k) {
    nlohmann::json rest = patch;
    rest.erase("volume");
    return Reference(rest, serial.at(steps[std::size_t(k)], parameters)).frame(0, 1);
  });
}

}  // namespace

TEST_CASE_METHOD(Fixture, "render steps: frames of the computed field equal renderings of the field dumped to a file, steered from the next step") {
  Job job(3);
  job.send(proto::SessionOpen{3, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"", kComputationScene});
  job.expect<proto::Ok>();
  auto status = statusOf(job);
  CHECK(status["computation"] == "gray-scott");
  CHECK(status["step"] == "0");
  CHECK_THAT(status["parameters"], Catch::StartsWith("feed 0.035 kill 0.065"));
  CHECK_THAT(status["parameter_ranges"], Catch::Contains("{feed 0.035 0 0.1 {"));

  // Parameters the computation does not declare, or out of range, are
  // refused naming the parameter and its range; nothing changes.
  job.send(proto::SetScene{"", R"({"parameters": {"feed": 0.5}})"});
  auto refused = job.expectError();
  CHECK(refused.code == proto::ErrorCode::kBadArgument);
  CHECK(refused.text == "parameters.feed: 0.5 is outside the range [0, 0.1] of gray-scott's parameter 'feed'");
  job.send(proto::SetScene{"", R"({"parameters": {"fed": 0.05}})"});
  refused = job.expectError();
  CHECK_THAT(refused.text, Catch::StartsWith("parameters.fed: gray-scott has no parameter 'fed' (its parameters: "
                                             "feed [0, 0.1], kill [0, 0.1]"));
  CHECK(statusOf(job)["parameters"] == status["parameters"]);

  // 7 steps, a frame every 3: steps 3, 6 and the last, 7.
  SerialComputation serial;
  auto id = job.send(proto::RenderSteps{7, 3});
  checkComputedFrames(job, id, serial, {3, 6, 7});
  CHECK(statusOf(job)["step"] == "7");
  // A frame shows the step the session is at; it does not advance.
  id = job.send(proto::RenderFrame{});
  checkComputedFrames(job, id, serial, {7});

  // Steered: feed changes from step 8 on.
  job.send(proto::SetScene{"", R"({"parameters": {"feed": 0.06}})"});
  job.expect<proto::Ok>();
  CHECK_THAT(statusOf(job)["parameters"], Catch::StartsWith("feed 0.06 "));
  id = job.send(proto::RenderSteps{2, 1});
  checkComputedFrames(job, id, serial, {8, 9}, {{"feed", 0.06}});

  // A computation cannot go back; a dataset's time request says so.
  job.send(proto::RenderTimeSteps{0, 2, 1});
  CHECK_THAT(job.expectError().text, Catch::Contains("is at step 9 and cannot go back"));
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "render steps on a dataset, and parameters for it, are refused, and Cancel stops a computation between frames") {
  Job job(2);
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  job.send(proto::RenderSteps{3, 1});
  CHECK_THAT(job.expectError().text, Catch::Contains("is not a computation volume"));
  job.send(proto::SetScene{"", R"({"parameters": {"feed": 0.05}})"});
  CHECK_THAT(job.expectError().text, Catch::StartsWith("parameters: only a computation volume takes parameters"));

  job.send(proto::SetScene{"", kComputationScene});
  job.expect<proto::Ok>();
  const auto render = job.send(proto::RenderSteps{100000, 1});
  auto first = job.receive();
  REQUIRE(first);
  REQUIRE(std::holds_alternative<proto::ImageFrame>(first->message));
  const auto cancel = job.send(proto::Cancel{render});
  std::optional<proto::ErrorMessage> ended;
  bool ok = false;
  int frames = 1;
  while (!ended || !ok) {
    auto d = job.receive(120);
    REQUIRE(d);
    if (d->info.requestId == cancel) {
      ok = true;
    } else if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) {
      ended = *e;
    } else {
      REQUIRE(std::holds_alternative<proto::ImageFrame>(d->message));
      ++frames;
    }
  }
  CHECK(ended->code == proto::ErrorCode::kCancelled);
  // The session is at the step of the last frame it sent, or the one after
  // it (a frame cancelled once its steps were computed), and goes on from there.
  const int step = std::stoi(statusOf(job)["step"]);
  CHECK(step >= frames);
  CHECK(step <= frames + 1);
  SerialComputation serial;
  const auto id = job.send(proto::RenderSteps{1, 1});
  checkComputedFrames(job, id, serial, {step + 1});
  CHECK(job.close());
}

// ---- Progressive refinement (issue 13, point 4): an interactive request
// is answered by a coarse frame, then the full-quality one, unless a newer
// request came meanwhile.

TEST_CASE_METHOD(Fixture, "an interactive request sends a coarse frame, then the full frame a normal render sends") {
  Job job(2);
  job.send(proto::SessionOpen{2, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  const Reference ref(nlohmann::json::object());
  // The coarse frame: the view rendered at 1/4 of the pixels per axis
  // (16 x 16) and sent at that size, as a direct render at 16 x 16 is;
  // the client zooms it.
  const Reference coarse(nlohmann::json::parse(R"({"image": {"width": 16, "height": 16}})"));
  std::vector<std::uint8_t> coarseBytes;  // turn 5's coarse frame on the wire
  for (const std::int32_t turn : {0, 5}) {
    INFO("turn " << turn);
    const auto id = job.send(proto::RenderInteractive{4, {0, 1, 0}, turn, 60});
    auto first = job.receive();
    REQUIRE(first);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&first->message)) FAIL(e->text);
    const auto quick = std::get<proto::ImageFrame>(first->message);
    CHECK(first->info.requestId == id);
    CHECK_FALSE(first->info.final());
    CHECK(quick.frameNumber == 0);
    CHECK(quick.width == 16);
    CHECK(quick.height == 16);
    CHECK(core::maxAbsDifference(dumped(job, id, 0), coarse.frame(turn, 60)) <= 1e-5);
    auto second = job.receive();
    REQUIRE(second);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&second->message)) FAIL(e->text);
    const auto full = std::get<proto::ImageFrame>(second->message);
    CHECK(second->info.requestId == id);
    CHECK(second->info.final());
    CHECK(full.frameNumber == 1);
    CHECK(core::maxAbsDifference(dumped(job, id, 1), ref.frame(turn, 60)) <= 1e-5);
    CHECK(quick.pixels != full.pixels);
    // The coarse frame waits for no gathering of timings: the first
    // request's reading of the bricks is charged to its full frame.
    CHECK(quick.timing.read == 0);
    if (turn == 0) CHECK(full.timing.read > 0);
    // The same view rendered normally: the very bytes of the full frame.
    if (turn == 0) job.send(proto::RenderFrame{});
    else job.send(proto::RenderRotation{{0, 1, 0}, turn, turn, 60});
    const auto normal = job.expect<proto::ImageFrame>();
    CHECK(normal.pixels == full.pixels);
    coarseBytes = quick.pixels;
  }
  // The coarse frame is, byte for byte, what a 16 x 16 session sends for
  // that view.
  job.send(proto::SetScene{"", R"({"image": {"width": 16, "height": 16}})"});
  job.expect<proto::Ok>();
  job.send(proto::RenderRotation{{0, 1, 0}, 5, 5, 60});
  const auto small = job.expect<proto::ImageFrame>();
  CHECK(small.width == 16);
  CHECK(small.pixels == coarseBytes);
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a coarse frame composites at its cluster's root on 3 ranks, and a rank's failure reaches the client") {
  Job job(3, {"--fail-once", "render@2"});
  job.send(proto::SessionOpen{3, {}, ""});
  job.expect<proto::SessionReady>();
  job.send(proto::SetScene{"phantom.json", kScene});
  job.expect<proto::Ok>();
  // Rank 2's coarse render fails: its failure goes with its sub-image to
  // rank 0, which sends no coarse frame, only the failure.
  job.send(proto::RenderInteractive{4, {0, 1, 0}, 0, 1});
  CHECK_THAT(job.expectError().text, Catch::Contains("rank 2 on " + thisHost() + ": injected failure in render"));
  // Then the three sub-images, blended front to back at rank 0, equal the
  // view rendered whole at 16 x 16; the full frame follows.
  const Reference ref(nlohmann::json::object());
  const Reference coarse(nlohmann::json::parse(R"({"image": {"width": 16, "height": 16}})"));
  for (const std::int32_t turn : {7, 20}) {
    INFO("turn " << turn);
    const auto id = job.send(proto::RenderInteractive{4, {0, 1, 0}, turn, 60});
    const auto quick = job.expect<proto::ImageFrame>();
    CHECK(quick.width == 16);
    CHECK(core::maxAbsDifference(dumped(job, id, 0), coarse.frame(turn, 60)) <= 1e-5);
    job.expect<proto::ImageFrame>();
    CHECK(core::maxAbsDifference(dumped(job, id, 1), ref.frame(turn, 60)) <= 1e-5);
  }
  CHECK(job.close());
}

TEST_CASE_METHOD(Fixture, "a newer request cancels an interactive render's full frame, rendering or waiting") {
  Job job(2);
  openSlowSession(job, 2);
  // While the slow full frame renders, a scene change arrives: the render
  // stops after its coarse frame.
  const auto slow = job.send(proto::RenderInteractive{4, {0, 1, 0}, 0, 1});
  const auto quick = job.expect<proto::ImageFrame>();
  CHECK(quick.frameNumber == 0);
  const auto change = job.send(proto::SetScene{"", R"({"sampling": null, "image": {"width": 64, "height": 64}})"});
  auto ended = job.receive(120);
  REQUIRE(ended);
  CHECK(ended->info.requestId == slow);
  REQUIRE(std::holds_alternative<proto::ErrorMessage>(ended->message));
  CHECK(std::get<proto::ErrorMessage>(ended->message).code == proto::ErrorCode::kCancelled);
  CHECK(std::get<proto::ErrorMessage>(ended->message).text == "cancelled after 1 frames");
  auto ok = job.receive();
  REQUIRE(ok);
  CHECK(ok->info.requestId == change);
  CHECK(std::holds_alternative<proto::Ok>(ok->message));
  // Two views one after the other: the first is queued behind when its
  // coarse frame is done, so its full frame is never rendered; the second
  // refines.
  const auto ids = job.sendTogether({proto::RenderInteractive{4, {0, 1, 0}, 3, 60}, proto::RenderInteractive{4, {0, 1, 0}, 4, 60}});
  const std::uint32_t older = ids[0], newer = ids[1];
  std::vector<std::pair<std::uint32_t, std::string>> answers;
  for (int i = 0; i < 4; ++i) {
    auto d = job.receive(120);
    REQUIRE(d);
    if (const auto* f = std::get_if<proto::ImageFrame>(&d->message))
      answers.emplace_back(d->info.requestId, "frame " + std::to_string(f->frameNumber));
    else if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message))
      answers.emplace_back(d->info.requestId, e->text);
  }
  const std::vector<std::pair<std::uint32_t, std::string>> expected{
      {older, "frame 0"}, {older, "cancelled after 1 frames"}, {newer, "frame 0"}, {newer, "frame 1"}};
  CHECK(answers == expected);
  CHECK(core::maxAbsDifference(dumped(job, newer, 1), Reference(nlohmann::json::object()).frame(4, 60)) <= 1e-5);
  CHECK_FALSE(fs::exists(job.dumpDir() / ("frame-" + std::to_string(older) + "-1.f32")));
  CHECK(job.close());
}
