#include "macrocells.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include "../preprocess.h"
#include "leap_distance.h"

namespace pvr::core {

namespace {

constexpr int kFar = 255;  // the distance field's cap: "255 or farther"

// The 1-D min-max transform of a line, in place:
//   d(i) = min(255, min over q of max(|i - q|, f(q))).
// Applied along x to the 0/255 visibility it gives the distance along x;
// applied next along y and then z to the previous result it gives the 3-D
// chessboard distance, because a cube (the chessboard ball) is the product
// of three intervals. Each direction is one pass: going forward,
// a(i) = min(f(i), A) where A, the best over q < i, is a(i-1) or a(i-1)+1;
// it stays a(i-1) = v exactly when some q < i with f(q) = v lies within v
// of i, and the latest such q is remembered per value. Positions are
// stamped with a base that grows from line to line, so a stale entry is
// always too far back to count and the table needs no clearing.
//
// A step's look-up depends on the step before, so kLanes neighbouring
// lines go in lockstep: their chains are independent and overlap in the
// CPU, and they share cache lines.
class MinMaxLines {
 public:
  static constexpr int kLanes = 8;

  // Transforms `lines` (1..kLanes) lines of n elements each: element k of
  // line j is f[j * lineStep + k * stride].
  void transform(std::uint8_t* f, std::ptrdiff_t lineStep, int lines, std::ptrdiff_t stride, std::int64_t n) {
    if (base_ > kMaxBase - 2 * (n + kFar + 1)) reset();
    forward_.resize(std::size_t(n) * kLanes);
    sweep(n, lines, [&](int j, std::int64_t k) -> std::uint8_t& { return f[j * lineStep + k * stride]; },
          [&](int j, std::int64_t k, int a) { forward_[std::size_t(k) * kLanes + std::size_t(j)] = std::uint8_t(a); });
    sweep(n, lines, [&](int j, std::int64_t k) -> std::uint8_t& { return f[j * lineStep + (n - 1 - k) * stride]; },
          [&](int j, std::int64_t k, int a) {
            std::uint8_t& out = f[j * lineStep + (n - 1 - k) * stride];
            out = std::uint8_t(std::min<int>(a, forward_[std::size_t(n - 1 - k) * kLanes + std::size_t(j)]));
          });
  }

 private:
  static constexpr std::int32_t kMaxBase = std::int32_t(1) << 30;

  void reset() {
    for (auto& lane : last_) std::fill(std::begin(lane), std::end(lane), -kMaxBase);
    base_ = 0;
  }

  // One direction; at(j, k) is line j's k-th element in sweep order,
  // done(j, k, a) is called after it was read with the one-sided result a.
  template <typename At, typename Done>
  void sweep(std::int64_t n, int lines, At&& at, Done&& done) {
    int prev[kLanes];
    std::fill(std::begin(prev), std::end(prev), kFar);
    for (std::int64_t k = 0; k < n; ++k) {
      const std::int32_t here = base_ + std::int32_t(k);
      for (int j = 0; j < lines; ++j) {
        const int fk = at(j, k);
        const int p = prev[j];
        const int a = p >= kFar ? kFar : (last_[j][p] >= here - p ? p : p + 1);
        prev[j] = std::min(fk, a);
        last_[j][fk] = here;
        done(j, k, prev[j]);
      }
    }
    base_ += std::int32_t(n) + kFar + 1;
  }

  std::int32_t last_[kLanes][kFar + 1];
  std::int32_t base_ = kMaxBase;  // forces a reset before the first line
  std::vector<std::uint8_t> forward_;
};

// out[i] = 0 where macrocell i shows something, else kFar: least[v] is the
// least maximum that shows something for minimum v. A function of its own
// so that restrict holds: a byte store may alias anything, and in the
// classify lambda each one made the loop reload every pointer it captured.
template <typename T>
void markShown(const T* __restrict mn, const T* __restrict mx, const std::int32_t* __restrict least,
               std::uint8_t* __restrict out, std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) out[i] = std::int32_t(mx[i]) >= least[mn[i]] ? 0 : kFar;
}

}  // namespace

