#include "step_levels.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "../error.h"
#include "../macrocell_bounds.h"

namespace pvr::core {

namespace {

constexpr int kShift = MacrocellLayout::kShift;
constexpr int kSize = MacrocellLayout::kSize;
// A macrocell's value range is taken over its nodes and one layer around
// them: a sample's central differences reach that far, so shading near a
// neighbour's jump counts as variation here.
constexpr int kMargin = 1;

// Index units from a block's middle to its ends, rounded up: half its
// length at the fine step along the axis of the smallest spacing.
std::int64_t halfBlock(const GridGeometry& grid, double sceneStep) {
  return std::int64_t(std::ceil(double(kLevelBlock / 2) * fineStep(sceneStep) / grid.minSpacing() - 1e-9)) + 1;
}

// Macrocells a block reaches from the one its middle lies in: the radius
// by which the levels are eroded, so that the middle's level holds for the
// whole block.
std::int64_t blockSpread(const GridGeometry& grid, double sceneStep) {
  return (halfBlock(grid, sceneStep) + kSize - 1) / kSize;
}

// out[i] = min of in[j] over |j - i| <= r within [0, n), along one axis
// (element k of line `line` at base + k * stride).
void erodeLine(std::uint8_t* v, std::int64_t n, std::int64_t stride, std::int64_t r, std::vector<std::uint8_t>& tmp) {
  tmp.resize(std::size_t(n));
  for (std::int64_t i = 0; i < n; ++i) tmp[std::size_t(i)] = v[i * stride];
  for (std::int64_t i = 0; i < n; ++i) {
    std::uint8_t m = tmp[std::size_t(i)];
    for (std::int64_t j = std::max<std::int64_t>(0, i - r); j <= std::min(n - 1, i + r); ++j)
      m = std::min(m, tmp[std::size_t(j)]);
    v[i * stride] = m;
  }
}

// Range queries over a table's entries in O(1): the max of [a, b] of one
// array, from the maxima of power-of-two spans (a sparse table).
class RangeMax {
 public:
  explicit RangeMax(std::vector<float> values) {
    spans_.push_back(std::move(values));
    const std::size_t n = spans_[0].size();
    for (std::size_t width = 2; width <= n; width *= 2) {
      const std::vector<float>& prev = spans_.back();
      std::vector<float> next(n - width + 1);
      for (std::size_t i = 0; i < next.size(); ++i) next[i] = std::max(prev[i], prev[i + width / 2]);
      spans_.push_back(std::move(next));
    }
  }
  float max(int a, int b) const {  // a <= b
    int level = 0;
    while ((2 << level) <= b - a + 1) ++level;
    const std::vector<float>& s = spans_[std::size_t(level)];
    return std::max(s[std::size_t(a)], s[std::size_t(b - (1 << level) + 1)]);
  }

