#include "preprocess.h"

#include <algorithm>
#include <type_traits>
#include <mutex>
#include <vector>

#include "error.h"
#include "thread_pool.h"

namespace pvr::core {

namespace {

constexpr int kShift = MacrocellLayout::kShift;
constexpr std::int64_t kSize = MacrocellLayout::kSize;

// A voxel as the min (max) accumulators see it: NaN and Inf become the
// empty value, so they never widen anything. (v - v) is 0 exactly for
// finite v, a test the compiler vectorises.
template <typename T> inline T forMin(T v) {
  if constexpr (std::is_floating_point_v<T>) return (v - v) == T(0) ? v : emptyMin<T>();
  else return v;
}
template <typename T> inline T forMax(T v) {
  if constexpr (std::is_floating_point_v<T>) return (v - v) == T(0) ? v : emptyMax<T>();
  else return v;
}
template <typename T> inline T lesser(T a, T b) { return b < a ? b : a; }
template <typename T> inline T greater(T a, T b) { return a < b ? b : a; }

// The element-wise loops, apart from the accumulator's members: with
// restrict pointers and a local count the compiler vectorises them even
// for uint8, whose stores could otherwise alias anything.
template <typename T>
void startRows(const T* __restrict r, std::size_t n, T* __restrict mn, T* __restrict mx) {
  for (std::size_t i = 0; i < n; ++i) {
    mn[i] = forMin(r[i]);
    mx[i] = forMax(r[i]);
  }
}
template <typename T>
void foldRow(const T* __restrict r, std::size_t n, T* __restrict mn, T* __restrict mx) {
  for (std::size_t i = 0; i < n; ++i) {
    mn[i] = lesser(mn[i], forMin(r[i]));
    mx[i] = greater(mx[i], forMax(r[i]));
  }
}
template <typename T>
void foldBounds(const T* __restrict srcMin, const T* __restrict srcMax, std::size_t n, T* __restrict mn,
                T* __restrict mx) {
  for (std::size_t i = 0; i < n; ++i) {
    mn[i] = lesser(mn[i], srcMin[i]);
    mx[i] = greater(mx[i], srcMax[i]);
  }
}
template <typename T>
std::uint64_t countNonFinite(const T* __restrict r, std::size_t n) {
  std::uint64_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) bad += (r[i] - r[i]) == T(0) ? 0 : 1;
  return bad;
}

// Adds the fine keys of a row's finite values to `counts`. Two tables
// taken in turn keep consecutive values from waiting on each other's
// increment; and an integer row counts a block of kRunBlock equal values
// (air, flat regions: most of a scan) with one addition, where one
// increment after another of the same key would each wait for the last.
template <typename T>
void countRow(const T* __restrict r, std::size_t n, std::uint64_t* __restrict a, std::uint64_t* __restrict b) {
  std::size_t i = 0;
  if constexpr (!std::is_floating_point_v<T>) {
    constexpr std::size_t kRunBlock = 64 / sizeof(T);
    for (; i + kRunBlock <= n; i += kRunBlock) {
      const T first = r[i];
      unsigned differ = 0;  // an OR over the block: vectorised, no branch per voxel
      for (std::size_t k = 1; k < kRunBlock; ++k) differ |= unsigned(r[i + k] != first);
      if (!differ) {
        a[fineKey(first)] += kRunBlock;
        continue;
      }
      for (std::size_t k = 0; k < kRunBlock; k += 2) {
        ++a[fineKey(r[i + k])];
        ++b[fineKey(r[i + k + 1])];
      }
    }
  }
  for (; i + 1 < n; i += 2) {
    if constexpr (std::is_floating_point_v<T>) {
      if ((r[i] - r[i]) == T(0)) ++a[fineKey(r[i])];
      if ((r[i + 1] - r[i + 1]) == T(0)) ++b[fineKey(r[i + 1])];
    } else {
      ++a[fineKey(r[i])];
      ++b[fineKey(r[i + 1])];
    }
  }
  if (i < n && (r[i] - r[i]) == T(0)) ++a[fineKey(r[i])];
}

// Folds slabs into the macrocell layers [layerLo, layerHi) (relative to
// layout.first.z) of `bounds`, and the slabs it is told to count into a
// value range of its own.
template <typename T>
class SlabAccumulator {
 public:
  SlabAccumulator(const NodeBox& stored, MacrocellBounds& bounds, std::int64_t layerLo,
                  std::int64_t layerHi, const NodeBox* counted)
      : st_(stored), l_(bounds.layout()), bounds_(bounds), layerLo_(layerLo), layerHi_(layerHi),
        ex_(std::size_t(stored.extent(0))) {
    if (counted && !counted->empty()) {
      counted_ = *counted;
      const std::size_t keys = std::size_t(1) << (sizeof(T) == 1 ? 8 : 16);  // fineKeyCount
      countsA_.assign(keys, 0);
      countsB_.assign(keys, 0);
    }
    groupMin_.resize(ex_);
    groupMax_.resize(ex_);
    rangeMin_.assign(ex_, emptyMin<T>());
    rangeMax_.assign(ex_, emptyMax<T>());
    slabMin_.resize(std::size_t(l_.count.x * l_.count.y));
    slabMax_.resize(slabMin_.size());
  }