void chessboardDistance(std::uint8_t* d, IVec3 count, ThreadPool* pool) {
  constexpr int kLanes = MinMaxLines::kLanes;
  const std::int64_t nx = count.x, ny = count.y, nz = count.z;
  auto lanesFrom = [](std::int64_t i, std::int64_t end) { return int(std::min<std::int64_t>(kLanes, end - i)); };
  // Along x: one line per (y, z), kLanes rows at a time.
  const std::int64_t rows = ny * nz, rowGroups = (rows + kLanes - 1) / kLanes;
  forChunks(std::size_t(rowGroups), pool, [&](std::size_t b, std::size_t e) {
    MinMaxLines lines;
    for (std::int64_t r = std::int64_t(b) * kLanes; r < std::min(rows, std::int64_t(e) * kLanes); r += kLanes)
      lines.transform(d + r * nx, nx, lanesFrom(r, rows), 1, nx);
  });
  // Along y: one line per (x, z), kLanes neighbours in x at a time.
  forChunks(std::size_t(nz), pool, [&](std::size_t b, std::size_t e) {
    MinMaxLines lines;
    for (std::int64_t z = std::int64_t(b); z < std::int64_t(e); ++z)
      for (std::int64_t x = 0; x < nx; x += kLanes) lines.transform(d + z * nx * ny + x, 1, lanesFrom(x, nx), nx, ny);
  });
  // Along z: one line per (x, y).
  forChunks(std::size_t(ny), pool, [&](std::size_t b, std::size_t e) {
    MinMaxLines lines;
    for (std::int64_t y = std::int64_t(b); y < std::int64_t(e); ++y)
      for (std::int64_t x = 0; x < nx; x += kLanes) lines.transform(d + y * nx + x, 1, lanesFrom(x, nx), nx * ny, nz);
  });
}

MacrocellGrid::MacrocellGrid(const Brick& brick, ThreadPool* pool) : bounds_(brick.macrocellBounds()) {
  if (!bounds_) {
    const auto start = std::chrono::steady_clock::now();
    bounds_ = preprocessVoxels(brick.type(), brick.owned(), brick.stored(), brick.bytes(), pool).bounds;
    buildSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  distance_.assign(bounds_->layout().size(), 0);  // all visible until classified
  findVisibleBox();
}

void MacrocellGrid::classify(const TransferTable& table, bool skipEmpty, ThreadPool* pool) {
  {
    std::lock_guard<std::mutex> lock(forward_->mutex);
    for (auto& field : forward_->byOctant) field.reset();
  }
  skipEmpty_ = skipEmpty;
  if (!skipEmpty) {
    std::fill(distance_.begin(), distance_.end(), std::uint8_t(0));  // every macrocell sampled
    findVisibleBox();
    return;
  }
  const std::size_t n = distance_.size();
  const std::size_t layer = std::size_t(count().x * count().y);
  dispatchScalar(bounds_->type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* mn = bounds_->min<T>();
    const T* mx = bounds_->max<T>();
    // Integer bounds of 16 bits or fewer: for each minimum, the least
    // maximum whose range shows something (a wider range shows at least
    // as much, so it grows with the minimum and one sweep finds them all);
    // a macrocell is then one look-up and a compare. An empty macrocell
    // (min > max) compares below its own minimum's entry.
    constexpr bool kTabled = std::is_integral_v<T> && sizeof(T) <= 2;
    constexpr std::int64_t kLowest = [] {
      if constexpr (kTabled) return std::int64_t(std::numeric_limits<T>::lowest());
      else return std::int64_t(0);
    }();
    std::vector<std::int32_t> leastShownMax;
    if constexpr (kTabled) {
      constexpr std::int64_t kValues = std::int64_t(1) << (8 * sizeof(T));
      leastShownMax.resize(std::size_t(kValues));
      std::int64_t hi = 0;
      for (std::int64_t lo = 0; lo < kValues; ++lo) {
        hi = std::max(hi, lo);
        while (hi < kValues && !table.anyVisible(double(lo + kLowest), double(hi + kLowest))) ++hi;
        leastShownMax[std::size_t(lo)] = std::int32_t(hi + kLowest);  // as a value, like the bounds
      }
    }
    std::uint8_t* out = distance_.data();
    forChunks(n / std::max<std::size_t>(layer, 1), pool, [&](std::size_t b, std::size_t e) {
      if constexpr (kTabled) {
        markShown(mn, mx, leastShownMax.data() - kLowest, out, b * layer, e * layer);
      } else {
        for (std::size_t i = b * layer; i < e * layer; ++i)
          out[i] = mn[i] <= mx[i] && table.anyVisible(double(mn[i]), double(mx[i])) ? 0 : kFar;
      }
    });
  });
  leapDistance(distance_.data(), count(), pool);
  findVisibleBox();
}

