// castRayByLevels: march one ray at the step each region's error allows.
//
// The ray's fine samples k (step h) fall into blocks of kLevelBlock,
// aligned to the global index: block b holds k in [b * kLevelBlock,
// (b + 1) * kLevelBlock). A block takes one level l (step_levels.h) and is
// sampled at step 2^l h: its coarse sample j is the fine sample
// 2^l j + 2^(l-1), which stands for the fine samples [2^l j, 2^l j + 2^l)
// (half a fine step past their middle, where a whole fine sample lies) and
// is classified from level l's table (a step of 2^l h). A coarse sample is
// a fine sample, so the brick that owns it takes it, and empty-space
// skipping, which passes over fine samples only where they are proven
// transparent, passes over coarse ones alike; the block's level is read at
// points that depend on the block alone (levelAt). So bricks take the same
// samples as the whole volume. Blocks at the chord's ends stay fine, where
// runEnd stretches and cuts the end segments.
//
// Per chunk, not per sample: one level look-up chooses the parameters and
// the ray a chunk is marched with; runSpan marches it as castRay does.
// Sixteen rays are started and walked past empty space at once, as
// castRays' are (LevelWalk, castRaysByLevels).
#pragma once

#if defined(__AVX512F__) && defined(__AVX512DQ__)
#include <immintrin.h>
#endif

#include "cast_ray.h"
#include "step_levels.h"

