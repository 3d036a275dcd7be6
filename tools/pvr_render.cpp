// pvr-render: render one scene in this process, all cores.
//
//   pvr-render SCENE.json -o OUT.exr|OUT.png [--step H] [--size WxH] [--threads N]
//              [--frames N] [--preintegrated on|off] [--skip on|off]
//
// EXR holds linear premultiplied RGBA float32 before the background; PNG is
// composited over the background in sRGB. Prints time per frame and samples
// per second; --frames renders the same frame N times and reports the median.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "error.h"
#include "image_io.h"
#include "raycast/raycaster.h"
#include "scene.h"
#include "scene_volume.h"

namespace {

struct Args {
  std::string scene, output;
  double step = 0;
  int width = 0, height = 0, threads = 0, frames = 1;
  int preintegrated = -1, skip = -1;  // -1: as the scene says
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "pvr-render: %s\nusage: pvr-render SCENE.json -o OUT.exr|OUT.png [--step H] "
               "[--size WxH] [--threads N] [--frames N] [--preintegrated on|off] [--skip on|off]\n",
               why.c_str());
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
  if (a.scene.empty()) usage("no scene file");
  if (a.output.empty()) usage("no output file (-o)");
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pvr::core;
  const Args args = parseArgs(argc, argv);
  try {
    Scene scene = loadSceneFile(args.scene);
    if (args.step > 0) scene.sampling.step = args.step;
    if (args.width > 0) scene.image.width = args.width, scene.image.height = args.height;
    if (args.preintegrated >= 0) scene.sampling.preintegrated = args.preintegrated == 1;

    const auto source = openSceneVolume(scene.volumes.front().source);
    resolveDefaults(scene, source->grid());
    // The scene's time step of a series (step 0, the volume itself, otherwise).
    const Brick volume = source->step(scene.volumes.front().source.timestep).readAll();

    RenderOptions options = renderOptionsFor(scene);
    if (args.skip >= 0) options.skipEmpty = args.skip == 1;
    ThreadPool pool(args.threads);
    BrickRenderer renderer(volume);
    renderer.classify(scene.volumes.front().transfer, options);
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
    std::printf("%s: %s, %dx%d, %d threads\n", args.output.c_str(), source->describe().c_str(),
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
