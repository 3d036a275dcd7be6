// speed_vs_error: what each rendering setting costs and what it buys.
//
//   speed_vs_error [options] [SCENE.json ...]
//       For each scene (default: the phantom, the peer scene and one scene per
//       real volume; a scene whose volume file is missing is skipped with a
//       message) sweeps step {2, 1, 0.5, 0.25, 0.125} voxels x {plain,
//       pre-integrated} x {skipping on, off}, plus the scene's own settings
//       when they are not among them. Per case: median time per frame, samples
//       per second (total and per thread) and RMSE / PSNR / max abs error of
//       linear premultiplied RGBA against the scene's reference. Prints a
//       table and writes CSV.
//   speed_vs_error --quick SCENE.json [--orbit K] [--step S]
//       The scene at its own settings only, the same figures, for scripts/demo.
//       --orbit K times K frames turning the camera 5 degrees each about its
//       view-up, the camera path of the VTK peer benchmark.
//       --step S renders at S voxels instead of the scene's own step, so a
//       faster, coarser setting is timed beside its error (issue 13 compares
//       speeds "at no larger error" than the peer's).
//       --early-termination A stops rays at opacity A instead of the scene's
//       sampling.early_termination (1: never; early_termination.sh).
//       --peer-png FILE compares another renderer's 8-bit RGB frame of the
//       scene's own view (VTK's PNG, over black, at the reference's size:
//       pass --error-size to match) with the same reference, beside ours
//       rounded to 8 bits the same way (RGB only: bench::rgbError).
//       --peer-model SCENE.json also compares that frame with the reference
//       of SCENE, the same scene as the other renderer models it (VTK:
//       bench/scenes/peer_blobs.py vtk-model), to tell its numerical error
//       from the difference of models.
//
// Options: --threads N (2), --frames N (5), --error-size N (256: longer side of
// the reference and of the images compared with it), --substeps N (64: the
// reference's dt is the smallest spacing / N, at most the scene step / 16),
// --steps LIST (voxels, comma-separated), --quality LIST (dB, comma-separated:
// per scene and target, sampling.target_psnr at the scene's step, its
// achieved PSNR and time beside the time of a uniform step of the same
// error, interpolated from the sweep, which then runs plain sampling with
// skipping only; quality.sh runs it on every scene), --case-seconds S (sweep: stop timing
// a case once its frames add up to S seconds, after at least one; the CSV
// says how many frames each median has), --csv PATH, --cache DIR, --no-cache.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "error.h"
#include "image_io.h"
#include "measure.h"

namespace {

namespace fs = std::filesystem;
using namespace pvr;
using bench::BenchScene;
using bench::Case;
using bench::CaseResult;
using bench::Reference;

constexpr double kOrbitDegrees = 5;  // peer_common.ROTATE_DEG_PER_FRAME

// The sweep's scenes, relative to the source tree.
const char* const kDefaultScenes[] = {
    "examples/scenes/default.json",        "bench/scenes/peer_blobs.json",
    "examples/scenes/ct_head_bone.json",   "examples/scenes/mri_head.json",
    "examples/scenes/mri_brain_pd.json",   "examples/scenes/orbital_oxirane.json",
    "examples/scenes/water_density.json",
};

struct Args {
  std::string quick;
  std::string peerPng;  // --quick: another renderer's frame to compare (--peer-png)
  std::string peerModel;  // --quick: the scene as that renderer models it (--peer-model)
  std::vector<std::string> scenes;
  std::vector<double> steps{2, 1, 0.5, 0.25, 0.125};
  std::vector<double> quality;  // target PSNRs, dB
  int threads = 2, frames = 5, orbit = 0;
  double quickStep = 0;  // --quick --step: voxels instead of the scene's own step (0 = its own)
  double quickEarlyTermination = 0;  // --quick --early-termination: instead of the scene's (0 = its own)
  double caseSeconds = 0;  // sweep: stop timing a case after this long (0 = never)
  bench::ReferenceSettings reference{256, 64, 16, PVR_BENCH_CACHE};
  std::string csv = std::string(PVR_SOURCE_DIR) + "/bench/results/speed_vs_error.csv";
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "speed_vs_error: %s\n"
               "usage: speed_vs_error [--threads N] [--frames N] [--error-size N] [--substeps N]\n"
               "                      [--steps A,B,...] [--quality DB,DB,...] [--case-seconds S] [--csv PATH]\n"
               "                      [--cache DIR | --no-cache] [SCENE.json ...]\n"
               "       speed_vs_error --quick SCENE.json [--orbit K] [--step S] [--early-termination A]\n"
               "                      [--peer-png FILE [--peer-model SCENE.json]] [same options]\n",
               why.c_str());
  std::exit(2);
}

