// The MPI test driver: run under mpirun with N ranks; loops over every
// strategy x decomposition x view inside one job (MPI start-up is the
// expensive part of a run) and compares each distributed frame with a
// single-process render of the same scene done here on rank 0.
//
//   pvr_composite_mpi_driver matrix DIR    the equality matrix, binary swap's message
//                                          count and the paper's pixel bound
//   pvr_composite_mpi_driver failure DIR   a rank whose brick read throws: every rank
//                                          fails with the same message, nothing hangs
//   pvr_composite_mpi_driver steering DIR  the Gray-Scott computation over the ranks
//                                          equals a serial run (steering_checks.cpp)
//   pvr_composite_mpi_driver compare A.exr B.exr TOL   (serial) max abs difference <= TOL
//
// DIR is a scratch directory for the volumes the driver writes. Exit 0 when
// every check passed; every failed check is printed by rank 0.
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "frame.h"
#include "image_io.h"
#include "mpi_communicator.h"
#include "raycast/raycaster.h"
#include "scene_volume.h"

// steering_checks.cpp: the example computation, distributed against serial.
int steering(pvr::comm::Communicator& comm);

namespace {

using namespace pvr;
using namespace pvr::core;
namespace fs = std::filesystem;

constexpr double kTolerance = 1e-5;
constexpr IVec3 kDims{29, 26, 23};
constexpr Vec3 kSpacing{0.07, 0.08, 0.09};

int failures = 0;

void check(comm::Communicator& comm, bool ok, const std::string& what) {
  if (ok) return;
  ++failures;
  if (comm.rank() == 0) std::printf("FAILED: %s\n", what.c_str());
}

// Marschner-Lobb samples as float32, little endian, x fastest.
std::vector<float> volumeValues() {
  const auto source = openProcedural("marschner-lobb", kDims, kSpacing);
  const Brick all = source->readAll();
  return std::vector<float>(all.as<float>(), all.as<float>() + kDims.product());
}

// A raw file with a JSON sidecar: every rank reads its own brick.
std::string writeRawVolume(const fs::path& dir) {
  const std::vector<float> values = volumeValues();
  std::ofstream(dir / "ml.raw", std::ios::binary)
      .write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(float)));
  std::ofstream(dir / "ml.json") << "{\"dims\": [" << kDims.x << ", " << kDims.y << ", " << kDims.z
                                 << "], \"dtype\": \"float32\", \"spacing\": [" << kSpacing.x << ", "
                                 << kSpacing.y << ", " << kSpacing.z << "], \"raw_file\": \"ml.raw\"}\n";
  return (dir / "ml.json").string();
}

// A gzip NRRD: not partially readable, so rank 0 reads and scatters.
std::string writeGzipVolume(const fs::path& dir) {
  const std::vector<float> values = volumeValues();
  gzFile gz = gzopen((dir / "ml.raw.gz").c_str(), "wb1");
  gzwrite(gz, values.data(), unsigned(values.size() * sizeof(float)));
  gzclose(gz);
  std::ofstream(dir / "ml.nhdr") << "NRRD0004\ntype: float\ndimension: 3\nsizes: " << kDims.x << ' '
                                 << kDims.y << ' ' << kDims.z << "\nspacings: " << kSpacing.x << ' '
                                 << kSpacing.y << ' ' << kSpacing.z
                                 << "\nencoding: gzip\nendian: little\ndata file: ml.raw.gz\n";
  return (dir / "ml.nhdr").string();
}

struct View {
  std::string name;
  CameraSpec camera;
};

std::vector<View> views(const GridGeometry& grid) {
  const Vec3 c = grid.center();
  const double size = length(grid.domainMax() - grid.domainMin());
  std::vector<View> out;
  CameraSpec axis;
  axis.projection = Projection::kOrthographic;
  axis.eye = c + Vec3{0, 0, 2 * size};
  axis.lookAt = c;
  axis.up = {0, 1, 0};
  axis.height = 1.1 * size;
  axis.automatic = false;
  out.push_back({"axis-aligned", axis});
  CameraSpec oblique = axis;
  oblique.eye = c + Vec3{-1.2, 0.9, 0.7} * size;
  oblique.up = {0, 0, 1};
  out.push_back({"oblique", oblique});
  CameraSpec perspective = oblique;
  perspective.projection = Projection::kPerspective;
  perspective.eye = c + Vec3{1.1, -1.5, 0.8} * size;
  perspective.fovYDeg = 35;
  out.push_back({"perspective", perspective});
  CameraSpec inside = perspective;
  inside.eye = c + Vec3{0.05, -0.1, 0.02} * size;
  inside.lookAt = c + Vec3{0.3, 0.4, 0.1} * size;
  inside.fovYDeg = 100;
  out.push_back({"eye inside", inside});
  return out;
}

