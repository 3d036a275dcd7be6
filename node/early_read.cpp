#include "early_read.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "decompose/kd_tree.h"
#include "distribute.h"
#include "scene_bricks.h"
#include "scene_volume.h"

namespace pvr::node {

namespace {

// The launcher's number in `name`, or -1 when it names none.
int launcherNumber(const char* name) {
  const char* text = std::getenv(name);
  if (!text || !*text) return -1;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  return *end == '\0' && value >= 0 && value < (1L << 24) ? int(value) : -1;
}

constexpr int kNicer = 10;

bool sameVolume(const core::VolumeSpec& a, const core::VolumeSpec& b) {
  return a.file == b.file && a.procedural == b.procedural && a.computation == b.computation && a.dims == b.dims &&
         a.spacing == b.spacing && a.timestep == b.timestep;
}

}  // namespace

struct EarlyRead::State {
  std::thread thread;
  std::mutex mutex;  // the frame's readBox against the destructor; the thread's results are read after join
  core::VolumeSpec spec;
  core::NodeBox owned, stored;
  std::optional<core::Brick> brick;
  bool handedOver = false;

  // The brick read early for `owned` and `stored` of `spec`, once; its
  // load times count what it spent before this call as `early`. The first
  // call decides: a frame reads its brick once (distribute.h).
  std::optional<core::Brick> take(const core::VolumeSpec& of, const core::NodeBox& o, const core::NodeBox& s) {
    const std::lock_guard<std::mutex> lock(mutex);
    const auto asked = std::chrono::steady_clock::now();
    if (thread.joinable()) thread.join();
    if (!brick || handedOver || !sameVolume(of, spec) || o != owned || s != stored) {
      brick.reset();  // the frame reads its own: not two bricks in memory
      return std::nullopt;
    }
    handedOver = true;
    std::optional<core::Brick> out = std::move(brick);
    brick.reset();
    core::LoadTimes& times = out->loadTimes();
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
    times.early = std::max(0.0, times.read + times.preprocess - waited);
    times.readEarly = true;
    return out;
  }

  void read(const std::function<core::Scene()>& load, const FrameOptions& options, int rank, int ranks) {
    try {
      const core::Scene scene = load();
      if (needsSceneBricks(scene) || options.decomposition == Decomposition::kBalanced) return;
      FrameOptions plain = options;
      plain.openVolume = nullptr;  // the file itself, not the opener that hands this brick over
      FrameVolume volume = openFrameVolume(scene, plain);
      if (!volume.source->canReadPartially()) return;  // rank 0 reads it whole and scatters
      const core::KdTree tree = core::KdTree::build(volume.source->grid(), ranks, splitAxisRule(options.decomposition));
      const core::NodeBox o = tree.ownedBox(rank);
      if (o.empty()) return;
      const core::NodeBox s = core::storedBox(tree, rank, volume.ghostLayers);
      core::Brick b = volume.source->readBox(o, s);
      spec = scene.volumes.front().source;
      owned = o;
      stored = s;
      brick = std::move(b);
    } catch (...) {
      // The frame reads again and reports what went wrong, agreed by every rank.
    }
  }
};

namespace {

// The scene's volume, handing over the early brick for its box.
class EarlySource final : public core::VolumeSource {
 public:
  EarlySource(std::unique_ptr<core::VolumeSource> inner, std::shared_ptr<EarlyRead::State> state,
              core::VolumeSpec spec)
      : inner_(std::move(inner)), state_(std::move(state)), spec_(std::move(spec)) {}

  const core::GridGeometry& grid() const override { return inner_->grid(); }
  core::ScalarType type() const override { return inner_->type(); }
  bool canReadPartially() const override { return inner_->canReadPartially(); }
  core::Brick readBox(const core::NodeBox& owned, const core::NodeBox& stored) const override {
    // The early read counts no histogram keys: only a frame that counts none takes it.
    if (!fineCounts_)
      if (std::optional<core::Brick> early = state_->take(spec_, owned, stored)) return std::move(*early);
    return inner_->readBox(owned, stored);
  }
  std::string describe() const override { return inner_->describe(); }
  std::string caveat() const override { return inner_->caveat(); }
  void setFineCounts(bool on) override {
    fineCounts_ = on;
    inner_->setFineCounts(on);
  }
  void prefetchBox(const core::NodeBox& stored) const override { inner_->prefetchBox(stored); }
  int steps() const override { return inner_->steps(); }
  double stepTime(int k) const override { return inner_->stepTime(k); }
  const core::VolumeSource& step(int k) const override {
    // A series' other steps are read as always; step 0 of a series is the series.
    const core::VolumeSource& s = inner_->step(k);
    return &s == inner_.get() ? *this : s;
  }

 private:
  std::unique_ptr<core::VolumeSource> inner_;
  std::shared_ptr<EarlyRead::State> state_;
  core::VolumeSpec spec_;
  bool fineCounts_ = true;
};

}  // namespace

EarlyRead::EarlyRead(std::function<core::Scene()> scene, const FrameOptions& options)
    : state_(std::make_shared<State>()) {
  // Asked for only (docs/runtime.md): at a load of 4-6 it measured no faster
  // than reading after MPI_Init, whose 0.2-0.3 s (ob1) leave few idle cores.
  const char* on = std::getenv("PVR_EARLY_READ");
  if (!on || std::string(on) != "1") return;
  const int rank = launcherNumber("OMPI_COMM_WORLD_RANK");
  const int ranks = launcherNumber("OMPI_COMM_WORLD_SIZE");
  if (rank < 0 || ranks < 1 || rank >= ranks) return;
  State* state = state_.get();
  state_->thread = std::thread([state, scene = std::move(scene), options, rank, ranks] {
    // Below the main thread (Linux: a thread's own nice value), so MPI_Init
    // takes the cores when it needs them and the read takes what it leaves;
    // after it every rank's main thread waits for its read, and the reads
    // share the cores alike.
    errno = 0;
    const int nice = ::getpriority(PRIO_PROCESS, id_t(::gettid()));
    if (errno == 0) (void)::setpriority(PRIO_PROCESS, id_t(::gettid()), std::min(19, nice + kNicer));
    state->read(scene, options, rank, ranks);
  });
}

EarlyRead::~EarlyRead() {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  if (state_->thread.joinable()) state_->thread.join();
}

VolumeOpener EarlyRead::opener() const {
  return [state = state_](const core::VolumeSpec& spec) -> std::unique_ptr<core::VolumeSource> {
    return std::make_unique<EarlySource>(core::openSceneVolume(spec), state, spec);
  };
}

bool EarlyRead::handedOver() const {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->handedOver;
}

}  // namespace pvr::node
