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
#pragma once

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
inline int levelAt(const KernelParams& p, const RaySetup& ray, double k) {
  std::size_t index = 0;
  for (int a = 2; a >= 0; --a) {
    const double u = ray.origin[a] + k * ray.step[a];
    const int m = std::clamp(int(std::floor(u)) >> MacrocellLayout::kShift, 0, p.lvDomainLast[a]);
    index = index * std::size_t(p.lvCount[a]) + std::size_t(std::clamp(m - p.lvFirst[a], 0, p.lvCount[a] - 1));
  }
  return p.levels[index];
}

// Block b's level: at its middle (the field is eroded by a block's reach,
// StepLevels::choose); fine (0) at the chord's ends.
inline int blockLevel(const KernelParams& p, const RaySetup& ray, const ChordEnds& ends, std::int64_t b) {
  const std::int64_t lo = b << kLevelBlockShift, hi = lo + kLevelBlock - 1;
  if ((ends.first >= lo && ends.first <= hi) || (ends.last >= lo && ends.last <= hi)) return 0;
  return levelAt(p, ray, double(lo + kLevelBlock / 2));
}

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

}  // namespace kernel

// One ray; its samples outside `span` lie in invisible macrocells
// (tileSpan(), tile_start.h; by default nothing is known).
template <typename T, bool kShaded>
RayResult castRayByLevels(const KernelParams& p, const RaySetup& ray, int mcShift,
                          const kernel::TileSpan& span = {}) {
  std::int64_t first, last;
  if (!kernel::sampleRange(p, ray, first, last)) return castRay<T, kShaded, false>(p, ray, mcShift);
  RayResult out;
  out.hit = true;
  // The march starts and ends where castRay's walk does (the visible box,
  // the tile's span): the samples outside are in invisible macrocells,
  // transparent at every level as the empty space skipped below is.
  std::int64_t k = first, end = last;
  if (!kernel::clipToWalk(p, ray, span, k, end)) return out;
  const kernel::ChordEnds ends = kernel::chordEnds(p, ray, first, last);
  // A coarse chunk has no chord end in it (blockLevel).
  const kernel::ChordEnds noEnds{-1, std::numeric_limits<std::int64_t>::max(), 0, 0};
  RaySetup coarse[kStepLevels];
  bool coarseSet[kStepLevels] = {};

  const float o[3] = {float(ray.origin[0]), float(ray.origin[1]), float(ray.origin[2])};
  const float d[3] = {float(ray.step[0]), float(ray.step[1]), float(ray.step[2])};
  const kernel::CubeExit cube(ray, mcShift);
  const std::uint8_t* field = p.leapField[kernel::octantOf(ray)];
  kernel::Accumulator acc;
  const std::int64_t fineChunk = kernel::visibleChunk(ray);
  while (k <= end) {  // k: the next fine sample not yet covered or skipped
    // Empty space is skipped as castRay skips it: a coarse sample in
    // skipped space is transparent too.
    if (const std::int64_t next = kernel::pastEmpty(p, field, cube, o, d, k, mcShift); next != k) {
      k = next;
      continue;
    }
    const std::int64_t block = k >> kLevelBlockShift, blockEnd = (block + 1) << kLevelBlockShift;
    const int level = kernel::blockLevel(p, ray, ends, block);
    if (level == 0) {
      std::int64_t exit = std::min(end + 1, k + fineChunk);
      if (exit > blockEnd && kernel::blockLevel(p, ray, ends, block + 1) != 0) exit = blockEnd;
      if (kernel::runSpan<T, kShaded, false>(p, ray, ends, k, exit, acc, out.samples)) break;
      k = exit;
      continue;
    }
    if (!coarseSet[level]) {
      coarse[level] = kernel::levelRay(ray, level);
      coarseSet[level] = true;
    }
    // The block's coarse samples from k on that this brick owns (theirs
    // are fine samples in [k, end]), with those of the next blocks of the
    // same level, a chunk at a time.
    const std::int64_t start = kernel::coarseFrom(k, level);
    std::int64_t runEnd = blockEnd;
    while (runEnd <= end && runEnd - blockEnd < (kernel::kBlocksPerChunk - 1) * kLevelBlock &&
           (runEnd >> level) - start < kernel::kCoarseChunk &&
           kernel::blockLevel(p, ray, ends, runEnd >> kLevelBlockShift) == level)
      runEnd += kLevelBlock;
    const std::int64_t exit =
        std::min({kernel::coarseFrom(end + 1, level), runEnd >> level, start + kernel::kCoarseChunk});
    if (start < exit &&
        kernel::runSpan<T, kShaded, false>(p.atLevel[level], coarse[level], noEnds, start, exit, acc, out.samples))
      break;
    k = std::min(runEnd, std::max(k + 1, kernel::fineOf(exit, level)));
  }
  out.colour = acc.rgba();
  return out;
}

}  // namespace pvr::core