std::vector<double> parseList(const std::string& option, const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const double v = std::stod(item);
    if (!(v > 0)) usage(option + ": every value must be > 0");
    out.push_back(v);
  }
  if (out.empty()) usage(option + ": no values");
  return out;
}

Args parseArgs(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(arg + " needs a value");
      return argv[++i];
    };
    auto positive = [&](const std::string& v) {
      const int n = std::stoi(v);
      if (n < 1) usage(arg + " must be >= 1");
      return n;
    };
    try {
      if (arg == "--quick") a.quick = value();
      else if (arg == "--threads") a.threads = positive(value());
      else if (arg == "--frames") a.frames = positive(value());
      else if (arg == "--orbit") a.orbit = positive(value());
      else if (arg == "--peer-png") a.peerPng = value();
      else if (arg == "--peer-model") a.peerModel = value();
      else if (arg == "--step") a.quickStep = parseList(arg, value()).at(0);
      else if (arg == "--early-termination") a.quickEarlyTermination = parseList(arg, value()).at(0);
      else if (arg == "--case-seconds") a.caseSeconds = std::stod(value());
      else if (arg == "--error-size") a.reference.maxEdge = positive(value());
      else if (arg == "--substeps") a.reference.substeps = positive(value());
      else if (arg == "--steps") a.steps = parseList(arg, value());
      else if (arg == "--quality") a.quality = parseList(arg, value());
      else if (arg == "--csv") a.csv = value();
      else if (arg == "--cache") a.reference.cacheDir = value();
      else if (arg == "--no-cache") a.reference.cacheDir.clear();
      else if (!arg.empty() && arg[0] == '-') usage("unknown option " + arg);
      else a.scenes.push_back(arg);
    } catch (const std::logic_error&) {
      usage(arg + ": not a number");
    }
  }
  if (!a.quick.empty() && !a.scenes.empty()) usage("--quick takes one scene; no other scene files");
  if (a.quick.empty() && a.orbit > 0) usage("--orbit goes with --quick");
  if (a.quick.empty() && a.quickStep > 0) usage("--step goes with --quick (the sweep takes --steps)");
  if (a.quick.empty() && a.quickEarlyTermination > 0) usage("--early-termination goes with --quick");
  if (a.quickEarlyTermination > 1) usage("--early-termination must be in (0, 1]");
  if (a.quick.empty() && !a.peerPng.empty()) usage("--peer-png goes with --quick");
  if (a.peerPng.empty() && !a.peerModel.empty()) usage("--peer-model goes with --peer-png");
  if (a.scenes.empty())
    for (const char* s : kDefaultScenes) a.scenes.push_back(std::string(PVR_SOURCE_DIR) + "/" + s);
  return a;
}

std::string shortName(const std::string& scenePath) { return fs::path(scenePath).stem().string(); }

const char* onOff(bool b) { return b ? "on" : "off"; }

// A text field for the CSV without quoting: gnuplot and awk split on every comma.
std::string csvField(std::string text) {
  for (char& ch : text)
    if (ch == ',' || ch == '"') ch = ';';
  return text;
}

void printReference(const Reference& ref, const BenchScene& scene) {
  std::printf("  reference: %dx%d, dt %.4g voxel, double precision, %s %.1f s; "
              "self-check dt vs dt/2: max abs %.1e, RMSE %.1e\n",
              ref.size.width, ref.size.height, ref.dt / scene.voxel(),
              ref.fromCache ? "from cache, took" : "took", ref.seconds, ref.selfCheckMaxAbs,
              ref.selfCheckRmse);
}

