#include "brick_summary.h"

#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace pvr::core {

namespace {

constexpr char kMagic[8] = {'P', 'V', 'R', 'S', 'U', 'M', '0', '1'};

std::optional<FileIdentity> identityOf(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  FileIdentity id;
  id.device = std::uint64_t(st.st_dev);
  id.inode = std::uint64_t(st.st_ino);
  id.size = std::uint64_t(st.st_size);
  id.modifiedNs = std::int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  id.changedNs = std::int64_t(st.st_ctim.tv_sec) * 1000000000 + st.st_ctim.tv_nsec;
  return id;
}

// FNV-1a, 64 bits: names a summary file after its key.
std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string boxText(const NodeBox& b) {
  return std::to_string(b.lo.x) + "," + std::to_string(b.lo.y) + "," + std::to_string(b.lo.z) + ":" +
         std::to_string(b.hi.x) + "," + std::to_string(b.hi.y) + "," + std::to_string(b.hi.z);
}

// Writes the bytes of trivially copyable values straight to the file, and
// reads them back in order: a summary's bounds (1/32 of an 8-bit brick's
// bytes) never sit in memory twice (issue 11's bound on a rank's memory).
struct Writer {
  std::ofstream& out;
  void bytes(const void* p, std::size_t n) { out.write(static_cast<const char*>(p), std::streamsize(n)); }
  template <typename V> void value(const V& v) { bytes(&v, sizeof v); }
};
struct Reader {
  std::ifstream& in;
  bool bytes(void* p, std::size_t n) { return bool(in.read(static_cast<char*>(p), std::streamsize(n))); }
  template <typename V> bool value(V& v) { return bytes(&v, sizeof v); }
};

}  // namespace

BrickSummaryCache::BrickSummaryCache(const RawLayout& layout, const GridGeometry& grid, ScalarType type,
                                     const NodeBox& owned, const NodeBox& stored)
    : dataPath_(layout.dataPath), type_(type), owned_(owned) {
  const char* dir = std::getenv(kSummaryCacheVariable);
  if (!dir || !*dir || layout.encoding != RawEncoding::kRaw) return;
  std::error_code ec;
  const std::filesystem::path data = std::filesystem::absolute(layout.dataPath, ec).lexically_normal();
  if (ec) return;
  key_ = "file=" + data.string() + ";offset=" + std::to_string(layout.offset) +
         ";big_endian=" + std::to_string(int(layout.bigEndian)) +
         ";host_little=" + std::to_string(int(std::endian::native == std::endian::little)) +
         ";type=" + std::string(scalarName(type)) + ";dims=" + std::to_string(grid.dims.x) + "," +
         std::to_string(grid.dims.y) + "," + std::to_string(grid.dims.z) + ";owned=" + boxText(owned) +
         ";stored=" + boxText(stored) + ";macrocell=" + std::to_string(MacrocellLayout::kSize) + ";";
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.pvrsum", static_cast<unsigned long long>(fnv1a(key_)));
  path_ = (std::filesystem::path(dir) / name).string();
}

std::optional<Preprocessed> BrickSummaryCache::load() {
  if (!enabled()) return std::nullopt;
  seen_ = identityOf(dataPath_);
  if (!seen_) return std::nullopt;

  // Step: the whole file, if its size is what this brick's summary takes.
  const MacrocellLayout layout = MacrocellLayout::forOwned(owned_);
  const std::size_t boundsBytes = 2 * layout.size() * scalarSize(type_);
  const std::size_t keys = fineKeyCount(type_);
  const std::size_t expected = sizeof kMagic + sizeof(std::uint32_t) + key_.size() + sizeof(FileIdentity) +
                               2 * sizeof(double) + sizeof(std::uint64_t) + boundsBytes + keys * sizeof(std::uint64_t);
  std::error_code ec;
  if (std::filesystem::file_size(path_, ec) != expected || ec) return std::nullopt;
  std::ifstream in(path_, std::ios::binary);
  if (!in) return std::nullopt;

  // Step: magic, key and identity must match; then the payload.
  Reader r{in};
  char magic[sizeof kMagic];
  std::uint32_t keyLength = 0;
  if (!r.bytes(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0) return std::nullopt;
  if (!r.value(keyLength) || keyLength != key_.size()) return std::nullopt;
  std::string key(keyLength, '\0');
  FileIdentity id;
  if (!r.bytes(key.data(), keyLength) || key != key_ || !r.value(id) || !(id == *seen_)) return std::nullopt;
  Preprocessed p;
  if (!r.value(p.range.min) || !r.value(p.range.max) || !r.value(p.range.nonFinite)) return std::nullopt;
  auto bounds = std::make_shared<MacrocellBounds>(type_, layout);
  const std::size_t half = boundsBytes / 2;
  if (!r.bytes(bounds->min<std::byte>(), half) || !r.bytes(bounds->max<std::byte>(), half)) return std::nullopt;
  auto histogram = std::make_shared<FineHistogram>();
  histogram->type = type_;
  histogram->counts.resize(keys);
  if (!r.bytes(histogram->counts.data(), keys * sizeof(std::uint64_t))) return std::nullopt;
  p.bounds = std::move(bounds);
  p.histogram = std::move(histogram);
  return p;
}

void BrickSummaryCache::store(const Preprocessed& p) const {
  if (!enabled() || !seen_ || !p.bounds || !p.histogram) return;
  // Step: only a file unchanged since load() and not modified lately.
  const std::optional<FileIdentity> now = identityOf(dataPath_);
  if (!now || !(*now == *seen_)) return;
  const auto wall = std::chrono::system_clock::now().time_since_epoch();
  const double age = double(std::chrono::duration_cast<std::chrono::nanoseconds>(wall).count() - now->modifiedNs) / 1e9;
  if (age < kRacySeconds) return;

  // Step: written beside, then renamed over: a reader sees a whole summary or none.
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path_).parent_path(), ec);
  const std::string temporary = path_ + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    Writer w{out};
    w.bytes(kMagic, sizeof kMagic);
    w.value(std::uint32_t(key_.size()));
    w.bytes(key_.data(), key_.size());
    w.value(*now);
    w.value(p.range.min);
    w.value(p.range.max);
    w.value(p.range.nonFinite);
    const std::size_t half = p.bounds->byteSize() / 2;
    w.bytes(p.bounds->min<std::byte>(), half);
    w.bytes(p.bounds->max<std::byte>(), half);
    w.bytes(p.histogram->counts.data(), p.histogram->counts.size() * sizeof(std::uint64_t));
    out.close();  // a failed write or close leaves the stream failed
    if (!out) {
      std::filesystem::remove(temporary, ec);
      return;
    }
  }
  std::filesystem::rename(temporary, path_, ec);
  if (ec) std::filesystem::remove(temporary, ec);
}

}  // namespace pvr::core
