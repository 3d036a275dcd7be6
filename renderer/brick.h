// Brick: a box of the global grid's nodes held in memory, with ghost layers.
//
// `owned` is the box this brick renders (its cells lie between owned.lo and
// owned.hi); `stored` is owned plus the ghost layers that trilinear
// reconstruction and central differences need, clipped to the grid. A whole
// volume is the brick whose owned and stored boxes are the whole grid.
// Scalars keep their file type: a uint8 volume costs one byte per voxel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "grid.h"
#include "macrocell_bounds.h"
#include "value_histogram.h"

namespace pvr::core {

class ThreadPool;

// Seconds spent filling a brick: `read` in I/O calls (readers set it),
// `preprocess` computing its value range and macrocell bounds (the fused
// pass of a reader, or updateValueRange()). A brick that carries no bounds
// gets them from the MacrocellGrid its BrickRenderer builds; that time is
// BrickRenderer::preprocessSeconds(), not part of these.
struct LoadTimes {
  double read = 0;
  double preprocess = 0;
};

// The finite values of a brick. Non-finite voxels (NaN, Inf) are counted, not
// ranged: they classify as empty wherever they are sampled.
struct ValueRange {
  double min = 0;
  double max = 0;
  std::uint64_t nonFinite = 0;
};

class Brick {
 public:
  Brick() = default;
  // Zero-filled storage for `stored`; throws if stored does not contain owned
  // or lies outside the grid.
  Brick(const GridGeometry& grid, ScalarType type, const NodeBox& owned, const NodeBox& stored);
  // The same with the voxels left unwritten (the padding is zero), for
  // readers that write every voxel: zero-filling first would touch every
  // page of a gigabyte brick once more.
  static Brick forOverwrite(const GridGeometry& grid, ScalarType type, const NodeBox& owned,
                            const NodeBox& stored);
  // A brick over voxels it does not own: `voxels` holds the stored box's
  // voxels in storage order followed by kPaddingBytes readable bytes (a
  // file's pages, io/byte_stream.h lend), kept alive by the pointer. Read
  // in place; the first writable access copies them into storage of the
  // brick's own.
  static Brick lending(const GridGeometry& grid, ScalarType type, const NodeBox& owned, const NodeBox& stored,
                       std::shared_ptr<const std::byte> voxels);

  const GridGeometry& grid() const { return grid_; }
  ScalarType type() const { return type_; }
  const NodeBox& owned() const { return owned_; }
  const NodeBox& stored() const { return stored_; }

  // Writable access drops the macrocell bounds (the voxels may no longer
  // match them); updateValueRange() computes them again.
  std::byte* bytes() {
    bounds_.reset();
    histogram_.reset();
    if (lent_) ownStorage();
    return data_.data();
  }
  const std::byte* bytes() const { return lent_ ? lent_.get() : data_.data(); }
  std::size_t byteSize() const { return storedBytes_; }
  // The voxels are a file's pages, not storage of the brick's own (lending).
  bool lent() const { return bool(lent_); }
  // Storage ends with this many zero bytes, so the vector kernel may load a
  // 32-bit word at the last voxel of any scalar type.
  static constexpr std::size_t kPaddingBytes = 8;
  template <typename T> T* as() { return reinterpret_cast<T*>(bytes()); }
  template <typename T> const T* as() const { return reinterpret_cast<const T*>(bytes()); }

  // Linear index into storage of a global node inside `stored`.
  std::size_t linearIndex(IVec3 node) const {
    const IVec3 e = stored_.extents();
    return std::size_t(((node.z - stored_.lo.z) * e.y + (node.y - stored_.lo.y)) * e.x +
                       (node.x - stored_.lo.x));
  }
  // One voxel as double; for tests, references and set-up, not for hot loops.
  double valueAt(IVec3 node) const;