Scene sceneFor(const std::string& volumeFile, const CameraSpec& camera, bool dense) {
  Scene s;
  s.volumes.front().source.file = volumeFile;
  // A dense volume shows every voxel; otherwise bands with empty space between.
  if (dense)
    s.volumes.front().transfer.points = {{0, 0.2, 0.4, 0.9, 0.06}, {1, 1.0, 0.9, 0.6, 0.5}};
  else
    s.volumes.front().transfer.points = {{0.0, 0, 0, 0, 0},        {0.45, 0.2, 0.5, 1, 0},  {0.55, 0.3, 0.6, 1, 0.4},
                         {0.65, 1, 0.7, 0.2, 0.0}, {0.8, 1, 0.7, 0.2, 0.0}, {0.9, 1, 0.3, 0.2, 0.8}};
  s.camera = camera;
  s.image.width = 56;
  s.image.height = 48;
  s.shading.enabled = true;  // central differences need ghost layers
  // Exact equality needs early termination off: each brick stops its own
  // part of a ray (terminationBound()).
  s.sampling.earlyTermination = 1;
  return s;
}

// How far ranks' frames may be from one process's under the default early
// termination: each brick stops its own part of a ray once that part's
// opacity reaches a_max, and one process stops the whole ray, so each
// leaves out at most 1 - a_max of the light behind (lit colours, ambient +
// diffuse + specular, stay below 2), once per brick along the ray.
double terminationBound(int bricksAlongRay) {
  return kTolerance + 2.0 * (bricksAlongRay + 1) * (1 - kDefaultEarlyTermination);
}

// The single-process render: what pvr-render does.
Image renderSerial(Scene scene) {
  const auto source = openSceneVolume(scene.volumes.front().source);
  resolveDefaults(scene, source->grid());
  const Brick volume = source->readAll();
  const RenderOptions options = renderOptionsFor(scene);
  ThreadPool pool(1);
  BrickRenderer renderer(volume);
  renderer.classify(scene.volumes.front().transfer, options);
  return renderer.render(Camera(scene.camera, scene.image.width, scene.image.height), options, pool);
}

struct StrategyCase {
  std::string name;
  int radix = 2;
};

