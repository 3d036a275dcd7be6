#include "mix_kernel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace pvr::core {

namespace {

template <typename T, bool kShaded>
void sampleMedium(const KernelParams& p, const RaySetup& ray, double k0, int count, float* out) {
  const T* v = static_cast<const T*>(p.voxels);
  for (int j = 0; j < count; ++j) {
    const double k = k0 + double(j);
    const float x0 = float(ray.origin[0] + k * ray.step[0]);
    const float x1 = float(ray.origin[1] + k * ray.step[1]);
    const float x2 = float(ray.origin[2] + k * ray.step[2]);
    const float value = kernel::trilinear(v, p, x0, x1, x2, p.ownCellLo, p.ownCellHi);
    if (!kernel::finite<T>(value)) continue;
    Rgba c = kernel::classify1D(p, value);  // (c d, d)
    if constexpr (kShaded) {
      if (!(c.a > 0)) continue;
      // shade() scales its specular term by c.a: here the depth, as the
      // extinction weighting wants.
      c = kernel::shade(v, p, ray, x0, x1, x2, c);
    }
    float* o = out + 4 * j;
    o[0] += c.r;
    o[1] += c.g;
    o[2] += c.b;
    o[3] += c.a;
  }
}

// Composites one piece of the ray w steps long whose media sum to `sum`,
// (sum c d, sum d) per step.
inline void composite(kernel::Accumulator& acc, const float* sum, double w) {
  const double depth = double(sum[3]) * w;
  if (!(depth > 0)) return;
  const double alpha = -std::expm1(-depth);
  const double f = w * alpha / depth;
  acc.addBehind({float(sum[0] * f), float(sum[1] * f), float(sum[2] * f), float(alpha)});
}

// One volume's chord on this ray, in steps, and the samples that stand for
// it: first..last, each for the step around it, the first stretched back
// to the entry and the last on to the exit (as ChordEnds); a chord holding
// no sample is one sample at its midpoint.
struct VolumeChord {
  double in = 0, out = 0;
  std::int64_t first = 0, last = -1;
  bool hit = false;
  // The sample standing for this volume's part of slot k (see castMixedRay).
  double sampleFor(std::int64_t k) const {
    return first > last ? 0.5 * (in + out) : double(std::clamp(k, first, last));
  }
};

// Samples [k, end] of a run where the volumes `active` are present in
// every slot and no chord ends: each sample stands for its whole slot.
// Returns true at early termination.
bool runMixedSlots(const MixedVolume* volumes, const RaySetup* rays, const int* active, int m, std::int64_t k,
                   std::int64_t end, float earlyTermination, int mcShift, kernel::Accumulator& acc,
                   std::uint64_t& samples) {
  while (k <= end) {
    // Empty where every volume present is in an empty macrocell; leap as
    // far as the nearest of them allows (see castRay).
    std::int64_t advance = std::numeric_limits<std::int64_t>::max();
    bool visible = false;
    for (int j = 0; j < m && !visible; ++j) {
      const KernelParams& p = volumes[active[j]].params;
      const RaySetup& r = rays[active[j]];
      int mc[3];
      for (int x = 0; x < 3; ++x)
        mc[x] = std::clamp(int(std::floor(r.origin[x] + double(k) * r.step[x])) >> mcShift, p.mcFirst[x],
                           p.mcFirst[x] + p.mcCount[x] - 1);
      const int distance = p.distance[kernel::macrocellIndex(p, mc)];
      if (distance == 0) {
        visible = true;
      } else {
        advance = std::min(advance, kernel::emptyExit(r, mc, distance, k, mcShift) - k);
      }
    }
    if (!visible) {
      k += advance;
      continue;
    }
    // A chunk of samples: each volume adds its part, then over.
    const std::int64_t exit = std::min(end + 1, k + kernel::kVisibleChunk);
    const int count = int(exit - k);
    float sum[4 * kernel::kVisibleChunk] = {};
    for (int j = 0; j < m; ++j)
      volumes[active[j]].sample(volumes[active[j]].params, rays[active[j]], double(k), count, sum);
    for (int s = 0; s < count; ++s) composite(acc, sum + 4 * s, 1.0);
    samples += std::uint64_t(count);
    if (acc.a >= earlyTermination) return true;
    k = exit;
  }
  return false;
}

// Slot k, [k - 0.5, k + 0.5], in which chords begin or end (at `cuts`,
// sorted, inside the slot): pieces between the cuts, each mixing the
// volumes present all along it, each volume by the sample that stands for
// its part of the slot; with `own`, only the pieces whose midpoints it
// owns. Returns true at early termination.
bool runMixedCutSlot(const MixedVolume* volumes, const RaySetup* rays, const VolumeChord* chords, int n,
                     std::int64_t k, const double* cuts, int cutCount, const MixOwnership* own,
                     float earlyTermination, kernel::Accumulator& acc, std::uint64_t& samples) {
  const double lo = double(k) - 0.5, hi = double(k) + 0.5;
  auto present = [&](int i, double from, double to) {
    return chords[i].hit && chords[i].in <= from && chords[i].out >= to;
  };
  // The pieces this brick composites, and the volumes they hold.
  double from[2 * kMaxMixedVolumes + 1], to[2 * kMaxMixedVolumes + 1];
  int pieces = 0;
  bool needed[kMaxMixedVolumes] = {};
  double start = lo;
  for (int c = 0; c <= cutCount; ++c) {
    const double end = c < cutCount ? cuts[c] : hi;
    if (end > start && (!own || own->owns(0.5 * (start + end)))) {
      from[pieces] = start;
      to[pieces] = end;
      ++pieces;
      for (int i = 0; i < n; ++i) needed[i] |= present(i, start, end);
    }
    start = std::max(start, end);
  }
  // Each volume met in them, classified once.
  float value[kMaxMixedVolumes][4] = {};
  for (int i = 0; i < n; ++i) {
    if (!needed[i] || !volumes[i].sample) continue;
    volumes[i].sample(volumes[i].params, rays[i], chords[i].sampleFor(k), 1, value[i]);
    ++samples;
  }
  for (int c = 0; c < pieces; ++c) {
    float sum[4] = {0, 0, 0, 0};
    for (int i = 0; i < n; ++i) {
      if (!present(i, from[c], to[c])) continue;
      for (int x = 0; x < 4; ++x) sum[x] += value[i][x];
    }
    composite(acc, sum, to[c] - from[c]);
    if (acc.a >= earlyTermination) return true;
  }
  return false;
}

// The slots [first, last] where a ray may have pieces `own` owns, and the
// samples [ownFirst, ownLast] it owns (contiguous: the region is convex).
// False if the ray misses the region. The slab estimate is within a sample
// or two; the exact test decides, as sampleRange (kernel.h) does.
bool ownedSpan(const MixOwnership& own, std::int64_t& first, std::int64_t& last, std::int64_t& ownFirst,
               std::int64_t& ownLast) {
  double tIn = double(first) - 1, tOut = double(last) + 1;
  for (int a = 0; a < 3; ++a) {
    if (own.step[a] == 0) {
      if (!(own.origin[a] >= own.lo[a] && own.origin[a] < own.hi[a])) return false;
      continue;
    }
    double t0 = (own.lo[a] - own.origin[a]) / own.step[a], t1 = (own.hi[a] - own.origin[a]) / own.step[a];
    if (t0 > t1) std::swap(t0, t1);
    tIn = std::max(tIn, t0);
    tOut = std::min(tOut, t1);
  }
  if (tIn > tOut + 2) return false;
  first = std::max(first, std::int64_t(std::floor(tIn)) - 2);
  last = std::min(last, std::int64_t(std::ceil(tOut)) + 2);
  ownFirst = first;
  ownLast = last;
  while (ownFirst <= ownLast && !own.owns(double(ownFirst))) ++ownFirst;
  while (ownLast >= ownFirst && !own.owns(double(ownLast))) --ownLast;
  return first <= last;
}

}  // namespace

