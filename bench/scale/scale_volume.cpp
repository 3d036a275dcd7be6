// The test volumes of bench/scale: the CT head of ../shared/data,
// trilinearly resampled into an N^3 uint8 cube with air around it, written
// a z-slice at a time so that a 2048^3 volume (8 GiB) needs only the head
// (14 MB) and one slice (4 MiB at 2048) in memory.
//
//   pvr-bench-scale-volume HEAD.json DIR STEM N
//       DIR/STEM.raw + DIR/STEM.json (raw + JSON sidecar)
//   pvr-bench-scale-volume HEAD.json DIR STEM N --series K
//       DIR/STEM/step_0000.{raw,json} ... step_K-1, the head moving along x
//       (one period of a sine over the K steps), and the series sidecar
//       DIR/STEM.series.json {"series": [{"time": T, "file": PATH}, ...]}
//       with PATH relative to DIR.
//
// The cube spans the head's longest side / 0.85 on every axis (isotropic
// spacing, in millimetres like the head), the head centred: its air, the
// headrest and the empty space around it are what empty-space skipping and
// content balancing see. Values: Hounsfield units mapped linearly,
// -1000 -> 0 and 2000 -> 255, clamped (soft tissue near 85, bone above 110).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "error.h"
#include "io/volume_io.h"

namespace {

using namespace pvr;
namespace fs = std::filesystem;

constexpr double kHeadShare = 0.85;  // the head's longest side over the cube's
constexpr double kMinHu = -1000, kMaxHu = 2000;
constexpr double kSeriesShift = 0.12;  // the series' largest x offset, over the cube's side

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "pvr-bench-scale-volume: %s\n", why.c_str());
  std::exit(1);
}

// Where each output index along one axis samples the head: the lower head
// node and the weight of the upper one, or outside (air).
struct AxisMap {
  std::vector<int> lower;
  std::vector<float> weight;
  std::vector<bool> inside;
};

// Output node i sits at i * spacing (the cube from 0 to side); the head's
// node j at offset + j * headSpacing, its centre at the cube's centre plus
// `shift`.
AxisMap mapAxis(int n, double side, int headDims, double headSpacing, double shift) {
  AxisMap m;
  const double spacing = side / (n - 1);
  const double offset = side / 2 + shift - (headDims - 1) * headSpacing / 2;
  for (int i = 0; i < n; ++i) {
    const double u = (i * spacing - offset) / headSpacing;  // in head nodes
    const bool inside = u >= 0 && u <= headDims - 1;
    const int lower = inside ? std::min(int(u), headDims - 2) : 0;
    m.lower.push_back(lower);
    m.weight.push_back(inside ? float(u - lower) : 0.f);
    m.inside.push_back(inside);
  }
  return m;
}

struct Head {
  core::IVec3 dims;
  core::Vec3 spacing;
  std::vector<float> hu;  // x fastest
  std::string describe;
  double side() const {
    return std::max({(dims.x - 1) * spacing.x, (dims.y - 1) * spacing.y, (dims.z - 1) * spacing.z}) / kHeadShare;
  }
};

Head loadHead(const std::string& path) {
  const auto source = core::openVolumeFile(path);
  if (source->type() != core::ScalarType::kInt16) die(path + ": expected the int16 CT head");
  const core::Brick all = source->readAll();
  Head head{source->grid().dims, source->grid().spacing, {}, source->describe()};
  const std::int16_t* v = all.as<std::int16_t>();
  head.hu.assign(v, v + std::size_t(head.dims.x) * head.dims.y * head.dims.z);
  return head;
}