namespace pvr::core {

namespace kernel {

// The ray at level l >= 1: its sample j is the fine sample 2^l j + 2^(l-1).
inline RaySetup levelRay(const RaySetup& fine, int level) {
  RaySetup r = fine;
  const double n = double(1 << level), shift = 0.5 * n;
  for (int a = 0; a < 3; ++a) {
    r.origin[a] = fine.origin[a] + shift * fine.step[a];
    r.step[a] = fine.step[a] * n;
    r.invStep[a] = fine.invStep[a] / n;
  }
  r.leapPerMacrocell = fine.leapPerMacrocell / n;
  return r;
}

// The first coarse sample of level l >= 1 at or after fine sample k.
inline std::int64_t coarseFrom(std::int64_t k, int level) {
  return (k - (std::int64_t(1) << (level - 1)) + (std::int64_t(1) << level) - 1) >> level;
}

// The fine sample of coarse sample j of level l >= 1.
inline std::int64_t fineOf(std::int64_t j, int level) {
  return (j << level) + (std::int64_t(1) << (level - 1));
}

// The level of the macrocell at fine coordinate k, clamped into the domain
// (the same macrocell for every brick) and, for safety, into the layout.
// The position is rounded once (walkMulAdd), as levelsOfBlocks' lanes
// round it.
inline int levelAt(const KernelParams& p, const RaySetup& ray, double k) {
  std::size_t index = 0;
  for (int a = 2; a >= 0; --a) {
    const double u = walkMulAdd(k, ray.step[a], ray.origin[a]);
    const int m = std::clamp(int(std::floor(u)) >> MacrocellLayout::kShift, 0, p.lvDomainLast[a]);
    index = index * std::size_t(p.lvCount[a]) + std::size_t(std::clamp(m - p.lvFirst[a], 0, p.lvCount[a] - 1));
  }
  return p.levels[index];
}

// Where a block's level is read: its middle (the field is eroded by a
// block's reach, StepLevels::choose).
inline double blockMiddle(std::int64_t b) { return double((b << kLevelBlockShift) + kLevelBlock / 2); }

// True when block b holds an end of the chord: it stays fine (level 0).
inline bool holdsChordEnd(const ChordEnds& ends, std::int64_t b) {
  const std::int64_t lo = b << kLevelBlockShift, hi = lo + kLevelBlock - 1;
  return (ends.first >= lo && ends.first <= hi) || (ends.last >= lo && ends.last <= hi);
}

// levelAt() at the middles of blocks b .. b + kBlocksAtOnce - 1, into
// out: eight in the lanes of a vector where the CPU has AVX-512. A march
// scans the blocks ahead for the chunk's level block by block, and one at
// a time each look-up (a double position per axis, its macrocell clamped
// twice, an index and a load) was most of the march's own cost at coarse
// levels.
#if defined(__AVX512F__) && defined(__AVX512DQ__)
inline constexpr int kBlocksAtOnce = 8;

inline void levelsOfBlocks(const KernelParams& p, const RaySetup& ray, std::int64_t b, int* out) {
  constexpr double kStride = double(kLevelBlock);
  const __m512d k = _mm512_add_pd(_mm512_set1_pd(blockMiddle(b)),
                                  _mm512_setr_pd(0, kStride, 2 * kStride, 3 * kStride, 4 * kStride, 5 * kStride,
                                                 6 * kStride, 7 * kStride));
  __m256i index = _mm256_setzero_si256();
  for (int a = 2; a >= 0; --a) {
    const __m512d u = _mm512_fmadd_pd(k, _mm512_set1_pd(ray.step[a]), _mm512_set1_pd(ray.origin[a]));
    const __m512d down = _mm512_maskz_roundscale_pd(preint::kAll, u, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    __m256i m = _mm256_srai_epi32(_mm512_maskz_cvttpd_epi32(preint::kAll, down), MacrocellLayout::kShift);
    m = _mm256_min_epi32(_mm256_max_epi32(m, _mm256_setzero_si256()), _mm256_set1_epi32(p.lvDomainLast[a]));
    m = _mm256_sub_epi32(m, _mm256_set1_epi32(p.lvFirst[a]));
    m = _mm256_min_epi32(_mm256_max_epi32(m, _mm256_setzero_si256()), _mm256_set1_epi32(p.lvCount[a] - 1));
    index = _mm256_add_epi32(_mm256_mullo_epi32(index, _mm256_set1_epi32(p.lvCount[a])), m);
  }
  alignas(32) std::int32_t at[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(at), index);
  for (int j = 0; j < 8; ++j) out[j] = p.levels[at[j]];
}
#else
inline constexpr int kBlocksAtOnce = 1;

inline void levelsOfBlocks(const KernelParams& p, const RaySetup& ray, std::int64_t b, int* out) {
  out[0] = levelAt(p, ray, blockMiddle(b));
}
#endif

// Blocks a chunk may join when they take the same level: a chunk is
// marched without looking at empty space again. A block holds 2^(6-l)
// samples of level l, one or two at the coarsest levels, so a cap of four
// blocks made chunks of 4-8 samples there, each paying a chunk's start and a
// part batch; and at those levels a coarse sample across an empty
// macrocell costs less than the leap's look-up (~24 ns, bench/results/
// walk.txt). With 16 (chunks then ended at kVisibleChunk samples): one
// thread, peer scene at target 40 dB 282 -> 228 ms a frame, CT head at
// 50 dB 370-415 -> 355-372 ms, same images.
inline constexpr std::int64_t kBlocksPerChunk = 16;

// Samples a chunk takes per look-up: at level 0 a uniform walk's
// (visibleChunk(), 32 at half-voxel steps), at coarser levels up to 64
// coarse samples. Each chunk leaves the batch loop and enters it again
// (its setup, and a first batch fetched with nothing to overlap it), and
// at a coarse step a sample run on into an empty macrocell costs less than
// a look-up. Against 16 of each, one thread alternating (load 1.0-1.4):
// peer scene at 40 dB 151.5 -> 141 ms a frame (medians of 7), CT head at
// 50 dB 341 -> 295 ms (faster in 6 of 6 rounds); samples run into empty
// space add 2-7 % to the samples and move no PSNR of
// bench/results/quality.txt by 0.01 dB (the batches' float grouping
// changes by an ulp). bench/results/plain.txt, section 8.
inline constexpr std::int64_t kCoarseChunk = 4 * kVisibleChunk;

// One ray's march by levels, a step at a time, a LeapingWalk as RayWalk is,
// so that the vector lanes start rays and take their look-ups past empty
// space for it (startInLanes, walkInLanes), sixteen rays at once, as
// castRays does: one ray at a time, the march's own scalar look-ups were a
// third of a peer frame at 40 dB (bench/results/plain.txt, section 8).
// Each ray takes the look-ups, leaps and chunks of the loop one ray at a
// time took, in the same order: the same samples and bits.
template <typename T, bool kShaded>
class LevelWalk : public LeapingWalk<LevelWalk<T, kShaded>> {
  using Base = LeapingWalk<LevelWalk>;
  // The base's names, for use unqualified here (a template's base is not searched).
  using Base::k_, Base::end_, Base::ends_, Base::acc_;

 public:
  using Base::finish;

  // Sets the march up; false when the ray is done already (out holds its
  // result). The ray's samples outside `span` lie in invisible macrocells
  // (tileSpan(), tile_start.h).
  bool start(const KernelParams& p, const RaySetup& ray, int mcShift, const TileSpan& span, RayResult& out) {
    std::int64_t first, last;
    if (!sampleRange(p, ray, first, last)) {
      out = castRay<T, kShaded, false>(p, ray, mcShift);
      return false;
    }
    out.hit = true;
    // The march starts and ends where castRay's walk does (the visible box,
    // the tile's span): the samples outside are in invisible macrocells,
    // transparent at every level as the empty space skipped is.
    WalkStart at;
    if (!walkStart(p, ray, span, first, last, at)) return false;
    begin(p, ray, mcShift, at);
    return true;
  }

  // Sets the march up from where it starts (start(), or startInLanes,
  // which finds the same as RayWalk::start for eight rays at once).
  void begin(const KernelParams& p, const RaySetup& ray, int mcShift, const WalkStart& at) {
    this->beginAt(p, ray, mcShift, at);
    fineChunk_ = visibleChunk(ray);
    levelsFrom_ = (at.k >> kLevelBlockShift) - kBlocksAtOnce;  // none known
  }

  // step() (LeapingWalk: empty space is skipped as castRay skips it, a
  // coarse sample in skipped space being transparent too) after a look-up
  // that found fine sample k's macrocell visible: a chunk at the level of
  // k's block.
  bool chunkAt(std::int64_t k, const KernelParams& p, const RaySetup& ray, int /*mcShift*/, RayResult& out) {
    k_ = k;
    const std::int64_t block = k_ >> kLevelBlockShift, blockEnd = (block + 1) << kLevelBlockShift;
    const int level = blockLevel(p, ray, block);
    if (level == 0) {
      std::int64_t exit = std::min(end_ + 1, k_ + fineChunk_);
      if (exit > blockEnd && blockLevel(p, ray, block + 1) != 0) exit = blockEnd;
      if (runSpan<T, kShaded, false>(p, ray, ends_, k_, exit, acc_, out.samples)) return finish(out);
      k_ = exit;
      return k_ <= end_ || finish(out);
    }
    if (!(coarseSet_ & (1u << level))) {
      coarse_[level] = levelRay(ray, level);
      coarseSet_ |= 1u << level;
    }
    // The block's coarse samples from k on that this brick owns (theirs
    // are fine samples in [k, end]), with those of the next blocks of the
    // same level, a chunk at a time.
    const std::int64_t start = coarseFrom(k_, level);
    std::int64_t runEnd = blockEnd;
    while (runEnd <= end_ && runEnd - blockEnd < (kBlocksPerChunk - 1) * kLevelBlock &&
           (runEnd >> level) - start < kCoarseChunk && blockLevel(p, ray, runEnd >> kLevelBlockShift) == level)
      runEnd += kLevelBlock;
    const std::int64_t exit = std::min({coarseFrom(end_ + 1, level), runEnd >> level, start + kCoarseChunk});
    // A coarse chunk has no chord end in it (blockLevel()).
    const ChordEnds noEnds{-1, std::numeric_limits<std::int64_t>::max(), 0, 0};
    if (start < exit && runSpan<T, kShaded, false>(p.atLevel[level], coarse_[level], noEnds, start, exit, acc_,
                                                   out.samples))
      return finish(out);
    k_ = std::min(runEnd, std::max(k_ + 1, fineOf(exit, level)));
    return k_ <= end_ || finish(out);
  }

 private:
  // Block b's level: levelAt() at its middle, fine (0) where it holds an
  // end of the chord. The march asks for blocks in increasing order, so the
  // levels of the blocks from b on are read kBlocksAtOnce at a time and
  // kept.
  int blockLevel(const KernelParams& p, const RaySetup& ray, std::int64_t b) {
    if (holdsChordEnd(ends_, b)) return 0;
    if (b < levelsFrom_ || b >= levelsFrom_ + kBlocksAtOnce) {
      levelsOfBlocks(p, ray, b, levels_);
      levelsFrom_ = b;
    }
    return levels_[b - levelsFrom_];
  }

  // k_ (LeapingWalk) is the next fine sample not yet covered or skipped.
  std::int64_t fineChunk_ = 0;    // samples of a level-0 chunk
  std::int64_t levelsFrom_ = 0;   // levels_[i] is block levelsFrom_ + i's levelAt()
  // Ints, not bytes: as bytes, GCC kept the level in a byte stack slot
  // that a 4-byte load read back (peer at 40 dB: 6 % more CPU a frame).
  int levels_[kBlocksAtOnce];
  RaySetup coarse_[kStepLevels];  // the ray at level l, once a chunk of that level needs it
  unsigned coarseSet_ = 0;        // bit l: coarse_[l] is set
};

}  // namespace kernel

// One ray marched by levels; its samples outside `span` lie in invisible
// macrocells (tileSpan(), tile_start.h; by default nothing is known).
template <typename T, bool kShaded>
RayResult castRayByLevels(const KernelParams& p, const RaySetup& ray, int mcShift,
                          const kernel::TileSpan& span = {}) {
  return kernel::castWalk<kernel::LevelWalk<T, kShaded>>(p, ray, mcShift, span);
}

// Rays rays[0, n) into out[0, n), n <= kRaysAtOnce, each as
// castRayByLevels would take it (with the same `span`), sixteen at once in
// vector lanes where the CPU has AVX-512 (castWalks).
template <typename T, bool kShaded>
void castRaysByLevels(const KernelParams& p, const RaySetup* rays, int n, int mcShift, const kernel::TileSpan& span,
                      RayResult* out) {
  kernel::castWalks<kernel::LevelWalk<T, kShaded>>(p, rays, n, mcShift, span, out);
}

}  // namespace pvr::core
