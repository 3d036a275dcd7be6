// The histogram of a volume's values, counted while its bricks are
// preprocessed (preprocess.h) and binned once the whole volume's range is known.
//
// A brick cannot bin into 256 bins of the volume's range: it learns that
// range only after every rank has read its brick. So it counts its values
// by a fine key that needs no range: the value itself for 8- and 16-bit
// integers (exact), the top 16 bits of an order-preserving encoding of the
// IEEE bits for float32 (a value's sign, exponent and 7 mantissa bits).
// Fine counts add across bricks; binning a fine key into the coarse bins
// depends only on the key and the range, so binning each brick's counts and
// adding the bins equals binning the sum: any decomposition gives the
// histogram a serial count of the whole volume gives (value_histogram_test).
//
// Each voxel counts once: a brick counts its owned nodes except the plane
// it shares with the next brick (countedBox), and never its ghosts.
// Non-finite float values are not counted (ValueRange::nonFinite counts them).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "grid.h"

namespace pvr::core {

// Coarse bins of the histogram a dataset reports.
inline constexpr int kHistogramBins = 256;

// Fine keys of a scalar type: 256 for uint8, 65536 for the others.
template <typename T> inline constexpr std::size_t kFineKeys = sizeof(T) == 1 ? 256 : 65536;
std::size_t fineKeyCount(ScalarType type);

// The fine key of a value of type T (finite for float).
template <typename T> inline std::uint32_t fineKey(T v) {
  if constexpr (sizeof(T) == 1) return std::uint32_t(std::uint8_t(v));
  else if constexpr (sizeof(T) == 2) return std::uint32_t(std::uint16_t(v));  // int16 wraps; keyValue undoes it
  else {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    // Negative floats reverse their order with magnitude: flip them all.
    const std::uint32_t ordered = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
    return ordered >> 16;
  }
}

// The value a fine key stands for: the value itself for integers, the
// middle of the key's interval for float32.
double fineKeyValue(ScalarType type, std::uint32_t key);

// The nodes of `owned` a brick counts: all of them on an axis where it
// reaches the grid's last node, else all but its last plane (its
// neighbour's first). Empty when owned is one node thick there.
NodeBox countedBox(const NodeBox& owned, const GridGeometry& grid);

// Fine counts of one brick (or a sum of bricks) of one scalar type.
struct FineHistogram {
  ScalarType type = ScalarType::kUInt8;
  std::vector<std::uint64_t> counts;  // fineKeyCount(type), by key
};

// `bins` bins of equal width over [min, max] (the last one closed); a
// key's value outside the range goes to the nearest end bin. All counts go
// to bin 0 when min == max.
std::vector<std::uint64_t> binHistogram(const FineHistogram& fine, double min, double max,
                                        int bins = kHistogramBins);

}  // namespace pvr::core
