#include "measure.h"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string_view>

#include <nlohmann/json.hpp>

#include "camera.h"
#include "error.h"
#include "image_io.h"
#include "reference.h"
#include "scene_volume.h"

namespace pvr::bench {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// FNV-1a, 64 bits: a stable hash for cache keys (std::hash promises nothing
// across builds).
class Fnv1a {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  void add(std::string_view s) { add(s.data(), s.size()); }
  void addFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> buffer(1 << 16);
    while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0)
      add(buffer.data(), std::size_t(in.gcount()));
  }
  std::string hex() const {
    char out[17];
    std::snprintf(out, sizeof out, "%016" PRIx64, h_);
    return out;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// Everything a reference depends on, hashed: the resolved scene without its
// sampling (the reference ignores step, pre-integration and early
// termination), the image it is rendered at, dt, the voxels, and the code
// (this executable: any rebuild of the reference or the loaders changes it).
std::string referenceKey(const BenchScene& scene, ImageSize size, double dt) {
  nlohmann::json doc = core::sceneToJson(scene.scene());
  doc.erase("sampling");
  doc["image"]["width"] = size.width;
  doc["image"]["height"] = size.height;
  doc["reference_dt"] = dt;
  Fnv1a h;
  h.add(doc.dump());
  h.add(scene.volume().bytes(), scene.volume().byteSize());
  h.addFile("/proc/self/exe");
  return fs::path(scene.path()).stem().string() + "-" + h.hex();
}

// dt against dt/2 on a sparse lattice of pixels: how far the reference
// itself is from converged.
void selfCheck(const core::ReferenceVolume& volume, const core::Scene& s,
               const core::Camera& camera, const core::ReferenceOptions& options,
               const core::Image& image, Reference& out, core::ThreadPool& pool) {
  constexpr int kEvery = 8;
  core::ReferenceOptions fine = options;
  fine.step = options.step / 2;
  const core::Vec3 light = core::referenceLight(camera, s.shading);
  const int rows = (camera.height() + kEvery / 2) / kEvery;
  std::vector<double> rowMax(std::size_t(rows), 0), rowSum(std::size_t(rows), 0);
  std::vector<int> rowCount(std::size_t(rows), 0);
  pool.parallelFor(std::size_t(rows), [&](std::size_t r, int) {
    const int y = int(r) * kEvery + kEvery / 2;
    if (y >= camera.height()) return;
    for (int x = kEvery / 2; x < camera.width(); x += kEvery) {
      const core::RgbaD f = core::integrateRay(volume, s.volumes.front().transfer, camera.ray(x, y), light, fine);
      const core::Rgba c = image.at(x, y);
      for (double d : {f.r - c.r, f.g - c.g, f.b - c.b, f.a - c.a}) {
        rowMax[r] = std::max(rowMax[r], std::abs(d));
        rowSum[r] += d * d;
      }
      rowCount[r] += 4;
    }
  });
  double worst = 0, sum = 0, n = 0;
  for (std::size_t r = 0; r < rowMax.size(); ++r) {
    worst = std::max(worst, rowMax[r]);
    sum += rowSum[r];
    n += rowCount[r];
  }
  out.selfCheckMaxAbs = worst;
  out.selfCheckRmse = n > 0 ? std::sqrt(sum / n) : 0;
}

bool readCached(const std::string& stem, Reference& out) {
  std::ifstream meta(stem + ".json");
  if (!meta || !fs::exists(stem + ".exr")) return false;
  try {
    const nlohmann::json doc = nlohmann::json::parse(meta);
    out.image = core::readExr(stem + ".exr");
    out.seconds = doc.at("seconds").get<double>();
    out.selfCheckMaxAbs = doc.at("self_check_max_abs").get<double>();
    out.selfCheckRmse = doc.at("self_check_rmse").get<double>();
  } catch (const std::exception&) {
    return false;  // a damaged cache entry is computed again
  }
  return out.image.frameWidth() == out.size.width && out.image.frameHeight() == out.size.height;
}

void writeCached(const std::string& stem, const Reference& ref) {
  core::writeExr(ref.image, stem + ".exr");
  std::ofstream meta(stem + ".json");
  meta << nlohmann::json{{"dt", ref.dt},
                         {"seconds", ref.seconds},
                         {"self_check_max_abs", ref.selfCheckMaxAbs},
                         {"self_check_rmse", ref.selfCheckRmse}}
              .dump(2)
       << "\n";
}

}  // namespace

