// Preprocessing speed: value range + macrocell bounds (with the fine
// histogram's counts), classification with the distance field, and content
// counts, per scalar type, on 1 and 2 threads, beside the pre-issue-11
// algorithm (old_preprocess.h) on the same brick, whose results the new
// ones must equal (the distance field as leap_distance.h promises), and
// beside memory speed: a plain min/max over the same bytes, streamed once
// on one thread (the "stream" row). Prints a table and writes
// bench/results/preprocess/preprocess.{csv,txt}.
//
//   pvr-bench-preprocess [--size N] [--file VOLUME]... [--type NAME]... [--threads N]... [--out DIR]
//
// Defaults: a synthetic N = 512 cube per type and the int16 CT head of
// ../shared/data (of a file, the brick rank 0 of 8 would read: the first
// octant plus a ghost layer); every type; threads 1 and 2; DIR =
// bench/results/preprocess of this tree. --type and --threads pick a part
// (for a profile: --type uint16 --threads 1).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "brick.h"
#include "decompose/content.h"
#include "io/volume_io.h"
#include "old_preprocess.h"
#include "preprocess.h"
#include "raycast/leap_distance.h"
#include "raycast/macrocells.h"
#include "thread_pool.h"
#include "transfer.h"
#include "value_histogram.h"

namespace {

using namespace pvr::core;
using pvr::bench::OldMacrocells;
using Clock = std::chrono::steady_clock;

double seconds(const std::function<void()>& f, int repeats) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t).count());
  }
  return best;
}

// A smooth field over the type's range with empty regions (so the distance
// field has work), float with a NaN every 1009 voxels.
Brick syntheticBrick(ScalarType type, std::int64_t n) {
  GridGeometry grid;
  grid.dims = {n, n, n};
  grid.spacing = {1, 1, 1};
  Brick b(grid, type, grid.allNodes(), grid.allNodes());
  dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const double lo = std::is_floating_point_v<T> ? 0.0 : double(std::numeric_limits<T>::lowest());
    const double hi = std::is_floating_point_v<T> ? 1.0 : double(std::numeric_limits<T>::max());
    T* v = b.as<T>();
    std::size_t i = 0;
    for (std::int64_t z = 0; z < n; ++z)
      for (std::int64_t y = 0; y < n; ++y) {
        const double yz = std::sin(0.071 * double(y)) * std::sin(0.033 * double(z));
        for (std::int64_t x = 0; x < n; ++x, ++i) {
          const double f = 0.5 + 0.5 * std::sin(0.05 * double(x)) * yz;
          v[i] = T(lo + f * (hi - lo));
          if constexpr (std::is_floating_point_v<T>)
            if (i % 1009 == 0) v[i] = std::numeric_limits<float>::quiet_NaN();
        }
      }
  });
  return b;
}

// Shows the upper 40% of the brick's value range.
TransferTable upperTable(const ValueRange& r) {
  TransferFunctionSpec tf;
  const double w = r.max - r.min;
  tf.points = {{r.min, 0, 0, 0, 0}, {r.min + 0.6 * w, 0, 0, 0, 0}, {r.min + 0.61 * w, 1, 1, 1, 0.3}, {r.max, 1, 1, 1, 0.6}};
  tf.unitDistance = 1;
  return TransferTable(tf, 0.5);
}

struct Row {
  std::string brick, type, impl;
  int threads = 1;
  std::uint64_t voxels = 0;
  double bounds = 0, histogram = 0, classify = 0, content = 0;
  bool agrees = true;
  double total() const { return bounds + classify + content; }
  double perCore() const { return double(voxels) / total() / threads; }
  double perCoreWithHistogram() const { return double(voxels) / (total() + histogram) / threads; }
};

// The fine histogram by its definition: every finite voxel of the counted
// box, one by one.
std::vector<std::uint64_t> bruteForceCounts(const Brick& b) {
  std::vector<std::uint64_t> counts(fineKeyCount(b.type()), 0);
  const NodeBox c = countedBox(b.owned(), b.grid());
  dispatchScalar(b.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = b.as<T>();
    for (std::int64_t z = c.lo.z; z <= c.hi.z; ++z)
      for (std::int64_t y = c.lo.y; y <= c.hi.y; ++y)
        for (std::int64_t x = c.lo.x; x <= c.hi.x; ++x) {
          const T value = v[b.linearIndex({x, y, z})];
          if (std::isfinite(double(value))) ++counts[fineKey(value)];
        }
  });
  return counts;
}

// Memory speed for this brick: the min and max of its bytes read as
// uint16 (32 per AVX-512 instruction, whatever the scalar type: float
// compares do not vectorise without -ffast-math), one streaming pass on
// one thread; the best of 3.
double streamSeconds(const Brick& b) {
  const std::byte* bytes = b.bytes();
  const std::size_t n = b.byteSize() / 2;
  volatile unsigned sink = 0;
  const double t = seconds([&] {
    std::uint16_t lo = 0xffff, hi = 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t v;
      std::memcpy(&v, bytes + 2 * i, 2);
      lo = v < lo ? v : lo;
      hi = hi < v ? v : hi;
    }
    sink = unsigned(lo) + hi;
  }, 3);
  (void)sink;
  return t;
}