  // Slab z (inside the stored box) starting at `slab`.
  void addSlab(const T* slab, std::int64_t z, bool countRange) {
    // Step: the layers this slab widens; none means it only counts.
    const std::int64_t m1 = (z >> kShift) - l_.first.z;        // node z at its layer's bottom face
    const std::int64_t m0 = ((z - 1) >> kShift) - l_.first.z;   // ... or top face of the one below
    const bool into0 = m0 >= layerLo_ && m0 < layerHi_;
    const bool into1 = m1 != m0 && m1 >= layerLo_ && m1 < layerHi_;
    if (!into0 && !into1 && !countRange) return;
    auto row = [&](std::int64_t y) { return slab + std::size_t(y - st_.lo.y) * ex_; };

    // Step: per macrocell row, reduce its node rows element by element,
    // then along x per macrocell.
    const std::int64_t cx = l_.count.x, firstX = l_.first.x, loX = st_.lo.x, hiX = st_.hi.x;
    for (std::int64_t j = 0; j < l_.count.y; ++j) {
      const std::int64_t my = l_.first.y + j;
      const std::int64_t ya = std::max(st_.lo.y, my * kSize);
      const std::int64_t yb = std::min(st_.hi.y, my * kSize + kSize);
      T* gmin = groupMin_.data();
      T* gmax = groupMax_.data();
      startRows(row(ya), ex_, gmin, gmax);
      for (std::int64_t y = ya + 1; y <= yb; ++y) foldRow(row(y), ex_, gmin, gmax);
      T* smin = slabMin_.data() + j * cx;
      T* smax = slabMax_.data() + j * cx;
      for (std::int64_t i = 0; i < cx; ++i) {
        const std::int64_t mx = firstX + i;
        const std::size_t xa = std::size_t(std::max(loX, mx * kSize) - loX);
        const std::size_t xb = std::size_t(std::min(hiX, mx * kSize + kSize) - loX);
        T lo = gmin[xa], hi = gmax[xa];
        for (std::size_t x = xa + 1; x <= xb; ++x) {
          lo = lesser(lo, gmin[x]);
          hi = greater(hi, gmax[x]);
        }
        smin[i] = lo;
        smax[i] = hi;
      }
      if (countRange) foldBounds(gmin, gmax, ex_, rangeMin_.data(), rangeMax_.data());
    }

    // Step: the range also covers ghost rows outside every macrocell row,
    // and float counts its non-finite voxels, each row once.
    if (countRange) {
      const std::int64_t yLo = l_.first.y * kSize, yHi = (l_.first.y + l_.count.y) * kSize;
      for (std::int64_t y = st_.lo.y; y <= st_.hi.y; ++y) {
        if (y < yLo || y > yHi) foldRow(row(y), ex_, rangeMin_.data(), rangeMax_.data());
        if constexpr (std::is_floating_point_v<T>) nonFinite_ += countNonFinite(row(y), ex_);
      }
    }

    // Step: count the owned voxels' keys, each slab once (countRange).
    if (countRange && !countsA_.empty() && z >= counted_.lo.z && z <= counted_.hi.z)
      for (std::int64_t y = counted_.lo.y; y <= counted_.hi.y; ++y)
        countRow(row(y) + std::size_t(counted_.lo.x - st_.lo.x), std::size_t(counted_.extent(0)), countsA_.data(),
                 countsB_.data());

    // Step: widen the layers.
    if (into0) foldLayer(m0);
    if (into1) foldLayer(m1);
  }

