// Persistent brick summaries (io/brick_summary.h): a second read of the
// same brick of the same raw file takes the kept summary, which equals
// preprocessing; a changed, freshly written or damaged file, or a damaged
// summary, is preprocessed again; without PVR_SUMMARY_CACHE nothing is kept.
#include <catch2/catch.hpp>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <vector>

#include "brick.h"
#include "io/brick_summary.h"
#include "io/raw_reader.h"
#include "test_files.h"

namespace pvr::core {
namespace {

namespace fs = std::filesystem;

constexpr ScalarType kTypes[] = {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16,
                                 ScalarType::kFloat32};

// Sets PVR_SUMMARY_CACHE for the scope of a test.
struct SummaryDirectory {
  explicit SummaryDirectory(const std::string& dir) { ::setenv(kSummaryCacheVariable, dir.c_str(), 1); }
  ~SummaryDirectory() { ::unsetenv(kSummaryCacheVariable); }
};

GridGeometry gridOf(IVec3 dims) {
  GridGeometry g;
  g.dims = dims;
  g.spacing = {1, 1, 1};
  return g;
}

const GridGeometry kGrid = gridOf({41, 23, 19});
const NodeBox kOwned{{0, 0, 6}, {40, 22, 12}};
const NodeBox kStored{{0, 0, 5}, {40, 22, 13}};

// Random voxels of `type` (float with a NaN now and then), little-endian.
void writeVolume(const fs::path& path, ScalarType type, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::byte> bytes(std::size_t(kGrid.allNodes().nodeCount()) * scalarSize(type));
  dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    for (std::size_t i = 0; i < bytes.size() / sizeof(T); ++i) {
      T v;
      if constexpr (std::is_floating_point_v<T>) v = i % 37 == 0 ? std::numeric_limits<T>::quiet_NaN() : T(rng() % 1000) - 500;
      else v = T(rng());
      std::memcpy(bytes.data() + i * sizeof(T), &v, sizeof(T));
    }
  });
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  REQUIRE(out.good());
}

// Sets the file's modification time `age` in the past (a summary is kept
// only for files modified at least kRacySeconds ago).
void age(const fs::path& path, std::chrono::seconds age) {
  fs::last_write_time(path, fs::file_time_type::clock::now() - age);
}

// writeVolume into DIR/NAME, modified an hour ago.
fs::path oldVolume(const std::string& dir, const std::string& name, ScalarType type, std::uint32_t seed) {
  const fs::path data = fs::path(dir) / name;
  writeVolume(data, type, seed);
  age(data, std::chrono::hours(1));
  return data;
}

RawLayout layoutOf(const fs::path& path) {
  RawLayout l;
  l.dataPath = path.string();
  return l;
}

Brick readBrick(const fs::path& path, ScalarType type) {
  return readRawBox(layoutOf(path), kGrid, type, kOwned, kStored);
}

std::string summaryPath(const fs::path& path, ScalarType type) {
  return BrickSummaryCache(layoutOf(path), kGrid, type, kOwned, kStored).path();
}

// Range, bounds (bit for bit) and fine counts.
void checkSame(const Brick& a, const Brick& b) {
  CHECK(std::memcmp(&a.valueRange().min, &b.valueRange().min, sizeof(double)) == 0);
  CHECK(std::memcmp(&a.valueRange().max, &b.valueRange().max, sizeof(double)) == 0);
  CHECK(a.valueRange().nonFinite == b.valueRange().nonFinite);
  REQUIRE(a.macrocellBounds());
  REQUIRE(b.macrocellBounds());
  const MacrocellBounds& x = *a.macrocellBounds();
  const MacrocellBounds& y = *b.macrocellBounds();
  REQUIRE(x.byteSize() == y.byteSize());
  CHECK(x.layout() == y.layout());
  CHECK(std::memcmp(x.min<std::byte>(), y.min<std::byte>(), x.byteSize() / 2) == 0);
  CHECK(std::memcmp(x.max<std::byte>(), y.max<std::byte>(), x.byteSize() / 2) == 0);
  REQUIRE(a.fineHistogram());
  REQUIRE(b.fineHistogram());
  CHECK(a.fineHistogram()->counts == b.fineHistogram()->counts);
}

// The offset of the range's min in a summary file of `path`'s brick:
// magic, key length, key, identity (brick_summary.cpp).
std::size_t rangeOffset(const fs::path& summary) {
  const std::string text = test::readText(summary);
  std::uint32_t keyLength = 0;
  std::memcpy(&keyLength, text.data() + 8, 4);
  return 8 + 4 + keyLength + sizeof(FileIdentity);
}

}  // namespace