int runQuick(const Args& args) {
  if (auto missing = bench::missingVolume(args.quick)) {
    std::printf("%s: skipped, %s\n", args.quick.c_str(), missing->c_str());
    return 0;
  }
  core::ThreadPool pool(args.threads);
  const BenchScene scene(args.quick);
  const core::Scene& s = scene.scene();
  Case c = bench::ownCase(s);
  if (args.quickStep > 0) c.step = args.quickStep * scene.voxel();
  if (args.quickEarlyTermination > 0) c.earlyTermination = args.quickEarlyTermination;
  std::printf("%s: %s, %dx%d, step %.3g voxel, %s, skipping on, %s, early termination %.6g, %d threads\n",
              args.quick.c_str(), scene.describe().c_str(), s.image.width, s.image.height,
              c.step / scene.voxel(), c.preintegrated ? "pre-integrated" : "plain",
              s.shading.enabled ? "shaded" : "unshaded", c.earlyTermination, pool.size());
  const Reference ref = bench::computeReference(scene, args.reference, pool);
  printReference(ref, scene);
  const double orbit = args.orbit > 0 ? kOrbitDegrees : 0;
  const int frames = args.orbit > 0 ? args.orbit : args.frames;
  const CaseResult r = bench::measureCase(scene, c, ref, frames, 0, orbit, pool);
  const bench::Timing& t = r.timing;
  std::printf("  time per frame     %.4f s (median of %d%s; min %.4f, max %.4f; load %.2f)\n",
              t.median, t.frames, args.orbit > 0 ? ", turning 5 degrees per frame" : "", t.min,
              t.max, r.load1);
  std::printf("  samples per second %.1f M total, %.1f M per core (%d threads); %.2f M a frame\n",
              t.samplesPerSecond() * 1e-6, t.samplesPerSecond() * 1e-6 / pool.size(), pool.size(),
              t.frames > 0 ? double(t.samples) / t.frames * 1e-6 : 0.0);
  std::printf("  error vs reference RMSE %.3e, PSNR %.2f dB, max abs %.3e (linear RGBA at %dx%d)\n",
              r.error.rmse, r.error.psnr, r.error.maxAbs, ref.size.width, ref.size.height);
  if (!args.peerPng.empty()) {
    // Both as 8-bit RGB over black against the reference's RGB, same pixels.
    const core::Image peer = core::readPngCodes(args.peerPng);
    if (peer.frameWidth() != ref.size.width || peer.frameHeight() != ref.size.height)
      throw Error(ErrorCode::kInvalidArgument,
                  args.peerPng + ": " + std::to_string(peer.frameWidth()) + "x" + std::to_string(peer.frameHeight()) +
                      ", the reference is " + std::to_string(ref.size.width) + "x" +
                      std::to_string(ref.size.height) + " (--error-size)");
    const core::ImageError theirs = bench::rgbError(peer, ref.image);
    const core::ImageError ours8 = bench::rgbError(bench::quantised8(r.image), ref.image);
    const core::ImageError ours = bench::rgbError(r.image, ref.image);
    std::printf("  peer frame error   RMSE %.3e, PSNR %.2f dB, max abs %.3e (%s, 8-bit RGB at %dx%d)\n",
                theirs.rmse, theirs.psnr, theirs.maxAbs, args.peerPng.c_str(), ref.size.width, ref.size.height);
    std::printf("  our 8-bit error    RMSE %.3e, PSNR %.2f dB, max abs %.3e (ours rounded to 8-bit RGB alike)\n",
                ours8.rmse, ours8.psnr, ours8.maxAbs);
    std::printf("  our RGB error      RMSE %.3e, PSNR %.2f dB, max abs %.3e (float RGB, not rounded)\n",
                ours.rmse, ours.psnr, ours.maxAbs);
    if (!args.peerModel.empty()) {
      const BenchScene model(args.peerModel);
      const Reference modelRef = bench::computeReference(model, args.reference, pool);
      const core::ImageError own = bench::rgbError(peer, modelRef.image);
      std::printf("  peer model error   RMSE %.3e, PSNR %.2f dB, max abs %.3e (the peer frame against the "
                  "reference of its own model, %s; reference took %.1f s)\n",
                  own.rmse, own.psnr, own.maxAbs, shortName(args.peerModel).c_str(), modelRef.seconds);
    }
  }
  return 0;
}