  // The counted slabs' range; min > max if they hold no finite voxel.
  ValueRange range() const {
    T lo = emptyMin<T>(), hi = emptyMax<T>();
    for (std::size_t i = 0; i < ex_; ++i) {
      lo = lesser(lo, rangeMin_[i]);
      hi = greater(hi, rangeMax_[i]);
    }
    return {double(lo), double(hi), nonFinite_};
  }

  // Adds the counted keys to `out` (sized fineKeyCount); nothing without a counted box.
  void addCounts(std::vector<std::uint64_t>& out) const {
    for (std::size_t k = 0; k < countsA_.size(); ++k) out[k] += countsA_[k] + countsB_[k];
  }

 private:
  void foldLayer(std::int64_t layer) {
    const std::size_t n = slabMin_.size();
    foldBounds(slabMin_.data(), slabMax_.data(), n, bounds_.min<T>() + std::size_t(layer) * n,
               bounds_.max<T>() + std::size_t(layer) * n);
  }

  NodeBox st_;
  MacrocellLayout l_;
  MacrocellBounds& bounds_;
  std::int64_t layerLo_, layerHi_;
  std::size_t ex_;
  std::vector<T> groupMin_, groupMax_;  // one macrocell row's node rows, reduced
  std::vector<T> rangeMin_, rangeMax_;  // every counted row, reduced
  std::vector<T> slabMin_, slabMax_;    // this slab's 2-D macrocell bounds
  std::uint64_t nonFinite_ = 0;
  NodeBox counted_;                                  // histogram box, when countsA_ is sized
  std::vector<std::uint64_t> countsA_, countsB_;     // fine key counts, two tables (countRow)
};

ValueRange mergeRanges(const ValueRange& a, const ValueRange& b) {
  return {std::min(a.min, b.min), std::max(a.max, b.max), a.nonFinite + b.nonFinite};
}

// A brick without any finite voxel reports the range [0, 0].
ValueRange finalRange(ValueRange r) {
  if (r.min > r.max) r.min = r.max = 0;
  return r;
}

}  // namespace

// The accumulator behind a SlabPreprocessor, whatever its scalar type.
struct SlabPreprocessor::Impl {
  virtual ~Impl() = default;
  virtual void add(const std::byte* voxels, std::int64_t z0, std::int64_t z1) = 0;
  virtual ValueRange range() const = 0;
  virtual void addCounts(std::vector<std::uint64_t>& out) const = 0;
  std::shared_ptr<MacrocellBounds> bounds;
  std::shared_ptr<FineHistogram> histogram;
};

namespace {

template <typename T>
struct TypedSlabPreprocessor final : SlabPreprocessor::Impl {
  TypedSlabPreprocessor(const NodeBox& stored, std::shared_ptr<MacrocellBounds> b, const NodeBox* counted)
      : acc(stored, *b, 0, b->layout().count.z, counted),
        slabNodes(std::size_t(stored.extent(0) * stored.extent(1))) {
    bounds = std::move(b);
  }
  void add(const std::byte* voxels, std::int64_t z0, std::int64_t z1) override {
    const T* v = reinterpret_cast<const T*>(voxels);
    for (std::int64_t z = z0; z <= z1; ++z, v += slabNodes) acc.addSlab(v, z, true);
  }
  ValueRange range() const override { return finalRange(acc.range()); }
  void addCounts(std::vector<std::uint64_t>& out) const override { acc.addCounts(out); }
  SlabAccumulator<T> acc;
  std::size_t slabNodes;
};

}  // namespace

namespace {

std::shared_ptr<FineHistogram> emptyHistogram(ScalarType type, const NodeBox* counted, const NodeBox& stored) {
  if (!counted) return nullptr;
  if (!counted->empty() && !stored.contains(*counted))
    throw Error(ErrorCode::kInternal, "preprocess: histogram box " + toString(*counted) +
                                          " is not inside the stored box " + toString(stored));
  auto h = std::make_shared<FineHistogram>();
  h->type = type;
  h->counts.assign(fineKeyCount(type), 0);
  return h;
}

}  // namespace