TEST_CASE("a brick's summary is kept, and a second read takes it, equal to preprocessing", "[preprocess][io]") {
  const std::string dir = test::scratchDir("brick_summary_kept");
  for (ScalarType type : kTypes) {
    CAPTURE(scalarName(type));
    const fs::path data = oldVolume(dir, std::string(scalarName(type)) + ".raw", type, 3);
    const Brick plain = readBrick(data, type);  // PVR_SUMMARY_CACHE unset: nothing kept

    const SummaryDirectory cache(dir + "/summaries");
    const std::string summary = summaryPath(data, type);
    CHECK_FALSE(fs::exists(summary));
    const Brick first = readBrick(data, type);
    REQUIRE(fs::exists(summary));
    const Brick second = readBrick(data, type);
    checkSame(first, plain);
    checkSame(second, plain);

    // The second read's range is the summary's: a range written into it
    // comes back (nothing else could produce 12345).
    std::string bytes = test::readText(summary);
    const double planted = 12345;
    std::memcpy(bytes.data() + rangeOffset(summary), &planted, sizeof planted);
    test::writeText(summary, bytes);
    CHECK(readBrick(data, type).valueRange().min == planted);
  }
}

TEST_CASE("a read told to count nothing still keeps a whole summary, and takes it", "[preprocess][io]") {
  // pvr-node --batch reads without fine counts (VolumeSource::setFineCounts);
  // with summaries on, the read that writes one counts, for the server's
  // histogram later.
  const std::string dir = test::scratchDir("brick_summary_uncounted");
  const ScalarType type = ScalarType::kUInt8;
  const fs::path data = oldVolume(dir, "v.raw", type, 11);
  const Brick counted = readBrick(data, type);
  const SummaryDirectory cache(dir + "/summaries");
  const Brick first = readRawBox(layoutOf(data), kGrid, type, kOwned, kStored, false);
  REQUIRE(fs::exists(summaryPath(data, type)));
  checkSame(first, counted);
  checkSame(readRawBox(layoutOf(data), kGrid, type, kOwned, kStored, false), counted);
}

TEST_CASE("a summary is not used once its file changes, nor kept for a file written just now", "[preprocess][io]") {
  const std::string dir = test::scratchDir("brick_summary_changed");
  const SummaryDirectory cache(dir + "/summaries");
  const ScalarType type = ScalarType::kUInt16;
  const fs::path data = oldVolume(dir, "v.raw", type, 5);
  readBrick(data, type);
  const std::string summary = summaryPath(data, type);
  REQUIRE(fs::exists(summary));

  // Step: one voxel of the brick's owned box becomes 65535, the size stays;
  // the new file is old again by its time (an hour older than before),
  // but its identity changed.
  {
    std::fstream f(data, std::ios::binary | std::ios::in | std::ios::out);
    const std::uint16_t top = 65535;
    const std::int64_t voxel = (9 * kGrid.dims.y + 4) * kGrid.dims.x + 7;
    f.seekp(std::streamoff(voxel * 2));
    f.write(reinterpret_cast<const char*>(&top), 2);
  }
  age(data, std::chrono::hours(2));
  const Brick changed = readBrick(data, type);
  CHECK(changed.valueRange().max == 65535);
  RawLayout l = layoutOf(data);
  ::unsetenv(kSummaryCacheVariable);
  checkSame(changed, readRawBox(l, kGrid, type, kOwned, kStored));
  ::setenv(kSummaryCacheVariable, (dir + "/summaries").c_str(), 1);

  // Step: a file modified just now keeps no summary (racily clean).
  const fs::path fresh = fs::path(dir) / "fresh.raw";
  writeVolume(fresh, type, 6);
  readBrick(fresh, type);
  CHECK_FALSE(fs::exists(summaryPath(fresh, type)));
}

TEST_CASE("a damaged summary is ignored and written again", "[preprocess][io]") {
  const std::string dir = test::scratchDir("brick_summary_damaged");
  const SummaryDirectory cache(dir + "/summaries");
  const ScalarType type = ScalarType::kFloat32;
  const fs::path data = oldVolume(dir, "v.raw", type, 8);
  const Brick first = readBrick(data, type);
  const std::string summary = summaryPath(data, type);
  REQUIRE(fs::exists(summary));

  for (const std::string& damage : {std::string("short"), std::string("magic")}) {
    CAPTURE(damage);
    std::string bytes = test::readText(summary);
    if (damage == "short") bytes.resize(bytes.size() - 1);
    else bytes[0] = 'X';
    test::writeText(summary, bytes);
    checkSame(readBrick(data, type), first);
    CHECK(test::readText(summary).size() > bytes.size() - 2);  // whole again
    CHECK(test::readText(summary)[0] == 'P');
  }
}

}  // namespace pvr::core