// The sweep's cases for a scene: the grid of settings, and the scene's own
// settings (flagged; added when the grid lacks them).
struct SweepCase {
  Case c;
  bool own = false;
};
std::vector<SweepCase> sweepCases(const Args& args, const BenchScene& scene) {
  const Case own = bench::ownCase(scene.scene());
  std::vector<SweepCase> cases;
  bool ownFound = false;
  // With --quality, the uniform steps the targets are compared with only.
  const std::vector<bool> pres = args.quality.empty() ? std::vector<bool>{false, true} : std::vector<bool>{false};
  const std::vector<bool> skips = args.quality.empty() ? std::vector<bool>{true, false} : std::vector<bool>{true};
  for (double steps : args.steps)
    for (bool pre : pres)
      for (bool skip : skips) {
        const Case c{steps * scene.voxel(), pre, skip, 0, own.earlyTermination};
        const bool isOwn = std::abs(c.step - own.step) <= 1e-6 * own.step &&
                           pre == own.preintegrated && skip == own.skipEmpty;
        ownFound |= isOwn;
        cases.push_back({c, isOwn});
      }
  if (!ownFound && args.quality.empty()) cases.push_back({own, true});
  return cases;
}

class CsvWriter {
 public:
  CsvWriter(const std::string& path, const Args& args) : out_(path) {
    if (!out_) throw Error(ErrorCode::kIo, path + ": cannot write");
    const std::time_t now = std::time(nullptr);
    char when[64];
    std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", std::localtime(&now));
    out_ << "# speed_vs_error " << when << ", " << args.threads << " threads, median of "
         << args.frames << " frames (fewer where a case's frames passed --case-seconds "
         << args.caseSeconds << "; see frames); error against a double-precision reference at "
         << "--error-size " << args.reference.maxEdge
         << "; load1 = 1-minute load average at the start of the case\n";
    out_ << "scene,volume,shaded,step_voxels,step_world,preintegrated,skipping,scene_default,"
            "threads,width,height,frames,median_s,min_s,max_s,samples_per_frame,msamples_per_s,"
            "msamples_per_s_per_core,error_width,error_height,rmse,psnr_db,max_abs,"
            "reference_dt_voxels,load1,target_psnr_db\n";
  }
  void row(const BenchScene& scene, const SweepCase& sc, const CaseResult& r, const Reference& ref,
           int threads) {
    const core::Scene& s = scene.scene();
    const bench::Timing& t = r.timing;
    char line[1024];
    std::snprintf(line, sizeof line,
                  "%s,%s,%d,%.6g,%.6g,%d,%d,%d,%d,%d,%d,%d,%.6f,%.6f,%.6f,%.0f,%.3f,%.3f,%d,%d,"
                  "%.6e,%.3f,%.6e,%.6g,%.2f,%.6g\n",
                  csvField(shortName(scene.path())).c_str(), csvField(scene.describe()).c_str(),
                  int(s.shading.enabled), sc.c.step / scene.voxel(), sc.c.step,
                  int(sc.c.preintegrated), int(sc.c.skipEmpty),
                  int(sc.own), threads, s.image.width, s.image.height, t.frames, t.median, t.min,
                  t.max, t.frames > 0 ? double(t.samples) / t.frames : 0.0,
                  t.samplesPerSecond() * 1e-6, t.samplesPerSecond() * 1e-6 / threads,
                  ref.size.width, ref.size.height, r.error.rmse, r.error.psnr, r.error.maxAbs,
                  ref.dt / scene.voxel(), r.load1, sc.c.targetPsnr);
    out_ << line;
    out_.flush();
  }

 private:
  std::ofstream out_;
};