std::optional<std::string> missingVolume(const std::string& scenePath) {
  const core::Scene scene = core::loadSceneFile(scenePath);
  if (scene.volumes.front().source.file.empty() || fs::exists(scene.volumes.front().source.file)) return std::nullopt;
  return scene.volumes.front().source.file + " is missing";
}

BenchScene::BenchScene(const std::string& path) : path_(path), scene_(core::loadSceneFile(path)) {
  source_ = core::openSceneVolume(scene_.volumes.front().source);
  core::resolveDefaults(scene_, source_->grid());
  volume_ = source_->readAll();
}

ImageSize errorImageSize(const core::Scene& scene, int maxEdge) {
  const int w = scene.image.width, h = scene.image.height;
  const int longer = std::max(w, h);
  if (longer <= maxEdge) return {w, h};
  const double f = double(maxEdge) / longer;
  return {std::max(1, int(std::lround(w * f))), std::max(1, int(std::lround(h * f)))};
}

Reference computeReference(const BenchScene& scene, const ReferenceSettings& settings,
                           core::ThreadPool& pool) {
  const core::Scene& s = scene.scene();
  Reference ref;
  ref.size = errorImageSize(s, settings.maxEdge);
  ref.dt = std::min(scene.voxel() / settings.substeps, s.sampling.step / settings.minStepRatio);

  std::string stem;
  if (!settings.cacheDir.empty()) {
    fs::create_directories(settings.cacheDir);
    stem = (fs::path(settings.cacheDir) / referenceKey(scene, ref.size, ref.dt)).string();
    if (readCached(stem, ref)) {
      ref.fromCache = true;
      return ref;
    }
  }

  // Integrate every pixel, then check the integration against a halved dt.
  const auto started = Clock::now();
  const core::ReferenceVolume volume(scene.volume());
  const core::Camera camera(s.camera, ref.size.width, ref.size.height);
  core::ReferenceOptions options;
  options.step = ref.dt;
  options.shading = s.shading;
  ref.image = core::renderReference(volume, s.volumes.front().transfer, camera, options, pool);
  ref.seconds = secondsSince(started);
  selfCheck(volume, s, camera, options, ref.image, ref, pool);

  if (!stem.empty()) writeCached(stem, ref);
  return ref;
}

Case ownCase(const core::Scene& scene) {
  return {scene.sampling.step, scene.sampling.preintegrated, true, scene.sampling.targetPsnr,
          scene.sampling.earlyTermination};
}

core::CameraSpec azimuth(const core::CameraSpec& camera, double degrees) {
  const core::Vec3 offset = camera.eye - camera.lookAt;
  const core::Vec3 forward = normalize(-offset);
  const core::Vec3 k = normalize(camera.up - forward * dot(camera.up, forward));
  const double a = degrees * std::acos(-1.0) / 180;
  const core::Vec3 turned = core::rotateAbout(offset, k, a);
  core::CameraSpec out = camera;
  out.eye = camera.lookAt + turned;
  out.up = k;
  return out;
}

double loadAverage1() {
  std::ifstream in("/proc/loadavg");
  double load = 0;
  in >> load;
  return load;
}

core::Image quantised8(const core::Image& image) {
  core::Image out = image.toFullFrame();
  auto byte = [](float v) { return std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f; };
  for (core::Rgba& p : out.pixels()) p = {byte(p.r), byte(p.g), byte(p.b), 0.0f};
  return out;
}