int MacrocellGrid::forwardFieldsKept() const { return int(std::clamp<std::size_t>(scalarSize(bounds_->type()), 1, 4)); }

MacrocellGrid::LeapFields MacrocellGrid::leapFields(const std::vector<int>& wanted, ThreadPool* pool) const {
  LeapFields out;
  bool chosen[8] = {};
  if (skipEmpty_)  // else distance() is all 0, and so would every forward field be
    for (std::size_t i = 0; i < std::min(wanted.size(), std::size_t(forwardFieldsKept())); ++i) chosen[wanted[i]] = true;
  std::lock_guard<std::mutex> lock(forward_->mutex);
  auto& cache = forward_->byOctant;
  for (int o = 0; o < 8; ++o)
    if (!chosen[o]) cache[o].reset();  // within the budget only while wanted
  for (int o = 0; o < 8; ++o) {
    out.byOctant[o] = distance_.data();
    if (!chosen[o]) continue;
    if (!cache[o]) {
      // distance_ marks the visible macrocells 0 and no other.
      auto field = std::make_shared<std::vector<std::uint8_t>>(distance_);
      forwardLeapDistance(field->data(), count(), o, pool);
      cache[o] = std::move(field);
    }
    out.held[o] = cache[o];
    out.byOctant[o] = cache[o]->data();
  }
  return out;
}

void MacrocellGrid::findVisibleBox() {
  // One pass over the field: each visible macrocell widens the box.
  const IVec3 n = count();
  IVec3 lo{n.x, n.y, n.z}, hi{-1, -1, -1};
  const std::uint8_t* d = distance_.data();
  for (std::int64_t z = 0; z < n.z; ++z)
    for (std::int64_t y = 0; y < n.y; ++y) {
      const std::uint8_t* row = d + (z * n.y + y) * n.x;
      std::int64_t x0 = 0;
      while (x0 < n.x && row[x0] != 0) ++x0;
      if (x0 == n.x) continue;
      std::int64_t x1 = n.x - 1;
      while (row[x1] != 0) --x1;
      lo = {std::min(lo.x, x0), std::min(lo.y, y), std::min(lo.z, z)};
      hi = {std::max(hi.x, x1), std::max(hi.y, y), std::max(hi.z, z)};
    }
  const IVec3 at = first();
  if (hi.x < 0) {
    visibleFirst_ = {at.x + 1, at.y + 1, at.z + 1};  // empty: first > last
    visibleLast_ = at;
    return;
  }
  visibleFirst_ = {at.x + lo.x, at.y + lo.y, at.z + lo.z};
  visibleLast_ = {at.x + hi.x, at.y + hi.y, at.z + hi.z};
}

}  // namespace pvr::core