// Pre-integration against plain sampling, skipping on, from one scene's
// sweep: at each step both errors, whether pre-integration is no worse,
// how its error at 2h compares with plain's at h, and its time over
// plain's at the same step.
struct SweepRow {
  SweepCase sc;
  CaseResult r;
};
void printPreintegration(const std::vector<SweepRow>& rows, const bench::RebuildTimes& rebuild,
                         double voxel) {
  auto find = [&](double steps, bool pre) -> const CaseResult* {
    for (const SweepRow& row : rows)
      if (row.sc.c.skipEmpty && row.sc.c.preintegrated == pre &&
          std::abs(row.sc.c.step / voxel - steps) <= 1e-9 * steps)
        return &row.r;
    return nullptr;
  };
  std::printf("  pre-integration (skipping on): rebuild on a transfer-function change %.2f ms "
              "(table) %.2f ms (classify; %.2f ms for a colour alone)\n",
              rebuild.table * 1e3, rebuild.classify * 1e3, rebuild.colourClassify * 1e3);
  std::printf("  %-6s %11s %11s %-7s %13s %-7s %9s\n", "step h", "plain RMSE", "preint RMSE",
              "p<=pl", "preint at 2h", "2h<=h", "time p/pl");
  for (const SweepRow& row : rows) {
    const Case& c = row.sc.c;
    if (!c.skipEmpty || c.preintegrated) continue;
    const double h = c.step / voxel;
    const CaseResult* pre = find(h, true);
    if (!pre) continue;
    const CaseResult* pre2h = find(2 * h, true);
    char twice[64] = "-", verdict[8] = "-";
    if (pre2h) {
      std::snprintf(twice, sizeof twice, "%.3e", pre2h->error.rmse);
      std::snprintf(verdict, sizeof verdict, "%s", pre2h->error.rmse <= row.r.error.rmse ? "yes" : "NO");
    }
    std::printf("  %-6.4g %11.3e %11.3e %-7s %13s %-7s %9.2f\n", h, row.r.error.rmse,
                pre->error.rmse, pre->error.rmse <= row.r.error.rmse ? "yes" : "NO", twice, verdict,
                row.r.timing.median > 0 ? pre->timing.median / row.r.timing.median : 0.0);
  }
}

// What a uniform step (plain, skipping on) whose error is `psnr` costs,
// interpolated from the sweep's rows: log time and log samples per frame
// linear in PSNR between the two rows around it; zeros when the sweep does
// not reach that PSNR.
struct UniformCost {
  double seconds = 0, samples = 0;
};
UniformCost uniformCostAt(const std::vector<SweepRow>& rows, double psnr) {
  struct Point {
    double psnr, seconds, samples;
  };
  std::vector<Point> curve;
  for (const SweepRow& row : rows)
    if (row.sc.c.targetPsnr == 0 && !row.sc.c.preintegrated && row.sc.c.skipEmpty && row.r.timing.frames > 0)
      curve.push_back({row.r.error.psnr, row.r.timing.median, double(row.r.timing.samples) / row.r.timing.frames});
  std::sort(curve.begin(), curve.end(), [](const Point& a, const Point& b) { return a.psnr < b.psnr; });
  for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
    const Point& a = curve[i];
    const Point& b = curve[i + 1];
    if (psnr < a.psnr || psnr > b.psnr || !(b.psnr > a.psnr)) continue;
    const double w = (psnr - a.psnr) / (b.psnr - a.psnr);
    auto mix = [w](double x, double y) { return std::exp(std::log(x) + w * (std::log(y) - std::log(x))); };
    return {mix(a.seconds, b.seconds), mix(a.samples, b.samples)};
  }
  return {};
}

