#include "preprocess.h"

#include <algorithm>
#include <mutex>
#include <optional>
#include <type_traits>
#include <vector>

#include "error.h"
#include "fine_counts.h"
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
// The kSize + 1 rows of a macrocell row reduced in one pass: each element
// is loaded once and stored once, where a fold row by row would load and
// store the accumulators kSize times.
template <typename T>
void reduceRows5(const T* __restrict r0, const T* __restrict r1, const T* __restrict r2, const T* __restrict r3,
                 const T* __restrict r4, std::size_t n, T* __restrict mn, T* __restrict mx) {
  static_assert(kSize == 4, "reduceRows5 reduces kSize + 1 rows");
  for (std::size_t i = 0; i < n; ++i) {
    mn[i] = lesser(lesser(lesser(forMin(r0[i]), forMin(r1[i])), lesser(forMin(r2[i]), forMin(r3[i]))), forMin(r4[i]));
    mx[i] = greater(greater(greater(forMax(r0[i]), forMax(r1[i])), greater(forMax(r2[i]), forMax(r3[i]))),
                    forMax(r4[i]));
  }
}
// Sliding bounds of kSize + 1 neighbours along x: w[x] covers [x, x + kSize],
// for x < n - kSize. Vectorised (shifted loads), where a loop per
// macrocell over its five elements is not.
template <typename T>
void windowBounds(const T* __restrict gmin, const T* __restrict gmax, std::size_t n, T* __restrict wmin,
                  T* __restrict wmax) {
  for (std::size_t x = 0; x + kSize < n; ++x) {
    wmin[x] = lesser(lesser(lesser(gmin[x], gmin[x + 1]), lesser(gmin[x + 2], gmin[x + 3])), gmin[x + 4]);
    wmax[x] = greater(greater(greater(gmax[x], gmax[x + 1]), greater(gmax[x + 2], gmax[x + 3])), gmax[x + 4]);
  }
}
// out[i] = w[kSize * i], i < n: the windows that start on the macrocell lattice.
template <typename T>
void pickLattice(const T* __restrict wmin, const T* __restrict wmax, std::size_t n, T* __restrict omin,
                 T* __restrict omax) {
  for (std::size_t i = 0; i < n; ++i) {
    omin[i] = wmin[std::size_t(kSize) * i];
    omax[i] = wmax[std::size_t(kSize) * i];
  }
}
// Asks the cache for [p, p + n) ahead of its loads.
inline void prefetchBytes(const void* p, std::size_t n) {
  const char* c = static_cast<const char*>(p);
  for (std::size_t i = 0; i < n; i += 64) __builtin_prefetch(c + i, 0, 3);
}

