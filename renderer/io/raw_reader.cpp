#include "raw_reader.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstring>
#include <optional>
#include <thread>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#include "brick_summary.h"
#include "byte_stream.h"
#include "gzip_stream.h"
#include "preprocess.h"
#include "source_util.h"

namespace pvr::core {

namespace {

// Reverses the bytes of each of `count` scalars of `size` bytes (2 or 4).
void swapBytesInPlace(std::byte* data, std::size_t count, std::size_t size) {
  if (size == 2) {
    for (std::size_t i = 0; i < count; ++i) {
      std::uint16_t v;
      std::memcpy(&v, data + 2 * i, 2);
      v = std::uint16_t(v << 8 | v >> 8);
      std::memcpy(data + 2 * i, &v, 2);
    }
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      std::uint32_t v;
      std::memcpy(&v, data + 4 * i, 4);
      v = __builtin_bswap32(v);
      std::memcpy(data + 4 * i, &v, 4);
    }
  }
}

// Reads one byte of every page of [p, p + n): the pages are in memory after.
void touchPages(const std::byte* p, std::size_t n) {
  const std::size_t page = std::size_t(::sysconf(_SC_PAGESIZE));
  unsigned sum = 0;
  for (std::size_t i = 0; i < n; i += page) sum += unsigned(p[i]);
  if (n > 0) sum += unsigned(p[n - 1]);
  // The compiler must not drop the loads.
  asm volatile("" : : "r"(sum));
}

// Faults a lent brick's pages in, in order, on a thread of its own, while
// the reader preprocesses those it has: the reading of a cold file overlaps
// the preprocessing and keeps the disk busy. Not ByteStream::willNeed: the
// kernel's read-ahead for an announced range fills the page cache with
// 4 KiB folios, where the faults of the MADV_HUGEPAGE mapping
// (ByteStream::lend) read 2 MiB folios that map whole, in this read and
// every later one of the file. 8 ranks of the 2048^3 uint8 volume, load
// 4-9: cold 7.8-14 s against 7.5-9.3 s announcing (the file's sequential
// read takes 25 s; 12-15 s with neither), the warm frame after it 2.8-3.5
// s against 3.9-4.5 s after announcing (main's 3.6-4.5 s).
class PagesAhead {
 public:
  PagesAhead(const std::byte* p, std::size_t n)
      : thread_([this, p, n] {
          constexpr std::size_t kStep = std::size_t(2) << 20;
          const std::size_t page = std::size_t(::sysconf(_SC_PAGESIZE));
          const auto base = reinterpret_cast<std::uintptr_t>(p) / page * page;
          const std::size_t end = reinterpret_cast<std::uintptr_t>(p) + n - base;
          for (std::size_t at = 0; at < end && !stop_.load(std::memory_order_relaxed); at += kStep) {
            const std::size_t len = std::min(kStep, end - at);
#ifdef MADV_POPULATE_READ
            if (::madvise(reinterpret_cast<void*>(base + at), len, MADV_POPULATE_READ) == 0) continue;
#endif
            touchPages(reinterpret_cast<const std::byte*>(base + at), len);  // kernels before 5.14
          }
        }) {}
  ~PagesAhead() {
    stop_.store(true, std::memory_order_relaxed);
    thread_.join();
  }
  PagesAhead(const PagesAhead&) = delete;
  PagesAhead& operator=(const PagesAhead&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::unique_ptr<ByteStream> openStream(const RawLayout& layout) {
  if (layout.encoding == RawEncoding::kGzip)
    return std::make_unique<GzipStream>(layout.dataPath, layout.gzipStart);
  return std::make_unique<FileStream>(layout.dataPath);
}

class RawVolumeSource final : public VolumeSource {
 public:
  RawVolumeSource(std::string name, const GridGeometry& grid, ScalarType type, RawLayout layout)
      : name_(std::move(name)), grid_(grid), type_(type), layout_(std::move(layout)) {}

  const GridGeometry& grid() const override { return grid_; }
  ScalarType type() const override { return type_; }
  bool canReadPartially() const override { return layout_.encoding == RawEncoding::kRaw; }
  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    return readRawBox(layout_, grid_, type_, owned, stored, fineCounts_);
  }
  void setFineCounts(bool on) override { fineCounts_ = on; }
  void prefetchBox(const NodeBox& stored) const override {
    if (canReadPartially()) prefetchRawBox(layout_, grid_, type_, stored);
  }
  std::string describe() const override { return name_ + ": " + shapeText(grid_, type_); }

 private:
  std::string name_;
  GridGeometry grid_;
  ScalarType type_;
  RawLayout layout_;
  bool fineCounts_ = true;
};

}  // namespace

std::unique_ptr<VolumeSource> rawVolumeSource(std::string name, const GridGeometry& grid, ScalarType type,
                                              RawLayout layout) {
  return std::make_unique<RawVolumeSource>(std::move(name), grid, type, std::move(layout));
}

std::unique_ptr<VolumeSource> openRawVolume(std::string name, const GridGeometry& grid,
                                            ScalarType type, RawLayout layout, SizeRule rule) {
  const std::string header = layout.headerPath.empty() ? layout.dataPath : layout.headerPath;
  grid.validate(header);
  // Both terms stay below 2^62, so the sum cannot overflow.
  const std::uint64_t data = voxelBytes(grid, type, header);
  if (layout.offset > (std::uint64_t(1) << 62))
    failAt(ErrorCode::kBadFile, header, "data offset " + std::to_string(layout.offset) + " is absurd");
  const std::uint64_t needed = layout.offset + data;

  // Step: compare what the data holds with what the header needs.
  withHeaderNamed(layout, [&] {
    const bool gzip = layout.encoding == RawEncoding::kGzip;
    const std::uint64_t have = gzip ? gzipDecodedSize(layout.dataPath, layout.gzipStart, needed)
                                    : fileSizeOf(layout.dataPath);
    if (have >= needed && (rule == SizeRule::kAtLeast || have == needed)) return;
    std::string what = std::string(gzip ? "gzip data decodes to " : "file has ") +
                       std::to_string(have) + " bytes, header needs " + std::to_string(needed) + " (";
    if (layout.offset > 0) what += std::to_string(layout.offset) + " bytes before the voxels + ";
    failAt(ErrorCode::kBadFile, layout.dataPath, what + shapeText(grid, type) + ")");
  });
  return rawVolumeSource(std::move(name), grid, type, std::move(layout));
}

void prefetchRawBox(const RawLayout& layout, const GridGeometry& grid, ScalarType type, const NodeBox& stored) {
  if (layout.encoding != RawEncoding::kRaw || stored.empty() || !grid.allNodes().contains(stored)) return;
  const std::size_t size = scalarSize(type);
  const IVec3 d = grid.dims;
  auto offsetOf = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return layout.offset + std::uint64_t((z * d.y + y) * d.x + x) * size;
  };
  try {
    FileStream stream(layout.dataPath);
    // One range per slab, from its first row to the end of its last (the
    // gaps share the rows' pages); whole slabs are one range.
    const bool wholeSlabs = stored.extent(0) == d.x && stored.extent(1) == d.y;
    const std::int64_t zEnd = wholeSlabs ? stored.lo.z : stored.hi.z;
    for (std::int64_t z = stored.lo.z; z <= zEnd; ++z) {
      const std::uint64_t first = offsetOf(stored.lo.x, stored.lo.y, z);
      const std::uint64_t end = offsetOf(stored.hi.x, stored.hi.y, wholeSlabs ? stored.hi.z : z) + size;
      stream.willNeed(first, std::size_t(end - first));
    }
  } catch (...) {
    // A hint: the read itself reports what is wrong with the file.
  }
}