MixSampler pickMixSampler(ScalarType type, bool shaded) {
  return dispatchScalar(type, [&](auto tag) -> MixSampler {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return shaded ? &sampleMedium<T, true> : &sampleMedium<T, false>;
  });
}

RayResult castMixedRay(const MixedVolume* volumes, const RaySetup* rays, int n, float earlyTermination,
                       int mcShift, const MixOwnership* own) {
  RayResult out;
  // Each volume's chord, and the cuts where the set of volumes changes.
  VolumeChord chords[kMaxMixedVolumes];
  double cuts[2 * kMaxMixedVolumes];
  int cutCount = 0;
  for (int i = 0; i < n; ++i) {
    VolumeChord& c = chords[i];
    c.hit = kernel::domainChord(volumes[i].params, rays[i], c.in, c.out) && c.out > c.in;
    if (!c.hit) continue;
    c.first = std::int64_t(std::ceil(c.in));
    c.last = std::int64_t(std::floor(c.out));
    cuts[cutCount++] = c.in;
    cuts[cutCount++] = c.out;
  }
  if (cutCount == 0) return out;
  std::sort(cuts, cuts + cutCount);

  // Sample k stands for its slot [k - 0.5, k + 0.5] of the ray. Runs of
  // slots without a cut have one set of volumes, each sampled at k; a slot
  // with cuts is split at them (runMixedCutSlot).
  // With `own`, only the slots where this brick's region may own pieces,
  // and of runs without cuts only the samples it owns.
  kernel::Accumulator acc;
  std::int64_t k = std::int64_t(std::floor(cuts[0] + 0.5));
  std::int64_t lastSlot = std::int64_t(std::floor(cuts[cutCount - 1] + 0.5));
  std::int64_t ownFirst = k, ownLast = lastSlot;
  if (own && !ownedSpan(*own, k, lastSlot, ownFirst, ownLast)) return out;
  out.hit = true;
  int next = 0;  // the first cut beyond slot k's start
  while (k <= lastSlot) {
    const double lo = double(k) - 0.5, hi = double(k) + 0.5;
    while (next < cutCount && cuts[next] <= lo) ++next;
    if (next < cutCount && cuts[next] < hi) {
      int inSlot = 0;
      while (next + inSlot < cutCount && cuts[next + inSlot] < hi) ++inSlot;
      if (runMixedCutSlot(volumes, rays, chords, n, k, cuts + next, inSlot, own, earlyTermination, acc,
                          out.samples))
        break;
      ++k;
      continue;
    }
    // Slots k .. end lie between two cuts.
    const std::int64_t end =
        next < cutCount ? std::int64_t(std::floor(cuts[next] - 0.5)) : lastSlot;
    int active[kMaxMixedVolumes], m = 0;
    for (int i = 0; i < n; ++i)
      if (chords[i].hit && volumes[i].sample && chords[i].in <= lo && chords[i].out >= hi) active[m++] = i;
    const std::int64_t runFirst = std::max(k, ownFirst), runLast = std::min(end, ownLast);
    if (m > 0 && runFirst <= runLast &&
        runMixedSlots(volumes, rays, active, m, runFirst, runLast, earlyTermination, mcShift, acc, out.samples))
      break;
    k = std::max(k + 1, end + 1);
  }
  out.colour = acc.rgba();
  return out;
}

}  // namespace pvr::core