  // Recomputes the finite value range, the macrocell bounds and the fine
  // histogram of the counted box (countedBox) from storage in one pass
  // (preprocess.h), over `pool`'s threads when one is given,
  // the same result either way. Loaders call it after filling storage; its
  // seconds add to loadTimes().preprocess.
  void updateValueRange(ThreadPool* pool = nullptr);
  const ValueRange& valueRange() const { return range_; }
  // For readers that preprocessed the voxels as they landed. Throws if the
  // bounds are not laid out for this brick's owned box and scalar type.
  void setPreprocessed(const ValueRange& range, std::shared_ptr<const MacrocellBounds> bounds,
                       std::shared_ptr<const FineHistogram> histogram = nullptr);
  // Fine counts of the voxels this brick counts (countedBox(owned, grid)),
  // or null when storage was written since, or a reader gave none.
  const std::shared_ptr<const FineHistogram>& fineHistogram() const { return histogram_; }
  // Counts them now if no reader did (a reader told to count nothing: the
  // server counts when the histogram is first asked for, not before the
  // first frame). Leaves range and bounds as they are.
  void countFineHistogram(ThreadPool* pool = nullptr);
  // The macrocell bounds of the owned box, or null when storage was written
  // since they were computed (or they never were). Shared, never copied:
  // the renderer's MacrocellGrid holds the same object.
  const std::shared_ptr<const MacrocellBounds>& macrocellBounds() const { return bounds_; }

  LoadTimes& loadTimes() { return loadTimes_; }
  const LoadTimes& loadTimes() const { return loadTimes_; }

 private:
  // Storage of large bricks comes in transparent huge pages where the
  // kernel offers them: a gigabyte brick then costs 512 page faults while
  // it is read instead of 262144 (brick.cpp).
  static void* allocateStorage(std::size_t bytes);
  // The bytes of a stored box's voxels; throws pvr::Error(kUnsupported)
  // when they exceed this host's physical memory, before anything is allocated.
  static std::size_t checkedStorageBytes(const NodeBox& stored, ScalarType type);
  static void freeStorage(void* p, std::size_t bytes) noexcept;
  // std::allocator, except that resize() leaves new bytes unwritten and
  // the storage comes from allocateStorage.
  template <typename T>
  struct UnwrittenAllocator : std::allocator<T> {
    template <typename U> struct rebind { using other = UnwrittenAllocator<U>; };
    using std::allocator<T>::allocator;
    T* allocate(std::size_t n) { return static_cast<T*>(allocateStorage(n * sizeof(T))); }
    void deallocate(T* p, std::size_t n) noexcept { freeStorage(p, n * sizeof(T)); }
    template <typename U> void construct(U* p) noexcept { ::new (static_cast<void*>(p)) U; }
    template <typename U, typename... A> void construct(U* p, A&&... args) {
      ::new (static_cast<void*>(p)) U(std::forward<A>(args)...);
    }
  };
  struct Unwritten {};
  Brick(const GridGeometry& grid, ScalarType type, const NodeBox& owned, const NodeBox& stored, Unwritten);
  // Copies lent voxels into storage of the brick's own.
  void ownStorage();

  GridGeometry grid_;
  ScalarType type_ = ScalarType::kUInt8;
  NodeBox owned_;
  NodeBox stored_;
  std::vector<std::byte, UnwrittenAllocator<std::byte>> data_;  // empty while lent_
  std::shared_ptr<const std::byte> lent_;                         // voxels lent by a file, or null
  std::size_t storedBytes_ = 0;                                   // the stored box's voxel bytes
  ValueRange range_;
  std::shared_ptr<const MacrocellBounds> bounds_;
  std::shared_ptr<const FineHistogram> histogram_;
  LoadTimes loadTimes_;
};

// The part of `source` that a brick owning `owned` with `ghostLayers` layers
// around it stores (clipped to the grid). `source` must store all of it.
Brick cropBrick(const Brick& source, const NodeBox& owned, int ghostLayers);

// Calls f(static_cast<const T*>(nullptr)) with T the brick's C++ scalar type:
// the one place a scalar type turns into a template argument.
template <typename F>
decltype(auto) dispatchScalar(ScalarType type, F&& f) {
  switch (type) {
    case ScalarType::kUInt8: return f(static_cast<const std::uint8_t*>(nullptr));
    case ScalarType::kUInt16: return f(static_cast<const std::uint16_t*>(nullptr));
    case ScalarType::kInt16: return f(static_cast<const std::int16_t*>(nullptr));
    case ScalarType::kFloat32: break;
  }
  return f(static_cast<const float*>(nullptr));
}

}  // namespace pvr::core
