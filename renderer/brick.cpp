#include "brick.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <new>
#include <utility>

#include "error.h"
#include "preprocess.h"

namespace pvr::core {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
// Below this a brick's page faults do not matter.
constexpr std::size_t kHugeStorage = std::size_t(64) << 20;
}  // namespace

namespace {

// Physical memory of this host: no brick larger than that can be held, and
// asking for one would fail late (std::bad_alloc) or push the host into swap.
std::uint64_t physicalMemory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && size > 0 ? std::uint64_t(pages) * std::uint64_t(size) : UINT64_MAX;
}

std::string gibText(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GiB", bytes / double(1ull << 30));
  return text;
}

}  // namespace

std::size_t Brick::checkedStorageBytes(const NodeBox& stored, ScalarType type) {
  // Node counts are at most 2^31 per axis: the product of three fits a long double exactly enough.
  const long double bytes = (long double)stored.extent(0) * (long double)stored.extent(1) *
                            (long double)stored.extent(2) * (long double)scalarSize(type);
  const std::uint64_t memory = physicalMemory();
  if (bytes > (long double)memory)
    throw Error(ErrorCode::kUnsupported, "brick " + toString(stored) + " of " + std::string(scalarName(type)) +
                                             " needs " + gibText(double(bytes)) + "; this host has " +
                                             gibText(double(memory)) + " of memory (use more ranks or hosts)");
  return std::size_t(bytes);
}

void* Brick::allocateStorage(std::size_t bytes) {
  if (bytes < kHugeStorage) return ::operator new(bytes);
  void* p = ::operator new(bytes, std::align_val_t(kHugePage));
  // Only advice: where transparent huge pages are off the brick keeps 4 KiB pages.
  (void)::madvise(p, bytes, MADV_HUGEPAGE);
  return p;
}

void Brick::freeStorage(void* p, std::size_t bytes) noexcept {
  if (bytes < kHugeStorage)
    ::operator delete(p);
  else
    ::operator delete(p, std::align_val_t(kHugePage));
}

Brick::Brick(const GridGeometry& grid, ScalarType type, const NodeBox& owned, const NodeBox& stored, Unwritten)
    : grid_(grid), type_(type), owned_(owned), stored_(stored) {
  if (owned.empty() || !stored.contains(owned) || !grid.allNodes().contains(stored))
    throw Error(ErrorCode::kInvalidArgument,
                "brick: owned box " + toString(owned) + " must lie in stored box " +
                    toString(stored) + " inside the grid " + toString(grid.allNodes()));
  storedBytes_ = checkedStorageBytes(stored, type);
  data_.resize(storedBytes_ + kPaddingBytes);
  std::fill(data_.end() - kPaddingBytes, data_.end(), std::byte{0});
}

Brick Brick::lending(const GridGeometry& grid, ScalarType type, const NodeBox& owned, const NodeBox& stored,
                     std::shared_ptr<const std::byte> voxels) {
  if (owned.empty() || !stored.contains(owned) || !grid.allNodes().contains(stored) || !voxels)
    throw Error(ErrorCode::kInvalidArgument,
                "brick: owned box " + toString(owned) + " must lie in stored box " + toString(stored) +
                    " inside the grid " + toString(grid.allNodes()) + ", with voxels lent");
  Brick brick;
  brick.grid_ = grid;
  brick.type_ = type;
  brick.owned_ = owned;
  brick.stored_ = stored;
  brick.storedBytes_ = checkedStorageBytes(stored, type);
  brick.lent_ = std::move(voxels);
  return brick;
}

void Brick::ownStorage() {
  data_.resize(storedBytes_ + kPaddingBytes);
  std::memcpy(data_.data(), lent_.get(), storedBytes_);
  std::fill(data_.end() - kPaddingBytes, data_.end(), std::byte{0});
  lent_.reset();
}

Brick::Brick(const GridGeometry& grid, ScalarType type, const NodeBox& owned, const NodeBox& stored)
    : Brick(grid, type, owned, stored, Unwritten{}) {
  std::fill(data_.begin(), data_.end(), std::byte{0});
}

Brick Brick::forOverwrite(const GridGeometry& grid, ScalarType type, const NodeBox& owned,
                          const NodeBox& stored) {
  return Brick(grid, type, owned, stored, Unwritten{});
}

double Brick::valueAt(IVec3 node) const {
  const std::size_t i = linearIndex(node);
  return dispatchScalar(type_, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return double(as<T>()[i]);
  });
}

void Brick::updateValueRange(ThreadPool* pool) {
  const auto start = std::chrono::steady_clock::now();
  const NodeBox counted = countedBox(owned_, grid_);
  Preprocessed p = preprocessVoxels(type_, owned_, stored_, std::as_const(*this).bytes(), pool, &counted);
  range_ = p.range;
  bounds_ = std::move(p.bounds);
  histogram_ = std::move(p.histogram);
  loadTimes_.preprocess += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void Brick::countFineHistogram(ThreadPool* pool) {
  if (histogram_) return;
  const NodeBox counted = countedBox(owned_, grid_);
  histogram_ = countFineKeys(type_, stored_, std::as_const(*this).bytes(), counted, pool);
}

void Brick::setPreprocessed(const ValueRange& range, std::shared_ptr<const MacrocellBounds> bounds,
                            std::shared_ptr<const FineHistogram> histogram) {
  if (!bounds || bounds->type() != type_ || !(bounds->layout() == MacrocellLayout::forOwned(owned_)))
    throw Error(ErrorCode::kInternal, "brick " + toString(stored_) +
                                          ": macrocell bounds are not laid out for its owned box " +
                                          toString(owned_) + " and scalar type");
  range_ = range;
  bounds_ = std::move(bounds);
  histogram_ = std::move(histogram);
}

Brick cropBrick(const Brick& source, const NodeBox& owned, int ghostLayers) {
  const NodeBox stored = owned.grown(ghostLayers).intersect(source.grid().allNodes());
  if (!source.stored().contains(stored))
    throw Error(ErrorCode::kInvalidArgument, "cropBrick: " + toString(stored) +
                                                 " is not inside the source brick " +
                                                 toString(source.stored()));
  Brick out = Brick::forOverwrite(source.grid(), source.type(), owned, stored);  // every row is copied below
  const std::size_t size = scalarSize(source.type());
  const std::size_t rowBytes = std::size_t(stored.extent(0)) * size;
  for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
    for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
      std::memcpy(out.bytes() + out.linearIndex({stored.lo.x, y, z}) * size,
                  source.bytes() + source.linearIndex({stored.lo.x, y, z}) * size, rowBytes);
  out.updateValueRange();
  return out;
}

}  // namespace pvr::core