core::ImageError rgbError(const core::Image& test, const core::Image& reference) {
  if (test.frameWidth() != reference.frameWidth() || test.frameHeight() != reference.frameHeight())
    throw Error(ErrorCode::kInvalidArgument,
                "rgbError: " + std::to_string(test.frameWidth()) + "x" + std::to_string(test.frameHeight()) +
                    " against a reference of " + std::to_string(reference.frameWidth()) + "x" +
                    std::to_string(reference.frameHeight()));
  double sum = 0, worst = 0;
  for (int y = 0; y < test.frameHeight(); ++y)
    for (int x = 0; x < test.frameWidth(); ++x) {
      const core::Rgba p = test.sample(x, y), q = reference.sample(x, y);
      for (double d : {double(p.r) - q.r, double(p.g) - q.g, double(p.b) - q.b}) {
        sum += d * d;
        worst = std::isnan(d) ? std::numeric_limits<double>::infinity() : std::max(worst, std::abs(d));
      }
    }
  core::ImageError e;
  const double n = 3.0 * test.frameWidth() * test.frameHeight();
  e.rmse = n > 0 ? std::sqrt(sum / n) : 0;
  e.psnr = e.rmse > 0 ? 20.0 * std::log10(1.0 / e.rmse) : std::numeric_limits<double>::infinity();
  e.maxAbs = worst;
  return e;
}

RebuildTimes rebuildTimes(const BenchScene& scene, int repeats, core::ThreadPool& pool) {
  const core::Scene& s = scene.scene();
  const core::TransferFunctionSpec& tf = s.volumes.front().transfer;
  // Moved by a hundredth of its span (its transparent ends move with it),
  // and recoloured (its ends stay): each classify below is a change.
  core::TransferFunctionSpec moved = tf, recoloured = tf;
  const double shift = 0.01 * (tf.points.back().scalar - tf.points.front().scalar);
  for (core::TransferPoint& point : moved.points) point.scalar += shift;
  for (core::TransferPoint& point : recoloured.points) point.r = 1.0 - point.r;
  core::RenderOptions options = core::renderOptionsFor(s);
  options.preintegrated = true;
  core::BrickRenderer renderer(scene.volume());
  std::vector<double> table, classify, colour;
  auto timed = [](auto&& work) {
    const auto started = Clock::now();
    work();
    return secondsSince(started);
  };
  for (int i = 0; i < repeats; ++i) {
    table.push_back(timed([&] { const core::PreintegratedTable built(tf); }));
    classify.push_back(timed([&] { renderer.classify(i % 2 ? tf : moved, options, &pool); }));
  }
  for (int i = 0; i < repeats; ++i) colour.push_back(timed([&] { renderer.classify(i % 2 ? tf : recoloured, options, &pool); }));
  auto median = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  return {median(table), median(classify), median(colour)};
}

CaseResult measureCase(const BenchScene& scene, const Case& c, const Reference& reference,
                       int frames, double capSeconds, double orbitDegrees, core::ThreadPool& pool) {
  const core::Scene& s = scene.scene();
  CaseResult result;
  result.load1 = loadAverage1();

  core::RenderOptions options = core::renderOptionsFor(s);
  options.step = c.step;
  options.preintegrated = c.preintegrated;
  options.skipEmpty = c.skipEmpty;
  options.targetPsnr = c.targetPsnr;
  options.earlyTermination = c.earlyTermination;
  core::BrickRenderer renderer(scene.volume());
  renderer.classify(s.volumes.front().transfer, options);

  // Error at the reference's size and view (this render also warms the caches).
  const core::Camera small(s.camera, reference.size.width, reference.size.height);
  result.image = renderer.render(small, options, pool).toFullFrame();
  result.error = core::compareImages(result.image, reference.image);

  // Timed frames at the scene's own size.
  std::vector<double> seconds;
  double spent = 0;
  core::CameraSpec view = s.camera;
  for (int f = 0; f < frames && !(capSeconds > 0 && spent >= capSeconds); ++f) {
    if (orbitDegrees != 0) view = azimuth(view, orbitDegrees);
    const core::Camera camera(view, s.image.width, s.image.height);
    core::RenderStats stats;
    const auto started = Clock::now();
    renderer.render(camera, options, pool, &stats);
    seconds.push_back(secondsSince(started));
    spent += seconds.back();
    result.timing.samples += stats.samples;
  }
  std::sort(seconds.begin(), seconds.end());
  Timing& t = result.timing;
  t.frames = int(seconds.size());
  if (!seconds.empty()) {
    t.median = seconds[seconds.size() / 2];
    t.min = seconds.front();
    t.max = seconds.back();
  }
  return result;
}

}  // namespace pvr::bench