// Old and new on one brick; new on `threadCounts`, and the stream row.
// `b` arrives without bounds.
std::vector<Row> measure(Brick& b, const std::string& name, const std::vector<int>& threadCounts) {
  std::vector<Row> rows;
  const std::uint64_t voxels = std::uint64_t(b.stored().nodeCount());
  const Brick& cb = b;

  Row stream{name, std::string(scalarName(b.type())), "stream", 1, voxels};
  stream.bounds = streamSeconds(cb);
  rows.push_back(stream);

  // The baseline, once (it is slow), and its results for the agreement check.
  Row old{name, std::string(scalarName(b.type())), "old", 1, voxels};
  OldMacrocells om;
  ValueRange oldRange;
  old.bounds = seconds([&] { oldRange = pvr::bench::oldValueRange(cb); om = pvr::bench::oldMacrocellBounds(cb); }, 1);
  const TransferTable table = upperTable(oldRange);
  old.classify = seconds([&] { pvr::bench::oldClassify(om, table); }, 1);
  ContentGrid oldContent;
  old.content = seconds([&] { oldContent = pvr::bench::oldCountContent(cb, table); }, 1);
  rows.push_back(old);

  const std::vector<std::uint64_t> expectedCounts = bruteForceCounts(cb);
  for (int threads : threadCounts) {
    ThreadPool pool(threads);
    ThreadPool* p = threads > 1 ? &pool : nullptr;
    Row r{name, old.type, "new", threads, voxels};
    // Bounds as a load runs them (the raw reader without fine counts: the
    // server counts the histogram later, when a Status asks; runtime.md),
    // and that count (Brick::countFineHistogram).
    Preprocessed boundsOnly;
    r.bounds = seconds([&] { boundsOnly = preprocessVoxels(b.type(), b.owned(), b.stored(), cb.bytes(), p); }, 3);
    const NodeBox counted = countedBox(b.owned(), b.grid());
    std::shared_ptr<FineHistogram> counts;
    r.histogram = seconds([&] { counts = countFineKeys(b.type(), b.stored(), cb.bytes(), counted, p); }, 3);
    b.updateValueRange(p);  // the brick's bounds and counts in one pass, for the checks below
    MacrocellGrid grid(cb);
    r.classify = seconds([&] { grid.classify(table, true, p); }, 3);
    ContentGrid content;
    r.content = seconds([&] { content = countContent(cb, table, {8, 8, 8}, p); }, 3);

    // The same results as the baseline.
    const ValueRange& nr = cb.valueRange();
    r.agrees = nr.min == oldRange.min && nr.max == oldRange.max && nr.nonFinite == oldRange.nonFinite &&
               content.counts == oldContent.counts &&
               std::equal(om.distance.begin(), om.distance.end(), grid.distance(),
                          [](std::uint8_t exact, std::uint8_t leap) { return leapDistanceFits(leap, exact); });
    const MacrocellBounds& nb = grid.bounds();
    r.agrees = r.agrees && counts->counts == expectedCounts && cb.fineHistogram() &&
               cb.fineHistogram()->counts == expectedCounts;
    for (std::size_t i = 0; i < om.min.size() && r.agrees; ++i) {
      r.agrees = boundsOnly.bounds->minAt(i) == nb.minAt(i) && boundsOnly.bounds->maxAt(i) == nb.maxAt(i);
      if (!r.agrees) break;
      const bool oldEmpty = om.min[i] > om.max[i], newEmpty = nb.minAt(i) > nb.maxAt(i);
      r.agrees = oldEmpty == newEmpty && (oldEmpty || (nb.minAt(i) == om.min[i] && nb.maxAt(i) == om.max[i]));
    }
    rows.push_back(r);
  }
  return rows;
}

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

}  // namespace

