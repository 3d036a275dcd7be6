// pvr-render: render one scene (one volume or several, mixed as
// overlapping media), or one volume file with defaults, in this process,
// all cores.
//
//   pvr-render SCENE.json|VOLUME -o OUT.exr|OUT.png [options]   (--help lists them)
//
// A volume file (NIfTI, NRRD, the .json sidecar of ../shared/data, any
// registered format) renders with the automatic camera, a white ramp over
// the data's value range (computed by the reader's pass over the voxels,
// so free) and shading on. EXR holds linear premultiplied RGBA float32
// before the background; PNG is composited over the background in sRGB.
// Prints time per frame and samples per second; --frames renders the same
// frame N times and reports the median.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "error.h"
#include "image_io.h"
#include "io/volume_io.h"
#include "raycast/raycaster.h"
#include "raycast/scene_renderer.h"
#include "scene.h"
#include "scene_volume.h"

namespace {

struct Args {
  std::string scene, output;
  double step = 0;
  int width = 0, height = 0, threads = 0, frames = 1;
  int preintegrated = -1, skip = -1, shading = -1;  // -1: as the scene says
};

// The command line and every option, one line each: --help prints it, a
// bad command line its first line; man/pvr-render.1 follows it.
constexpr const char* kUsage =
    "usage: pvr-render SCENE.json|VOLUME -o OUT.exr|OUT.png [OPTION VALUE ...]\n"
    "\n"
    "Renders one scene (docs/scene.md), or one volume file with defaults, in this process.\n"
    "A VOLUME (.nii, .nii.gz, .nhdr, .nrrd, the .json sidecar of a raw file) gets the automatic\n"
    "camera, a white opacity ramp over the data's value range (clear below its first tenth) and\n"
    "shading on.\n"
    "\n"
    "options:\n"
    "  -o OUT.exr|OUT.png          the image (EXR: linear premultiplied float; PNG: sRGB over the background)\n"
    "  --size WxH                  image size in pixels (default: the scene's, 512x512)\n"
    "  --step H                    sample distance in world units (default: half the smallest spacing)\n"
    "  --shading on|off            gradient shading (default: the scene's; on for a volume file)\n"
    "  --preintegrated on|off      pre-integrated classification (default: the scene's)\n"
    "  --skip on|off               empty-space skipping (default on)\n"
    "  --threads N                 render threads (default: all cores)\n"
    "  --frames N                  render N times and report the median time (default 1)\n"
    "  -h, --help                  print this help and exit\n"
    "\n"
    "examples:\n"
    "  pvr-render head.nii.gz -o head.png\n"
    "  pvr-render examples/scenes/ct_head_bone.json -o bone.exr --size 1024x1024\n";

[[noreturn]] void usage(const std::string& why) {
  const std::string text(kUsage);
  std::fprintf(stderr, "pvr-render: %s\n%s(pvr-render --help lists every option)\n", why.c_str(),
               text.substr(0, text.find('\n') + 1).c_str());
  std::exit(2);
}

int onOff(const std::string& option, const std::string& v) {
  if (v == "on") return 1;
  if (v == "off") return 0;
  usage(option + " takes on or off, not '" + v + "'");
}

Args parseArgs(int argc, char** argv) {
  using pvr::core::kMaxImageSide;
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    }
    try {
      if (arg == "-o") a.output = value();
      else if (arg == "--step") {
        a.step = std::stod(value());
        if (!(a.step > 0)) usage("--step must be > 0");
      }
      else if (arg == "--threads") a.threads = std::stoi(value());
      else if (arg == "--frames") a.frames = std::max(1, std::stoi(value()));
      else if (arg == "--preintegrated") a.preintegrated = onOff(arg, value());
      else if (arg == "--skip") a.skip = onOff(arg, value());
      else if (arg == "--shading") a.shading = onOff(arg, value());
      else if (arg == "--size") {
        const std::string v = value();
        if (std::sscanf(v.c_str(), "%dx%d", &a.width, &a.height) != 2 || a.width < 1 || a.height < 1 ||
            a.width > kMaxImageSide || a.height > kMaxImageSide)
          usage("--size takes WxH, each in 1.." + std::to_string(kMaxImageSide) + ", not '" + v + "'");
      } else if (!arg.empty() && arg[0] == '-') usage("unknown option " + arg);
      else if (a.scene.empty()) a.scene = arg;
      else usage("more than one scene file");
    } catch (const std::logic_error&) {
      usage(arg + ": not a number");
    }
  }
  if (a.scene.empty()) usage("no scene or volume file");
  if (a.output.empty()) usage("no output file (-o)");
  return a;
}