Brick readRawBox(const RawLayout& layout, const GridGeometry& grid, ScalarType type,
                 const NodeBox& owned, const NodeBox& stored, bool fineCounts) {
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  checkReadBoxes(layout.dataPath, grid, owned, stored);
  const std::size_t size = scalarSize(type);
  const IVec3 d = grid.dims;
  const IVec3 e = stored.extents();

  // Step: find the longest contiguous run. Whole x rows make a slab one
  // run; whole slabs make several slabs one run, up to kSlabGroupBytes, a
  // size that stays in cache until it is preprocessed.
  constexpr std::size_t kSlabGroupBytes = std::size_t(1) << 20;
  const bool wholeRows = e.x == d.x;
  const bool wholeSlabs = wholeRows && e.y == d.y;
  const std::size_t slabBytes = std::size_t(e.x * e.y) * size;
  const std::int64_t slabsPerGroup =
      wholeSlabs ? std::clamp<std::int64_t>(std::int64_t(kSlabGroupBytes / slabBytes), 1, e.z) : 1;
  const std::int64_t runsY = wholeRows ? 1 : e.y;
  const std::size_t rowRunBytes = std::size_t(e.x * (wholeRows ? e.y : 1)) * size;
  // Short rows cost a call each; below kShortRowBytes one call reads the
  // span from a slab's first row to its last, gaps included, into a
  // buffer of at most one whole-width slab, and the rows are copied out.
  // The gaps share the rows' disk pages anyway.
  constexpr std::size_t kShortRowBytes = std::size_t(16) << 10;
  const bool spans = !wholeRows && rowRunBytes < kShortRowBytes;
  const std::size_t rowPitch = std::size_t(d.x) * size;  // file bytes from one row to the next
  std::vector<std::byte> span(spans ? std::size_t(e.y - 1) * rowPitch + rowRunBytes : 0);

  // Step: read the groups of slabs in file order (a gzip stream only goes
  // forward), bring each to host order and preprocess it while it is in
  // cache: the voxels are touched once.
  const bool swap = size > 1 && layout.bigEndian != (std::endian::native == std::endian::big);
  // A summary of this brick kept from an earlier read of the same file
  // (brick_summary.h) stands for the preprocessing: the slabs are only read.
  BrickSummaryCache summaries(layout, grid, type, owned, stored);
  auto preStart = Clock::now();
  std::optional<Preprocessed> summary = summaries.load();
  const NodeBox counted = countedBox(owned, grid);
  std::optional<SlabPreprocessor> pre;
  // A summary to keep is whole: it counts even when this read need not.
  if (!summary) pre.emplace(type, owned, stored, fineCounts || summaries.enabled() ? &counted : nullptr);
  const double summarySeconds = since(preStart);
  // The file bytes of the group of slabs starting at z0: from its first
  // run to the end of its last.
  auto groupOffset = [&](std::int64_t z0) {
    return layout.offset + std::uint64_t((z0 * d.y + stored.lo.y) * d.x + stored.lo.x) * size;
  };
  auto groupBytes = [&](std::int64_t z0) {
    if (wholeSlabs) return std::size_t(std::min(stored.hi.z, z0 + slabsPerGroup - 1) - z0 + 1) * slabBytes;
    return std::size_t(e.y - 1) * rowPitch + std::size_t(e.x) * size;
  };
  // Groups announced ahead of the one being read (ByteStream::willNeed):
  // enough bytes in flight to keep a disk's queue full.
  constexpr std::size_t kReadAheadBytes = std::size_t(128) << 20;
  const std::int64_t groupsAhead =
      std::max<std::int64_t>(1, std::int64_t(kReadAheadBytes / groupBytes(stored.lo.z)));
  Brick brick;
  withHeaderNamed(layout, [&] {
    std::unique_ptr<ByteStream> stream = openStream(layout);
    // A brick of whole slabs in the file's byte order is one run of the
    // file: it keeps the file's pages (ByteStream::lend) instead of a copy.
    std::shared_ptr<const std::byte> lent;
    if (wholeSlabs && !swap)
      lent = stream->lend(groupOffset(stored.lo.z), std::size_t(e.z) * slabBytes, Brick::kPaddingBytes);
    brick = lent ? Brick::lending(grid, type, owned, stored, lent)
                 : Brick::forOverwrite(grid, type, owned, stored);  // every voxel is read below
    std::byte* voxels = lent ? nullptr : brick.bytes();
    std::optional<PagesAhead> ahead;
    if (lent) ahead.emplace(lent.get(), std::size_t(e.z) * slabBytes);
    std::int64_t announced = stored.lo.z;  // first group not yet announced
    for (std::int64_t z0 = stored.lo.z; z0 <= stored.hi.z; z0 += slabsPerGroup) {
      const std::int64_t z1 = std::min(stored.hi.z, z0 + slabsPerGroup - 1);
      // A lent brick announces nothing (PagesAhead brings it in instead).
      for (; !lent && announced <= stored.hi.z && announced < z0 + groupsAhead * slabsPerGroup; announced += slabsPerGroup)
        stream->willNeed(groupOffset(announced), groupBytes(announced));
      const std::size_t at = std::size_t(z0 - stored.lo.z) * slabBytes;
      const auto readStart = Clock::now();
      if (lent) {
        // Bring the group's pages in (from the disk, or mapped from the
        // cache) as the read, so preprocessing times only its own work.
        touchPages(lent.get() + at, groupBytes(z0));
      } else if (wholeSlabs) {
        const std::uint64_t node = std::uint64_t(z0 * d.y * d.x);
        stream->read(layout.offset + node * size, voxels + at, std::size_t(z1 - z0 + 1) * slabBytes);
      } else if (spans) {
        const std::uint64_t node = std::uint64_t((z0 * d.y + stored.lo.y) * d.x + stored.lo.x);
        stream->read(layout.offset + node * size, span.data(), span.size());
        for (std::int64_t j = 0; j < e.y; ++j)
          std::memcpy(voxels + at + std::size_t(j) * rowRunBytes, span.data() + std::size_t(j) * rowPitch,
                      rowRunBytes);
      } else {
        std::byte* dst = voxels + at;
        for (std::int64_t j = 0; j < runsY; ++j, dst += rowRunBytes) {
          const std::int64_t y = stored.lo.y + j;
          const std::uint64_t node = std::uint64_t((z0 * d.y + y) * d.x + stored.lo.x);
          stream->read(layout.offset + node * size, dst, rowRunBytes);
        }
      }
      brick.loadTimes().read += since(readStart);
      const auto slabStart = Clock::now();
      if (swap) swapBytesInPlace(voxels + at, std::size_t(z1 - z0 + 1) * slabBytes / size, size);
      if (pre) pre->add(lent ? lent.get() + at : voxels + at, z0, z1);
      brick.loadTimes().preprocess += since(slabStart);
    }
  });
  preStart = Clock::now();
  Preprocessed result;
  if (summary) {
    result = std::move(*summary);
  } else {
    result = pre->finish();
    summaries.store(result);
  }
  brick.setPreprocessed(result.range, std::move(result.bounds), std::move(result.histogram));
  brick.loadTimes().preprocess += summarySeconds + since(preStart);
  return brick;
}

}  // namespace pvr::core