int matrix(comm::Communicator& comm, const fs::path& dir) {
  std::string rawFile, gzipFile;
  comm::runAgreed(comm, [&] {
    if (comm.rank() == 0) {
      rawFile = writeRawVolume(dir);
      gzipFile = writeGzipVolume(dir);
    }
  });
  rawFile = (dir / "ml.json").string();
  gzipFile = (dir / "ml.nhdr").string();
  const GridGeometry grid = openVolumeFile(rawFile)->grid();
  const int n = comm.size();
  const std::vector<StrategyCase> cases = {
      {"binary-swap"}, {"direct-send"}, {"tree"}, {"radix-k", 4}, {"radix-k", 2}};
  int frames = 0;

  // Every strategy x decomposition x view equals the single-process image.
  for (const View& view : views(grid)) {
    const Scene scene = sceneFor(rawFile, view.camera, false);
    Image reference;
    if (comm.rank() == 0) reference = renderSerial(scene);
    for (const StrategyCase& c : cases)
      for (const auto& [decompositionLabel, decomposition] : node::decompositions()) {
        node::FrameOptions options;
        options.strategy = c.name;
        options.strategyParams.radix = c.radix;
        options.decomposition = decomposition;
        const node::FrameResult result = node::renderFrame(scene, options, comm);
        ++frames;
        const std::string label = c.name + (c.name == "radix-k" ? " k=" + std::to_string(c.radix) : "") + ", " +
                                  std::string(decompositionLabel) + ", " + view.name + ", " + std::to_string(n) +
                                  " ranks";
        if (comm.rank() == 0) {
          const double diff = maxAbsDifference(result.image, reference);
          check(comm, diff <= kTolerance, label + ": max abs difference " + std::to_string(diff));
          if (diff > kTolerance) {  // keep both images for a look
            writeExr(result.image, (dir / ("failed-" + std::to_string(frames) + ".exr")).string());
            writeExr(reference, (dir / ("failed-" + std::to_string(frames) + "-reference.exr")).string());
          }
        }
        check(comm, result.readPartially, label + ": ranks did not read their own bricks");
      }
  }

  // Under the default early termination, within its bound of the single-process render.
  for (const View& view : views(grid)) {
    Scene scene = sceneFor(rawFile, view.camera, true);
    scene.sampling.earlyTermination = kDefaultEarlyTermination;
    const node::FrameResult result = node::renderFrame(scene, {}, comm);
    ++frames;
    if (comm.rank() == 0) {
      const double diff = maxAbsDifference(result.image, renderSerial(scene));
      std::printf("early termination, %d ranks, %s, dense: max abs difference %.2e (bound %.2e)\n", n,
                  view.name.c_str(), diff, terminationBound(n));
      check(comm, diff <= terminationBound(n),
            "early termination " + std::to_string(kDefaultEarlyTermination) + ", dense, " + view.name + ", " +
                std::to_string(n) + " ranks: max abs difference " + std::to_string(diff) + " above " +
                std::to_string(terminationBound(n)));
    }
  }

  // The scatter path (gzip: rank 0 reads and sends bricks) renders alike.
  for (const auto& entry : node::decompositions()) {
    const Scene scene = sceneFor(gzipFile, views(grid)[2].camera, false);
    node::FrameOptions options;
    options.decomposition = entry.value;
    const node::FrameResult result = node::renderFrame(scene, options, comm);
    ++frames;
    check(comm, !result.readPartially, "gzip volume: expected rank 0 to scatter");
    if (comm.rank() == 0) {
      const double diff = maxAbsDifference(result.image, renderSerial(scene));
      check(comm, diff <= kTolerance, "scattered bricks: max abs difference " + std::to_string(diff));
    }
  }

  // Binary swap on a dense volume: log2(n) messages per rank for n a power
  // of two, and the paper's bound on pixels sent over all ranks,
  // sum over phases i = 1..log n of (1/2) 2^(-(i-1)/3) n^(1/3) p <= 2.43 n^(1/3) p.
  if (std::has_single_bit(unsigned(n))) {
    for (std::size_t v = 0; v < 3; ++v) {
      // Zoomed in so the dense volume covers the whole frame, as the analysis assumes.
      Scene scene = sceneFor(rawFile, views(grid)[v].camera, true);
      scene.camera.height *= 0.45;
      scene.camera.fovYDeg = 14;
      scene.image.width = scene.image.height = 64;
      const node::FrameResult result = node::renderFrame(scene, {}, comm);
      ++frames;
      std::uint64_t pixels = 0;
      for (const node::RankReport& r : result.ranks) {
        pixels += r.composite.pixelsSent;
        check(comm, r.composite.messagesSent == std::uint64_t(std::countr_zero(unsigned(n))),
              "binary swap sent " + std::to_string(r.composite.messagesSent) + " messages on a rank of " +
                  std::to_string(n));
      }
      const double p = 64.0 * 64.0, bound = 2.43 * std::cbrt(double(n)) * p;
      if (comm.rank() == 0)
        std::printf("binary swap, %d ranks, %s, dense: %llu pixels sent, bound 2.43 n^(1/3) p = %.0f (%.2f of it)\n",
                    n, views(grid)[v].name.c_str(), (unsigned long long)pixels, bound, pixels / bound);
      check(comm, double(pixels) <= bound, "binary swap pixels sent above 2.43 n^(1/3) p");
    }
  }
  if (comm.rank() == 0) std::printf("%d ranks: %d distributed frames, %d failed checks\n", n, frames, failures);
  return failures == 0 ? 0 : 1;
}

// Wraps a volume so that reading a brick fails on one rank.
class FailingSource final : public VolumeSource {
 public:
  FailingSource(std::unique_ptr<VolumeSource> inner, int failingRank, int myRank)
      : inner_(std::move(inner)), failingRank_(failingRank), myRank_(myRank) {}
  const GridGeometry& grid() const override { return inner_->grid(); }
  ScalarType type() const override { return inner_->type(); }
  bool canReadPartially() const override { return inner_->canReadPartially(); }
  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    if (myRank_ == failingRank_)
      throw Error(ErrorCode::kBadFile, "brick " + toString(stored) + ": checksum mismatch in bad-brick.raw");
    return inner_->readBox(owned, stored);
  }
  std::string describe() const override { return inner_->describe(); }

 private:
  std::unique_ptr<VolumeSource> inner_;
  int failingRank_, myRank_;
};