template <typename T>
std::uint64_t countNonFinite(const T* __restrict r, std::size_t n) {
  std::uint64_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) bad += (r[i] - r[i]) == T(0) ? 0 : 1;
  return bad;
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
      counts_.emplace();
    }
    groupMin_.resize(ex_);
    groupMax_.resize(ex_);
    windowMin_.resize(ex_);
    windowMax_.resize(ex_);
    rangeMin_.assign(std::size_t(l_.count.x), emptyMin<T>());
    rangeMax_.assign(std::size_t(l_.count.x), emptyMax<T>());
    // Step: the macrocells along x whose node range lies whole in the
    // stored row [whole0_, whole1_), the first one's node, and the nodes
    // some macrocell covers.
    const std::int64_t firstX = l_.first.x, cx = l_.count.x;
    whole0_ = 0;
    while (whole0_ < cx && (firstX + whole0_) * kSize < st_.lo.x) ++whole0_;
    whole1_ = cx;
    while (whole1_ > whole0_ && (firstX + whole1_ - 1) * kSize + kSize > st_.hi.x) --whole1_;
    wholeAt_ = std::size_t(std::max<std::int64_t>(0, (firstX + whole0_) * kSize - st_.lo.x));
    coveredLo_ = std::size_t(std::max(st_.lo.x, firstX * kSize) - st_.lo.x);
    coveredHi_ = std::size_t(std::min(st_.hi.x, (firstX + cx) * kSize) - st_.lo.x);
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
    // then along x: sliding windows picked on the lattice for the
    // macrocells of whole node ranges, one by one for the (at most two)
    // clipped at the stored box's x ends.
    const std::int64_t cx = l_.count.x;
    for (std::int64_t j = 0; j < l_.count.y; ++j) {
      const std::int64_t my = l_.first.y + j;
      const std::int64_t ya = std::max(st_.lo.y, my * kSize);
      const std::int64_t yb = std::min(st_.hi.y, my * kSize + kSize);
      // The next macrocell row's new node rows, asked for now: each row is
      // a short stream (2 KiB of a 2048-wide uint8 slab) that the hardware
      // prefetcher has no time to learn, and waiting for their first loads
      // was most of this pass (perf annotate). Rows are contiguous in a
      // slab; a prefetch past the brick's mapping is harmless.
      if (yb < st_.hi.y) prefetchBytes(row(yb + 1), std::size_t(std::min<std::int64_t>(kSize, st_.hi.y - yb)) * ex_ * sizeof(T));
      T* gmin = groupMin_.data();
      T* gmax = groupMax_.data();
      if (yb - ya == kSize) {
        reduceRows5(row(ya), row(ya + 1), row(ya + 2), row(ya + 3), row(ya + 4), ex_, gmin, gmax);
      } else {
        startRows(row(ya), ex_, gmin, gmax);
        for (std::int64_t y = ya + 1; y <= yb; ++y) foldRow(row(y), ex_, gmin, gmax);
      }
      T* smin = slabMin_.data() + j * cx;
      T* smax = slabMax_.data() + j * cx;
      if (whole1_ > whole0_) {
        const std::size_t n = std::size_t(whole1_ - whole0_);
        windowBounds(gmin + wholeAt_, gmax + wholeAt_, std::size_t(kSize) * n + 1, windowMin_.data(),
                     windowMax_.data());
        pickLattice(windowMin_.data(), windowMax_.data(), n, smin + whole0_, smax + whole0_);
      }
      for (std::int64_t i = 0; i < cx; ++i) {
        if (i == whole0_ && whole1_ > whole0_) i = whole1_;
        if (i >= cx) break;
        const std::int64_t mx = l_.first.x + i;
        const std::size_t xa = std::size_t(std::max(st_.lo.x, mx * kSize) - st_.lo.x);
        const std::size_t xb = std::size_t(std::min(st_.hi.x, mx * kSize + kSize) - st_.lo.x);
        T lo = gmin[xa], hi = gmax[xa];
        for (std::size_t x = xa + 1; x <= xb; ++x) {
          lo = lesser(lo, gmin[x]);
          hi = greater(hi, gmax[x]);
        }
        smin[i] = lo;
        smax[i] = hi;
      }
      // The range: the macrocells' bounds cover the nodes from the first
      // macrocell's to the last's; the columns outside, one by one.
      if (countRange) {
        foldBounds(smin, smax, std::size_t(cx), rangeMin_.data(), rangeMax_.data());
        for (std::size_t x = 0; x < ex_; ++x) {
          if (x == coveredLo_) x = coveredHi_ + 1;
          if (x >= ex_) break;
          rangeLo_ = lesser(rangeLo_, gmin[x]);
          rangeHi_ = greater(rangeHi_, gmax[x]);
        }
      }
    }

    // Step: the range also covers ghost rows outside every macrocell row,
    // and float counts its non-finite voxels, each row once.
    if (countRange) {
      const std::int64_t yLo = l_.first.y * kSize, yHi = (l_.first.y + l_.count.y) * kSize;
      for (std::int64_t y = st_.lo.y; y <= st_.hi.y; ++y) {
        if (y < yLo || y > yHi) {
          const T* r = row(y);
          for (std::size_t x = 0; x < ex_; ++x) {
            rangeLo_ = lesser(rangeLo_, forMin(r[x]));
            rangeHi_ = greater(rangeHi_, forMax(r[x]));
          }
        }
        if constexpr (std::is_floating_point_v<T>) nonFinite_ += countNonFinite(row(y), ex_);
      }
    }

    // Step: count the owned voxels' keys, each slab once (countRange).
    if (countRange && counts_ && z >= counted_.lo.z && z <= counted_.hi.z)
      for (std::int64_t y = counted_.lo.y; y <= counted_.hi.y; ++y)
        counts_->countRow(row(y) + std::size_t(counted_.lo.x - st_.lo.x), std::size_t(counted_.extent(0)));

    // Step: widen the layers.
    if (into0) foldLayer(m0);
    if (into1) foldLayer(m1);
  }

  // The counted slabs' range; min > max if they hold no finite voxel.
  ValueRange range() const {
    T lo = rangeLo_, hi = rangeHi_;
    for (std::size_t i = 0; i < rangeMin_.size(); ++i) {
      lo = lesser(lo, rangeMin_[i]);
      hi = greater(hi, rangeMax_[i]);
    }
    return {double(lo), double(hi), nonFinite_};
  }

  // Adds the counted keys to `out` (sized fineKeyCount); nothing without a counted box.
  void addCounts(std::vector<std::uint64_t>& out) const {
    if (counts_) counts_->addTo(out);
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
  std::vector<T> windowMin_, windowMax_;  // sliding bounds along x (windowBounds)
  std::int64_t whole0_ = 0, whole1_ = 0;  // macrocells of whole node ranges along x
  std::size_t wholeAt_ = 0;               // node of macrocell whole0_, in the stored row
  std::size_t coveredLo_ = 0, coveredHi_ = 0;  // nodes some macrocell covers, in the stored row
  std::vector<T> rangeMin_, rangeMax_;    // every counted slab's macrocell bounds, reduced
  T rangeLo_ = emptyMin<T>(), rangeHi_ = emptyMax<T>();  // ... and its nodes outside every macrocell
  std::vector<T> slabMin_, slabMax_;    // this slab's 2-D macrocell bounds
  std::uint64_t nonFinite_ = 0;
  NodeBox counted_;                     // histogram box, when counts_ is there
  std::optional<FineCounter<T>> counts_;  // its fine key counts
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

std::shared_ptr<FineHistogram> countFineKeys(ScalarType type, const NodeBox& stored, const std::byte* voxels,
                                             const NodeBox& counted, ThreadPool* pool) {
  auto out = emptyHistogram(type, &counted, stored);
  if (counted.empty()) return out;
  dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = reinterpret_cast<const T*>(voxels);
    const std::size_t ex = std::size_t(stored.extent(0)), slabNodes = ex * std::size_t(stored.extent(1));
    auto countSlabs = [&](FineCounter<T>& counter, std::int64_t z0, std::int64_t z1) {
      for (std::int64_t z = z0; z < z1; ++z)
        for (std::int64_t y = counted.lo.y; y <= counted.hi.y; ++y)
          counter.countRow(v + std::size_t(z - stored.lo.z) * slabNodes + std::size_t(y - stored.lo.y) * ex +
                               std::size_t(counted.lo.x - stored.lo.x),
                           std::size_t(counted.extent(0)));
    };
    // Chunks of slabs into one counter per thread: a 16-bit counter is
    // 512 KiB to clear and add up.
    std::vector<std::optional<FineCounter<T>>> counters(std::size_t(pool ? pool->size() : 1));
    forChunks(std::size_t(counted.extent(2)), pool, [&](std::size_t z0, std::size_t z1, int worker) {
      auto& counter = counters[std::size_t(worker)];
      if (!counter) counter.emplace();
      countSlabs(*counter, counted.lo.z + std::int64_t(z0), counted.lo.z + std::int64_t(z1));
    });
    for (const auto& counter : counters)
      if (counter) counter->addTo(out->counts);
  });
  return out;
}

}  // namespace pvr::core
