// What speed_vs_error measures, apart from how it prints it.
//
// A BenchScene is one scene document resolved at its own image size with its
// volume in memory. Its reference is the same scene integrated by
// tests/renderer/reference.h (double precision, substep dt far below any step the
// sweep uses), rendered at a reduced "error size" so that it stays
// affordable; every test image compared with it is rendered at that same
// size, while frame times are measured at the scene's own size. References
// are cached on disk, keyed by everything they depend on (the resolved scene
// without its sampling section, the error size, dt, the volume file's
// identity and this executable's own bytes), so a rebuilt program never
// reads a stale one.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "image.h"
#include "io/volume_io.h"
#include "raycast/raycaster.h"
#include "scene.h"
#include "thread_pool.h"

namespace pvr::bench {

// Why a scene cannot run here (its volume file is absent), or nothing.
std::optional<std::string> missingVolume(const std::string& scenePath);

class BenchScene {
 public:
  // Loads and resolves the scene and reads its whole volume. Throws pvr::Error.
  explicit BenchScene(const std::string& path);

  const std::string& path() const { return path_; }
  const core::Scene& scene() const { return scene_; }  // resolved
  const core::Brick& volume() const { return volume_; }
  std::string describe() const { return source_->describe(); }
  double voxel() const { return volume_.grid().minSpacing(); }

 private:
  std::string path_;
  core::Scene scene_;
  std::unique_ptr<core::VolumeSource> source_;
  core::Brick volume_;
};

// The scene's image scaled down, aspect kept, so its longer side is at most
// maxEdge (unchanged when it already fits).
struct ImageSize {
  int width = 0, height = 0;
};
ImageSize errorImageSize(const core::Scene& scene, int maxEdge);

struct ReferenceSettings {
  int maxEdge = 256;       // error-image size: longer side
  double substeps = 64;    // dt = smallest spacing / substeps ...
  double minStepRatio = 16;  // ... and at most the scene's own step / minStepRatio
  std::string cacheDir;    // empty: no cache
};

struct Reference {
  core::Image image;
  ImageSize size;
  double dt = 0;            // world units
  double seconds = 0;       // to integrate it (when it was computed)
  bool fromCache = false;
  // The reference's own convergence: dt against dt/2 on every 8th pixel of
  // every 8th row (RGBA max abs and RMSE over those pixels).
  double selfCheckMaxAbs = 0, selfCheckRmse = 0;
};
Reference computeReference(const BenchScene& scene, const ReferenceSettings& settings,
                           core::ThreadPool& pool);

struct Case {
  double step = 0;  // world units
  bool preintegrated = false;
  bool skipEmpty = true;
  double targetPsnr = 0;  // > 0: the step per region for this PSNR (sampling.target_psnr)
  double earlyTermination = core::kDefaultEarlyTermination;  // a ray stops at this opacity; 1 = never
};
// The case the scene file itself asks for (its step, its pre-integration,
// skipping on as in pvr-render).
Case ownCase(const core::Scene& scene);

struct Timing {
  int frames = 0;
  double median = 0, min = 0, max = 0;  // seconds per frame
  std::uint64_t samples = 0;            // summed over the timed frames
  // Mean samples of a frame over the median time of a frame.
  double samplesPerSecond() const {
    return frames > 0 && median > 0 ? double(samples) / frames / median : 0;
  }
};

struct CaseResult {
  Timing timing;
  core::ImageError error;
  core::Image image;  // the case rendered at the reference's size and view (for error)
  double load1 = 0;  // 1-minute load average when the case started
};

// Renders the case once at the reference's size and compares (this also
// warms caches), then up to `frames` timed frames at the scene's own size;
// with capSeconds > 0 it stops early, after at least one frame, once the
// timed frames add up to capSeconds (Timing::frames says how many ran). With
// orbitDegrees != 0 every timed frame first turns the camera by that angle
// about its (orthogonalised) view-up through the look-at point, as VTK's
// Azimuth does in the peer benchmark; the error is always measured at the
// scene's own view.
CaseResult measureCase(const BenchScene& scene, const Case& c, const Reference& reference,
                       int frames, double capSeconds, double orbitDegrees, core::ThreadPool& pool);

// The camera turned by `degrees` about its view-up (orthogonalised against
// the view direction) through the look-at point; the new view-up is that
// orthogonalised vector.
core::CameraSpec azimuth(const core::CameraSpec& camera, double degrees);

double loadAverage1();

// Another renderer's frame against the same reference: an 8-bit RGB image
// (VTK's PNG, composited over black) and ours made alike. A premultiplied
// image over black is its RGB, so the reference's RGB is what a perfect
// renderer would have drawn; alpha is not compared.
//
// (The other renderer's file is read by core::readPngCodes.)
// The image over black, each channel rounded to 8 bits as a PNG would hold it.
core::Image quantised8(const core::Image& image);
// RMSE, PSNR and max abs error over the R, G and B channels only, full frame.
core::ImageError rgbError(const core::Image& test, const core::Image& reference);

// What a transfer-function change costs with pre-integration on: building
// the pre-integration table alone, and the renderer's whole classify()
// (both tables, the macrocells' visibility and the clear cells) after a
// change that moves the transparent ends and after one of colour alone,
// medians of `repeats`.
struct RebuildTimes {
  double table = 0, classify = 0;  // seconds
  double colourClassify = 0;       // classify() after a change of colour alone (the transparent ends kept)
};
RebuildTimes rebuildTimes(const BenchScene& scene, int repeats, core::ThreadPool& pool);

}  // namespace pvr::bench