int failure(comm::Communicator& comm, const fs::path& dir) {
  comm::runAgreed(comm, [&] {
    if (comm.rank() == 0) {
      writeRawVolume(dir);
      writeGzipVolume(dir);
    }
  });
  const GridGeometry grid = openVolumeFile((dir / "ml.json").string())->grid();
  const int n = comm.size();
  // The last rank fails reading its own brick; with gzip rank 0 fails reading the whole.
  const std::vector<std::pair<std::string, int>> cases = {{"ml.json", n - 1}, {"ml.nhdr", 0}};
  for (const auto& [file, failing] : cases)
    for (const auto& [strategy, decomposition] :
         {std::pair{"binary-swap", node::Decomposition::kKd}, {"direct-send", node::Decomposition::kBalanced}}) {
      node::FrameOptions options;
      options.strategy = strategy;
      options.decomposition = decomposition;
      options.openVolume = [&, failing = failing](const VolumeSpec& spec) {
        return std::make_unique<FailingSource>(openSceneVolume(spec), failing, comm.rank());
      };
      std::string message = "no error";
      try {
        node::renderFrame(sceneFor((dir / file).string(), views(grid)[1].camera, false), options, comm);
      } catch (const Error& e) {
        message = e.what();
      }
      // Every rank holds the same message, naming the failing rank.
      const auto* p = reinterpret_cast<const std::byte*>(message.data());
      const auto all = comm.allGather(std::span<const std::byte>(p, message.size()));
      bool same = true;
      for (const auto& m : all) same = same && std::string(reinterpret_cast<const char*>(m.data()), m.size()) == message;
      const std::string expected = "rank " + std::to_string(failing) + ": brick ";
      check(comm, same, file + ": ranks disagree on the error");
      check(comm, message.rfind(expected, 0) == 0, file + ": unexpected error '" + message + "'");
      if (comm.rank() == 0) std::printf("%d ranks, %s, %s: every rank failed with '%s'\n", n, file.c_str(), strategy, message.c_str());
    }
  // Nothing is left stuck: a good frame still renders.
  node::renderFrame(sceneFor((dir / "ml.json").string(), views(grid)[1].camera, false), {}, comm);
  return failures == 0 ? 0 : 1;
}

int compare(const std::string& a, const std::string& b, double tolerance) {
  const double diff = maxAbsDifference(readExr(a), readExr(b));
  std::printf("%s vs %s: max abs difference %g (tolerance %g)\n", a.c_str(), b.c_str(), diff, tolerance);
  return diff <= tolerance ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  try {
    if (mode == "compare" && argc == 5) return compare(argv[2], argv[3], std::stod(argv[4]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare: %s\n", e.what());
    return 1;
  }
  if (mode == "pml" && argc == 2) {
    // The PML a rank's MPI was told to use, as MpiEnvironment leaves it.
    comm::MpiEnvironment mpi(&argc, &argv);
    const char* pml = std::getenv("OMPI_MCA_pml");
    std::printf("rank %d pml %s\n", mpi.world().rank(), pml ? pml : "(none)");
    return 0;
  }
  if ((mode != "matrix" && mode != "failure" && mode != "steering") || argc != 3) {
    std::fprintf(stderr, "usage: %s matrix|failure|steering DIR | pml | compare A.exr B.exr TOL\n", argv[0]);
    return 2;
  }
  comm::MpiEnvironment mpi(&argc, &argv);
  comm::Communicator& comm = mpi.world();
  try {
    if (mode == "steering") return steering(comm);  // steering_checks.cpp
    const fs::path dir = argv[2];
    if (comm.rank() == 0) fs::create_directories(dir);
    comm.barrier();
    return mode == "matrix" ? matrix(comm, dir) : failure(comm, dir);
  } catch (const Error& e) {
    if (comm.rank() == 0) std::fprintf(stderr, "FAILED: %s\n", e.what());
    return 1;
  }
}