 private:
  std::vector<std::vector<float>> spans_;
};

}  // namespace

int levelGhostLayers(const GridGeometry& grid, double sceneStep) {
  return int(halfBlock(grid, sceneStep) + kSize * blockSpread(grid, sceneStep)) + kSize + kMargin;
}

double levelError(double steps, double variation, double slope, double entries) {
  // Root mean square over where the samples fall (rays in a pixel's
  // neighbourhood fall everywhere): a kink's midpoint error, between
  // -1/24 and 1/12 of step^2 times the slope change, has an RMS of about
  // 1/16; a jump's, up to half a step of it, of 1/sqrt(12).
  const double smooth = steps * steps / 16.0 * 2.0 * slope * entries / double(kSize);
  return std::min(steps * variation / std::sqrt(12.0), smooth);
}

double levelBudget(double targetPsnr) {
  // The image's RMSE at the target is 10^(-PSNR/20) (peak 1). A pixel's
  // error adds up over the macrocells its ray crosses with variation, and
  // partly cancels; most pixels meet few. The share per macrocell crossing
  // was calibrated on the bench scenes (bench/speed_vs_error/quality.sh):
  // at 3 the shaded water density and CT head missed 60 dB (59.9, 59.4),
  // at 1.5 every scene meets 40, 50 and 60 dB (bench/results/quality.txt).
  constexpr double kShare = 1.5;
  return kShare * std::pow(10.0, -targetPsnr / 20.0);
}

StepLevels::StepLevels(const Brick& brick, double sceneStep, ThreadPool* pool)
    : brick_(brick), sceneStep_(sceneStep) {
  const GridGeometry& grid = brick.grid();
  const NodeBox& own = brick.owned();
  const NodeBox& st = brick.stored();
  // Block middles lie within half a block of an owned sample; the levels
  // there are eroded from blockSpread macrocells around them.
  const std::int64_t reach = halfBlock(grid, sceneStep);
  spread_ = blockSpread(grid, sceneStep);
  for (int a = 0; a < 3; ++a) {
    const std::int64_t cells = std::max<std::int64_t>(1, grid.dims[a] - 1);
    domainCount_[a] = (cells + kSize - 1) >> kShift;
    first_[a] = std::max<std::int64_t>(0, ((own.lo[a] - reach) >> kShift) - spread_);
    const std::int64_t last = std::min(domainCount_[a] - 1, ((own.hi[a] + reach) >> kShift) + spread_);
    count_[a] = std::max<std::int64_t>(1, last - first_[a] + 1);
    // The nodes the last macrocell's range reads must be stored.
    const std::int64_t needLo = std::max<std::int64_t>(0, (first_[a] << kShift) - kMargin);
    const std::int64_t needHi = std::min(grid.dims[a] - 1, ((last + 1) << kShift) + kMargin);
    if (needLo < st.lo[a] || needHi > st.hi[a])
      throw Error(ErrorCode::kInternal,
                  "StepLevels: the brick stores nodes " + std::to_string(st.lo[a]) + ".." + std::to_string(st.hi[a]) +
                      " on axis " + std::to_string(a) + ", the step levels read " + std::to_string(needLo) + ".." +
                      std::to_string(needHi) + " (ghost layers: levelGhostLayers)");
  }
  const std::size_t n = std::size_t(count_.product());
  min_.assign(n, 0);
  max_.assign(n, -1);
  levels_.assign(n, 0);
  const IVec3 ext = st.extents();
  const std::int64_t strideY = ext.x, strideZ = ext.x * ext.y;
  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = reinterpret_cast<const T*>(brick.bytes());
    auto slab = [&](std::size_t z, int) {
      for (std::int64_t y = 0; y < count_.y; ++y)
        for (std::int64_t x = 0; x < count_.x; ++x) {
          const IVec3 m{first_.x + x, first_.y + y, first_.z + std::int64_t(z)};
          IVec3 lo, hi;
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::max<std::int64_t>(0, (m[a] << kShift) - kMargin);
            hi[a] = std::min(grid.dims[a] - 1, ((m[a] + 1) << kShift) + kMargin);
          }
          float mn = emptyMin<float>(), mx = emptyMax<float>();
          for (std::int64_t k = lo.z; k <= hi.z; ++k)
            for (std::int64_t j = lo.y; j <= hi.y; ++j) {
              const T* row = v + (k - st.lo.z) * strideZ + (j - st.lo.y) * strideY - st.lo.x;
              for (std::int64_t i = lo.x; i <= hi.x; ++i) {
                const float s = float(row[i]);
                if (!(std::fabs(s) <= 3.4e38f)) continue;  // NaN and Inf classify as empty
                mn = std::min(mn, s);
                mx = std::max(mx, s);
              }
            }
          const std::size_t at = std::size_t((z * std::size_t(count_.y) + std::size_t(y)) * std::size_t(count_.x) +
                                             std::size_t(x));
          min_[at] = mn;
          max_[at] = mx;
        }
    };
    if (pool) pool->parallelFor(std::size_t(count_.z), slab);
    else for (std::size_t z = 0; z < std::size_t(count_.z); ++z) slab(z, 0);
  });
}