// A scene document is a JSON object with "volume" or "volumes"; any other
// file (a JSON sidecar included) is a volume for a format to open.
bool isSceneFile(const std::string& path) {
  if (std::filesystem::path(path).extension() != ".json") return false;
  std::ifstream in(path);
  const auto doc = nlohmann::json::parse(in, nullptr, false);
  return doc.is_object() && (doc.contains("volume") || doc.contains("volumes"));
}

// The scene of a bare volume file: every default is the data's
// (resolveDefaults, resolveDataDefaults): the automatic camera, shading for
// 3-D data, the white ramp over the value range.
pvr::core::Scene sceneOfVolume(const std::string& path) {
  return pvr::core::parseScene({{"volume", {{"file", std::filesystem::absolute(path).string()}}}}, ".");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pvr::core;
  const Args args = parseArgs(argc, argv);
  try {
    // Every volume of the scene, whole, in the scene's order.
    Scene scene;
    std::vector<std::unique_ptr<VolumeSource>> sources;
    std::vector<Brick> volumes;
    if (isSceneFile(args.scene)) {
      scene = loadSceneFile(args.scene);
      for (const SceneVolume& v : scene.volumes) {
        sources.push_back(openSceneVolume(v.source));
        // The scene's time step of a series (step 0, the volume itself, otherwise).
        volumes.push_back(sources.back()->step(v.source.timestep).readAll());
      }
    } else {
      sources.push_back(openVolumeFile(args.scene));
      volumes.push_back(sources.back()->readAll());
      scene = sceneOfVolume(args.scene);
    }
    if (args.step > 0) scene.sampling.step = args.step;
    if (args.width > 0) scene.image.width = args.width, scene.image.height = args.height;
    if (args.preintegrated >= 0) scene.sampling.preintegrated = args.preintegrated == 1;
    if (args.shading >= 0) scene.shading.enabled = args.shading == 1;
    std::vector<GridGeometry> grids;
    for (const auto& source : sources) grids.push_back(source->grid());
    resolveDefaults(scene, grids);
    // Each volume's data range fits its default ramp or stretches its
    // preset (one rule for every program: resolveDataDefaults).
    for (std::size_t i = 0; i < volumes.size(); ++i)
      resolveDataDefaults(scene.volumes[i].transfer, volumes[i].valueRange().min, volumes[i].valueRange().max);

    RenderOptions options = renderOptionsFor(scene);
    if (args.skip >= 0) options.skipEmpty = args.skip == 1;
    ThreadPool pool(args.threads);
    std::vector<const Brick*> bricks;
    for (const Brick& v : volumes) bricks.push_back(&v);
    SceneRenderer renderer(bricks);
    renderer.classify(scene.volumes, options);
    const Camera camera(scene.camera, scene.image.width, scene.image.height);

    Image image;
    RenderStats stats;
    std::vector<double> seconds;
    for (int f = 0; f < args.frames; ++f) {
      image = renderer.render(camera, options, pool, &stats);
      seconds.push_back(stats.seconds);
    }
    std::sort(seconds.begin(), seconds.end());
    const double median = seconds[seconds.size() / 2];
    writeImage(image, scene.image.background, args.output);
    std::string described;
    for (const int i : renderer.shown())
      described += (described.empty() ? "" : " + ") + sources[std::size_t(i)]->describe();
    if (described.empty()) described = "no visible volume";
    std::printf("%s: %s, %dx%d, %d threads\n", args.output.c_str(), described.c_str(),
                scene.image.width, scene.image.height, pool.size());
    std::printf("time per frame %.4f s (median of %d), %.1f M samples/s, %.1f M samples/s per thread\n",
                median, args.frames, stats.samples / median * 1e-6,
                stats.samples / median * 1e-6 / pool.size());
    return 0;
  } catch (const pvr::Error& e) {
    std::fprintf(stderr, "pvr-render: %s\n", e.what());
    return 1;
  }
}