// Writes DIR/STEM.raw a z-slice at a time and DIR/STEM.json with the same
// keys as core::writeRawJsonVolume (which needs the whole volume in memory).
std::string writeVolume(const Head& head, const std::string& dir, const std::string& stem, int n, double shiftX,
                        const std::string& description) {
  fs::create_directories(dir);
  const double side = head.side(), spacing = side / (n - 1);
  const AxisMap mx = mapAxis(n, side, head.dims.x, head.spacing.x, shiftX);
  const AxisMap my = mapAxis(n, side, head.dims.y, head.spacing.y, 0);
  const AxisMap mz = mapAxis(n, side, head.dims.z, head.spacing.z, 0);
  const std::size_t hx = std::size_t(head.dims.x), hxy = hx * std::size_t(head.dims.y);
  const float scale = float(255 / (kMaxHu - kMinHu));

  const std::string raw = (fs::path(dir) / (stem + ".raw")).string();
  std::FILE* out = std::fopen(raw.c_str(), "wb");
  if (!out) die(raw + ": cannot open for writing");
  std::vector<std::uint8_t> slice(std::size_t(n) * n);
  for (int z = 0; z < n; ++z) {
    std::fill(slice.begin(), slice.end(), std::uint8_t(0));
    for (int y = 0; mz.inside[z] && y < n; ++y) {
      if (!my.inside[y]) continue;
      const float wz = mz.weight[z], wy = my.weight[y];
      const float* base = head.hu.data() + std::size_t(mz.lower[z]) * hxy + std::size_t(my.lower[y]) * hx;
      std::uint8_t* row = slice.data() + std::size_t(y) * n;
      for (int x = 0; x < n; ++x) {
        if (!mx.inside[x]) continue;
        // Trilinear: along x on the four rows around the sample, then y, then z.
        const float* p = base + mx.lower[x];
        const float wx = mx.weight[x];
        const auto lerp = [](float a, float b, float w) { return a + (b - a) * w; };
        const float c00 = lerp(p[0], p[1], wx), c01 = lerp(p[hx], p[hx + 1], wx);
        const float c10 = lerp(p[hxy], p[hxy + 1], wx), c11 = lerp(p[hxy + hx], p[hxy + hx + 1], wx);
        const float hu = lerp(lerp(c00, c01, wy), lerp(c10, c11, wy), wz);
        row[x] = std::uint8_t(std::clamp((hu - float(kMinHu)) * scale, 0.f, 255.f) + 0.5f);
      }
    }
    if (std::fwrite(slice.data(), 1, slice.size(), out) != slice.size()) die(raw + ": write failed");
  }
  if (std::fclose(out) != 0) die(raw + ": write failed");

  const nlohmann::json sidecar = {{"dims", {n, n, n}},
                                  {"dtype", "uint8"},
                                  {"spacing", {spacing, spacing, spacing}},
                                  {"origin", {0, 0, 0}},
                                  {"raw_file", stem + ".raw"},
                                  {"endian", "little"},
                                  {"description", description}};
  const std::string json = (fs::path(dir) / (stem + ".json")).string();
  std::ofstream(json) << sidecar.dump(2) << "\n";
  if (!std::ifstream(json)) die(json + ": cannot write");
  return json;
}

std::string describe(const Head& head, int n) {
  char text[512];
  std::snprintf(text, sizeof text,
                "bench/scale test volume: %s trilinearly resampled to %d^3 uint8 (isotropic, the head's longest "
                "side %.0f%% of the cube, centred, air around it); HU %g..%g mapped linearly to 0..255",
                head.describe.c_str(), n, kHeadShare * 100, kMinHu, kMaxHu);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5 && !(argc == 7 && std::string(argv[5]) == "--series"))
    die("usage: pvr-bench-scale-volume HEAD.json DIR STEM N [--series K]");
  try {
    const std::string dir = argv[2], stem = argv[3];
    const int n = std::stoi(argv[4]);
    if (n < 2) die("N must be at least 2");
    const Head head = loadHead(argv[1]);
    if (argc == 5) {
      std::printf("%s\n", writeVolume(head, dir, stem, n, 0, describe(head, n)).c_str());
      return 0;
    }
    // The series: step k shifts the head along x by a sine of k over K.
    const int steps = std::stoi(argv[6]);
    if (steps < 1) die("K must be at least 1");
    nlohmann::json series = nlohmann::json::array();
    for (int k = 0; k < steps; ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "step_%04d", k);
      const double shift = kSeriesShift * head.side() * std::sin(2 * M_PI * k / steps);
      writeVolume(head, (fs::path(dir) / stem).string(), name, n, shift,
                  describe(head, n) + "; series step " + std::to_string(k) + " of " + std::to_string(steps) +
                      ", moved along x");
      series.push_back({{"time", k / 10.0}, {"file", stem + "/" + name + ".json"}});
    }
    const std::string path = (fs::path(dir) / (stem + ".series.json")).string();
    std::ofstream(path) << nlohmann::json{{"series", series}}.dump(1) << "\n";
    std::printf("%s\n", path.c_str());
  } catch (const std::exception& e) {
    die(e.what());
  }
  return 0;
}