int main(int argc, char** argv) {
  std::int64_t size = 512;
  std::vector<std::string> files;
  std::vector<ScalarType> types;
  std::vector<int> threadCounts;
  std::string out = std::string(PVR_SOURCE_DIR) + "/bench/results/preprocess";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--size" && i + 1 < argc) size = std::stoll(argv[++i]);
    else if (a == "--file" && i + 1 < argc) files.push_back(argv[++i]);
    else if (a == "--type" && i + 1 < argc) types.push_back(parseScalarType(argv[++i], "--type"));
    else if (a == "--threads" && i + 1 < argc) threadCounts.push_back(std::max(1, std::stoi(argv[++i])));
    else if (a == "--out" && i + 1 < argc) out = argv[++i];
    else {
      std::cerr << "usage: pvr-bench-preprocess [--size N] [--file VOLUME]... [--type uint8|uint16|int16|float32]...\n"
                   "                            [--threads N]... [--out DIR]\n";
      return a == "--help" ? 0 : 2;
    }
  }
  if (types.empty()) types = {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16, ScalarType::kFloat32};
  if (threadCounts.empty()) threadCounts = {1, 2};
  if (files.empty()) files.push_back(std::string(PVR_SOURCE_DIR) + "/../shared/data/ct_head_cranium/ct_head_cranium.json");

  std::ostringstream text;
  const std::string loadBefore = loadAverage();
  std::vector<Row> rows;
  for (ScalarType type : types) {
    Brick b = syntheticBrick(type, size);
    const std::string name = "synthetic " + std::to_string(size) + "^3";
    for (const Row& r : measure(b, name, threadCounts)) rows.push_back(r);
  }
  for (const std::string& path : files) {
    // The brick rank 0 of 8 reads: the first octant and one ghost layer.
    const auto source = openVolumeFile(path);
    const IVec3 d = source->grid().dims;
    const NodeBox owned{{0, 0, 0}, {d.x / 2, d.y / 2, d.z / 2}};
    Brick b = source->readBox(owned, owned.grown(1).intersect(source->grid().allNodes()));
    text << "fused read of " << toString(b.stored()) << " from " << source->describe() << ": "
         << b.loadTimes().read << " s in I/O calls, "
         << b.loadTimes().preprocess << " s preprocessing ("
         << double(b.stored().nodeCount()) / std::max(b.loadTimes().preprocess, 1e-9) / 1e9
         << " G voxels/s, page cache warm or cold as it happened)\n";
    b.bytes();  // drop the reader's bounds so that the new pass computes them again
    if (std::find(types.begin(), types.end(), b.type()) == types.end()) continue;
    for (const Row& r : measure(b, std::filesystem::path(path).stem().string() + " octant", threadCounts))
      rows.push_back(r);
  }

  // Step: the table, the CSV and the text file.
  text << "bounds = value range + macrocell min/max, as a load runs them; hist = the fine histogram's\n"
          "counts alone (one table increment per voxel; a server counts them when a Status first asks,\n"
          "not for a frame: countFineKeys);\n"
          "classify = visibility + distance field;\n"
          "content = content counts in 8^3 blocks; total = bounds + classify + content;\n"
          "Mvox/s/core = voxels / total / threads; +hist = voxels / (total + hist) / threads;\n"
          "best of 3 runs for new, 1 for old (single-threaded: it has no threads); agrees = new\n"
          "range, bounds and counts equal old's, the fine histogram (alone and from the pass with the bounds)\n"
          "a count of every voxel, and the distances are its exact ones as the leap\n"
          "distance promises (exact below 16 macrocells, a close lower bound beyond; leap_distance.h).\n"
          "stream = memory speed: the min and max of the brick's bytes read as uint16, one streaming pass\n"
          "on one thread (its time in the bounds column; best of 3).\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-22s %-8s %-6s %3s %9s %9s %10s %9s %9s %12s %11s %7s\n", "brick", "type",
                "impl", "thr", "bounds s", "hist s", "classify s", "content s", "total s", "Mvox/s/core", "+hist", "agrees");
  text << line;
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "%-22s %-8s %-6s %3d %9.4f %9.4f %10.4f %9.4f %9.4f %12.0f %11.0f %7s\n",
                  r.brick.c_str(), r.type.c_str(), r.impl.c_str(), r.threads, r.bounds, r.histogram, r.classify,
                  r.content, r.total(), r.perCore() / 1e6, r.perCoreWithHistogram() / 1e6,
                  r.impl != "new" ? "-" : (r.agrees ? "yes" : "NO"));
    text << line;
  }
  text << "load average (1, 5, 15 min) before: " << loadBefore << ", after: " << loadAverage()
       << " on " << std::thread::hardware_concurrency() << " hardware threads; a load above ~1 means"
       << " other work shared the cores and the figures are low.\n";
  std::cout << text.str();

  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/preprocess.csv");
  csv << "brick,type,impl,threads,voxels,bounds_s,histogram_s,classify_s,content_s,total_s,voxels_per_s_per_core,"
         "with_histogram_per_core,agrees\n";
  for (const Row& r : rows)
    csv << r.brick << "," << r.type << "," << r.impl << "," << r.threads << "," << r.voxels << "," << r.bounds
        << "," << r.histogram << "," << r.classify << "," << r.content << "," << r.total() << "," << r.perCore()
        << "," << r.perCoreWithHistogram() << "," << (r.impl != "new" ? "" : (r.agrees ? "yes" : "no")) << "\n";
  std::ofstream(out + "/preprocess.txt") << text.str();
  bool ok = true;
  for (const Row& r : rows) ok &= r.agrees;
  return ok ? 0 : 1;
}