SlabPreprocessor::SlabPreprocessor(ScalarType type, const NodeBox& owned, const NodeBox& stored,
                                   const NodeBox* counted) {
  auto bounds = std::make_shared<MacrocellBounds>(type, MacrocellLayout::forOwned(owned));
  auto histogram = emptyHistogram(type, counted, stored);
  impl_ = dispatchScalar(type, [&](auto tag) -> std::unique_ptr<Impl> {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return std::make_unique<TypedSlabPreprocessor<T>>(stored, std::move(bounds), counted);
  });
  impl_->histogram = std::move(histogram);
}

SlabPreprocessor::~SlabPreprocessor() = default;

void SlabPreprocessor::add(const std::byte* voxels, std::int64_t z0, std::int64_t z1) {
  impl_->add(voxels, z0, z1);
}

Preprocessed SlabPreprocessor::finish() {
  if (impl_->histogram) impl_->addCounts(impl_->histogram->counts);
  return {impl_->range(), std::move(impl_->bounds), std::move(impl_->histogram)};
}

Preprocessed preprocessVoxels(ScalarType type, const NodeBox& owned, const NodeBox& stored,
                              const std::byte* voxels, ThreadPool* pool, const NodeBox* counted) {
  Preprocessed out;
  out.histogram = emptyHistogram(type, counted, stored);
  const MacrocellLayout layout = MacrocellLayout::forOwned(owned);
  out.bounds = std::make_shared<MacrocellBounds>(type, layout);
  const std::int64_t layers = layout.count.z;
  const std::size_t slabNodes = std::size_t(stored.extent(0) * stored.extent(1));

  // Chunks of macrocell layers, a few per thread so uneven chunks balance.
  // A chunk reads the slabs of its layers' node ranges (the one shared with
  // the chunk below is read twice) and counts the slabs from its first
  // layer's bottom face to the next chunk's, the first and last chunk also
  // the ghost slabs outside every layer.
  const int threads = pool ? pool->size() : 1;
  const std::int64_t chunks = std::min<std::int64_t>(layers, threads == 1 ? 1 : 4 * threads);
  auto layerAt = [&](std::int64_t c) { return layers * c / chunks; };
  auto countFrom = [&](std::int64_t c) {
    if (c == 0) return stored.lo.z;
    if (c == chunks) return stored.hi.z + 1;
    return (layout.first.z + layerAt(c)) * kSize;
  };
  std::vector<ValueRange> ranges(static_cast<std::size_t>(chunks));
  std::mutex countsMutex;  // chunks add their key counts to out.histogram one at a time
  auto runChunk = [&](std::size_t c, int) {
    dispatchScalar(type, [&](auto tag) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
      const std::int64_t l0 = layerAt(std::int64_t(c)), l1 = layerAt(std::int64_t(c) + 1);
      SlabAccumulator<T> acc(stored, *out.bounds, l0, l1, counted);
      const std::int64_t cz0 = countFrom(std::int64_t(c)), cz1 = countFrom(std::int64_t(c) + 1) - 1;
      const std::int64_t bz0 = std::max(stored.lo.z, (layout.first.z + l0) * kSize);
      const std::int64_t bz1 = std::min(stored.hi.z, (layout.first.z + l1) * kSize);
      const T* v = reinterpret_cast<const T*>(voxels);
      for (std::int64_t z = std::min(cz0, bz0); z <= std::max(cz1, bz1); ++z)
        acc.addSlab(v + std::size_t(z - stored.lo.z) * slabNodes, z, z >= cz0 && z <= cz1);
      ranges[c] = acc.range();
      if (out.histogram) {
        const std::lock_guard<std::mutex> lock(countsMutex);
        acc.addCounts(out.histogram->counts);
      }
    });
  };
  if (pool && chunks > 1) pool->parallelFor(std::size_t(chunks), runChunk);
  else for (std::size_t c = 0; c < std::size_t(chunks); ++c) runChunk(c, 0);

  ValueRange range = ranges[0];
  for (std::size_t c = 1; c < ranges.size(); ++c) range = mergeRanges(range, ranges[c]);
  out.range = finalRange(range);
  return out;
}

}  // namespace pvr::core