void StepLevels::choose(const TransferFunctionSpec& tf, double targetPsnr, double shadingShare) {
  // The integrand per voxel of path: premultiplied colour and opacity of a
  // one-voxel step, per table entry; its range and steepest step between
  // entries over any span of entries.
  const double voxel = brick_.grid().minSpacing();
  const TransferTable perVoxel(tf, voxel);
  constexpr int n = TransferTable::kEntries;
  const Rgba* e = perVoxel.entries();
  std::vector<float> hi[4], negLo[4], slope(n, 0);
  for (int c = 0; c < 4; ++c) {
    hi[c].resize(n);
    negLo[c].resize(n);
  }
  for (int i = 0; i < n; ++i) {
    const float ch[4] = {e[i].r, e[i].g, e[i].b, e[i].a};
    for (int c = 0; c < 4; ++c) {
      hi[c][i] = ch[c];
      negLo[c][i] = -ch[c];
    }
    if (i + 1 < n) {
      const float next[4] = {e[i + 1].r, e[i + 1].g, e[i + 1].b, e[i + 1].a};
      for (int c = 0; c < 4; ++c) slope[i] = std::max(slope[i], std::fabs(next[c] - ch[c]));
    }
  }
  std::vector<RangeMax> highest, lowest;
  for (int c = 0; c < 4; ++c) {
    highest.emplace_back(std::move(hi[c]));
    lowest.emplace_back(std::move(negLo[c]));
  }
  const RangeMax steepest(std::move(slope));

  const double budget = levelBudget(targetPsnr);
  const double fine = fineStep(sceneStep_) / voxel;  // the fine step in voxels
  const double scale = perVoxel.scale(), offset = perVoxel.offset();
  auto entry = [&](double s) { return std::clamp(s * scale + offset, 0.0, double(n - 1)); };
  for (std::size_t i = 0; i < levels_.size(); ++i) {
    if (!(min_[i] <= max_[i])) {
      levels_[i] = kStepLevels - 1;  // nothing finite: nothing to see
      continue;
    }
    // Entries i and i + 1 both feed a look-up between them.
    const double from = entry(min_[i]), to = entry(max_[i]);
    const int a = std::max(0, int(std::floor(from))), b = std::min(n - 1, int(std::ceil(to)));
    double variation = 0;
    for (int c = 0; c < 4; ++c)
      variation = std::max(variation, double(highest[c].max(a, b) + lowest[c].max(a, b)));
    const double steep = b > a ? double(steepest.max(a, b - 1)) : 0.0;
    // Shading: where the data varies, the lit share of the brightest
    // emission may change across the macrocell with the gradient's
    // direction, smoothly over its 4 voxels.
    double lit = 0;
    if (shadingShare > 0 && max_[i] > min_[i])
      for (int c = 0; c < 4; ++c) lit = std::max(lit, shadingShare * double(highest[c].max(a, b)));
    auto error = [&](double steps) {
      return levelError(steps, variation, steep, to - from) + levelError(steps, lit, lit / 2.0, 2.0);
    };
    int level = kStepLevels - 1;
    while (level > 0 && error(fine * double(1 << level)) > budget) --level;
    levels_[i] = std::uint8_t(level);
  }
  // A block takes the level at its middle: the finest within its reach.
  std::vector<std::uint8_t> line;
  const std::int64_t nx = count_.x, ny = count_.y, nz = count_.z;
  for (std::int64_t z = 0; z < nz; ++z)
    for (std::int64_t y = 0; y < ny; ++y) erodeLine(&levels_[std::size_t((z * ny + y) * nx)], nx, 1, spread_, line);
  for (std::int64_t z = 0; z < nz; ++z)
    for (std::int64_t x = 0; x < nx; ++x) erodeLine(&levels_[std::size_t(z * ny * nx + x)], ny, nx, spread_, line);
  for (std::int64_t y = 0; y < ny; ++y)
    for (std::int64_t x = 0; x < nx; ++x) erodeLine(&levels_[std::size_t(y * nx + x)], nz, nx * ny, spread_, line);
}
}  // namespace pvr::core