// Quality chosen by error: each target at the scene's step, its achieved
// error, time and samples, and what a uniform step of that error costs
// (time and samples, and the target's cost over it: "x" < 1 is cheaper).
void runQuality(const Args& args, const BenchScene& scene, const Reference& ref, std::vector<SweepRow>& rows,
                CsvWriter& csv, core::ThreadPool& pool) {
  std::printf("  quality chosen by error (sampling.target_psnr at step %.3g voxel, plain, skipping on):\n",
              scene.scene().sampling.step / scene.voxel());
  std::printf("  %-9s %9s %-4s %9s %12s %9s %12s %8s %8s %5s\n", "target dB", "PSNR dB", "met", "s/frame",
              "samples", "uniform s", "uniform samp", "time x", "samp x", "load");
  for (double target : args.quality) {
    SweepCase sc{bench::ownCase(scene.scene()), false};  // the scene's step and early termination, plain
    sc.c.preintegrated = false;
    sc.c.targetPsnr = target;
    const CaseResult r = bench::measureCase(scene, sc.c, ref, args.frames, args.caseSeconds, 0, pool);
    const UniformCost uniform = uniformCostAt(rows, r.error.psnr);
    const double samples = r.timing.frames > 0 ? double(r.timing.samples) / r.timing.frames : 0.0;
    char text[4][32] = {"-", "-", "-", "-"};
    if (uniform.seconds > 0) {
      std::snprintf(text[0], sizeof text[0], "%.4f", uniform.seconds);
      std::snprintf(text[1], sizeof text[1], "%.0f", uniform.samples);
      std::snprintf(text[2], sizeof text[2], "%.2f", r.timing.median / uniform.seconds);
      std::snprintf(text[3], sizeof text[3], "%.2f", samples / uniform.samples);
    }
    std::printf("  %-9.4g %9.2f %-4s %9.4f %12.0f %9s %12s %8s %8s %5.2f\n", target, r.error.psnr,
                r.error.psnr >= target ? "yes" : "NO", r.timing.median, samples, text[0], text[1], text[2],
                text[3], r.load1);
    std::fflush(stdout);
    csv.row(scene, sc, r, ref, pool.size());
    rows.push_back({sc, r});
  }
}

int runSweep(const Args& args) {
  core::ThreadPool pool(args.threads);
  fs::create_directories(fs::path(args.csv).parent_path());
  CsvWriter csv(args.csv, args);
  for (const std::string& path : args.scenes) {
    if (auto missing = bench::missingVolume(path)) {
      std::printf("\n%s: skipped, %s\n", path.c_str(), missing->c_str());
      continue;
    }
    const BenchScene scene(path);
    const core::Scene& s = scene.scene();
    std::printf("\n%s: %s, %dx%d, %s, early termination %.6g, %d threads\n", shortName(path).c_str(),
                scene.describe().c_str(), s.image.width, s.image.height,
                s.shading.enabled ? "shaded" : "unshaded", s.sampling.earlyTermination, pool.size());
    std::fflush(stdout);
    const Reference ref = bench::computeReference(scene, args.reference, pool);
    printReference(ref, scene);
    std::printf("  %-6s %-8s %-4s %9s %9s %9s %10s %8s %9s %5s\n", "step", "classify", "skip",
                "s/frame", "Msamp/s", "per core", "RMSE", "PSNR dB", "max abs", "load");
    std::vector<SweepRow> rows;
    for (const SweepCase& sc : sweepCases(args, scene)) {
      const CaseResult r =
          bench::measureCase(scene, sc.c, ref, args.frames, args.caseSeconds, 0, pool);
      const double rate = r.timing.samplesPerSecond() * 1e-6;
      std::printf("  %-6.4g %-8s %-4s %9.4f %9.1f %9.1f %10.3e %8.2f %9.2e %5.2f%s\n",
                  sc.c.step / scene.voxel(), sc.c.preintegrated ? "preint" : "plain",
                  onOff(sc.c.skipEmpty), r.timing.median, rate, rate / pool.size(), r.error.rmse,
                  r.error.psnr, r.error.maxAbs, r.load1, sc.own ? "  <- scene's own settings" : "");
      std::fflush(stdout);
      csv.row(scene, sc, r, ref, pool.size());
      rows.push_back({sc, r});
    }
    if (args.quality.empty()) printPreintegration(rows, bench::rebuildTimes(scene, 9, pool), scene.voxel());
    else runQuality(args, scene, ref, rows, csv, pool);
  }
  std::printf("\nwrote %s\n", args.csv.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  try {
    return args.quick.empty() ? runSweep(args) : runQuick(args);
  } catch (const pvr::Error& e) {
    std::fprintf(stderr, "speed_vs_error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "speed_vs_error: %s\n", e.what());
    return 1;
  }
}
