#include "value_histogram.h"

#include <algorithm>
#include <cmath>

namespace pvr::core {

std::size_t fineKeyCount(ScalarType type) {
  switch (type) {
    case ScalarType::kUInt8: return kFineKeys<std::uint8_t>;
    case ScalarType::kUInt16: return kFineKeys<std::uint16_t>;
    case ScalarType::kInt16: return kFineKeys<std::int16_t>;
    case ScalarType::kFloat32: return kFineKeys<float>;
  }
  return kFineKeys<float>;
}

namespace {

// The float whose order-preserving encoding is `ordered` (fineKey undone).
float orderedToFloat(std::uint32_t ordered) {
  const std::uint32_t bits = (ordered & 0x80000000u) ? (ordered & 0x7fffffffu) : ~ordered;
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

}  // namespace

double fineKeyValue(ScalarType type, std::uint32_t key) {
  switch (type) {
    case ScalarType::kUInt8:
    case ScalarType::kUInt16: return double(key);
    case ScalarType::kInt16: return double(std::int16_t(std::uint16_t(key)));
    case ScalarType::kFloat32: break;
  }
  // The key's interval of encodings, its ends as floats; a key that holds
  // NaN or Inf encodings at one end (never counted) falls back to the other.
  const double lo = orderedToFloat(key << 16), hi = orderedToFloat((key << 16) | 0xffffu);
  if (!std::isfinite(lo)) return hi;
  if (!std::isfinite(hi)) return lo;
  return 0.5 * (lo + hi);
}

NodeBox countedBox(const NodeBox& owned, const GridGeometry& grid) {
  NodeBox box = owned;
  for (int a = 0; a < 3; ++a)
    if (box.hi[a] < grid.dims[a] - 1) box.hi[a] -= 1;
  return box;
}

std::vector<std::uint64_t> binHistogram(const FineHistogram& fine, double min, double max, int bins) {
  std::vector<std::uint64_t> out(std::size_t(std::max(bins, 1)), 0);
  const double width = max - min;
  for (std::size_t key = 0; key < fine.counts.size(); ++key) {
    const std::uint64_t n = fine.counts[key];
    if (n == 0) continue;
    std::size_t bin = 0;
    if (width > 0) {
      const double at = std::floor((fineKeyValue(fine.type, std::uint32_t(key)) - min) / width * double(out.size()));
      bin = std::size_t(std::clamp(at, 0.0, double(out.size() - 1)));
    }
    out[bin] += n;
  }
  return out;
}

}  // namespace pvr::core
