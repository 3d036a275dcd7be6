// The two ways the batched kernels fetch integer voxels' corner pairs
// (renderer/raycast/batch_loads.h): the hardware gather and the masked
// broadcast loads, of which the build picks one per core
// (kBroadcastPairs). Each must give every lane the voxels a scalar read
// gives, whichever this machine's build uses.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "raycast/batch_loads.h"

#if defined(__AVX2__) && defined(__FMA__)

namespace pvr::core {
namespace {

// Lane j's voxels index[j] and index[j] + 1, read one at a time.
template <typename T>
void expectPairs(const std::vector<T>& voxels, const std::int32_t* index, __m256 lo, __m256 hi) {
  alignas(32) float first[8], second[8];
  _mm256_store_ps(first, lo);
  _mm256_store_ps(second, hi);
  for (int j = 0; j < 8; ++j) {
    CAPTURE(j, index[j]);
    CHECK(first[j] == float(voxels[std::size_t(index[j])]));
    CHECK(second[j] == float(voxels[std::size_t(index[j]) + 1]));
  }
}

template <typename T>
void checkEveryWay() {
  // Voxels of every value the type has, and the padding a brick keeps
  // after its last voxel (a word at the last voxel reads past it).
  std::mt19937 random(7);
  std::vector<T> voxels(4096 + 4);
  std::uniform_int_distribution<int> value(std::numeric_limits<T>::min(), std::numeric_limits<T>::max());
  for (T& v : voxels) v = T(value(random));
  std::uniform_int_distribution<std::int32_t> at(0, 4095 - 1);
  for (int trial = 0; trial < 200; ++trial) {
    alignas(32) std::int32_t index[8];
    for (std::int32_t& i : index) i = at(random);
    if (trial == 0) index[7] = 4094;  // the last pair
    __m256 lo, hi;
    kernel::splitPairs8<T>(kernel::gatherWords8(voxels.data(), index), lo, hi);
    expectPairs(voxels, index, lo, hi);
#if defined(__AVX512F__) && defined(__AVX512VL__)
    kernel::splitPairs8<T>(kernel::broadcastWords8(voxels.data(), index), lo, hi);
    expectPairs(voxels, index, lo, hi);
#endif
    kernel::loadPairs8(voxels.data(), index, 0, lo, hi);  // the build's own choice
    expectPairs(voxels, index, lo, hi);
  }
}

TEST_CASE("corner pairs gathered or broadcast equal the voxels read one at a time", "[raycast][batch]") {
  checkEveryWay<std::uint8_t>();
  checkEveryWay<std::int8_t>();
  checkEveryWay<std::uint16_t>();
  checkEveryWay<std::int16_t>();
}

}  // namespace
}  // namespace pvr::core

#endif
