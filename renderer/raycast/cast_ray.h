// castRay: march one ray through one brick, skipping invisible macrocells.
//
// Instantiated per scalar type, shading, pre-integration and the way
// shading raises the specular power (kPower, specular_power.h) by
// raycaster.cpp; nothing in here branches on configuration at run time.
#pragma once

#include <cstdint>
#include <limits>

#include "kernel.h"
#include "kernel_batch.h"
#include "preint_lighting.h"
#include "start_lanes.h"
#include "tile_start.h"
#include "walk_lanes.h"

namespace pvr::core {

namespace kernel {

// Samples [start, exit) of a visible run, one at a time. Returns true when
// the ray reached the early-termination opacity.
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kTablePower>
inline bool runScalar(const KernelParams& p, const RaySetup& ray, std::int64_t start,
                      std::int64_t exit, Accumulator& acc, std::uint64_t& samples) {
  if (start >= exit) return false;  // the batched kernel did them all: no window to set up
  const T* v = static_cast<const T*>(p.voxels);
  const float o0 = float(ray.origin[0]), o1 = float(ray.origin[1]), o2 = float(ray.origin[2]);
  const float d0 = float(ray.step[0]), d1 = float(ray.step[1]), d2 = float(ray.step[2]);
  // Pre-integrated: the samples at s - 1, s and s + 1 and segment s's front end.
  PreintWindow w;
  if constexpr (kPreintegrated) w = preintWindow<T>(p, ray, start);
  float centre = 0.5f, spread = 0.0f;  // pre-integrated: where in its segment to light it
  for (std::int64_t s = start; s < exit; ++s) {
    const float x0 = o0 + float(s) * d0, x1 = o1 + float(s) * d1, x2 = o2 + float(s) * d2;
    Rgba c;
    if constexpr (kPreintegrated) {
      // Sample s + 2's position by the same formula as every sample's, so a
      // run that starts later reads exactly the values carried here.
      const float next = around(v, p, o0 + float(s + 2) * d0, o1 + float(s + 2) * d1, o2 + float(s + 2) * d2);
      float lo, hi;
      aroundRange(v, p, o0 + float(s + 1) * d0, o1 + float(s + 1) * d1, o2 + float(s + 1) * d2, lo, hi);
      const preint::End backEnd = segmentEnd<T>(p, curvedNode<T>(w.front, w.back, next, lo, hi));
      c = finite<T>(w.front) && finite<T>(w.back)
              ? preint::segment(p.preint, w.frontEnd, backEnd, p.stepLength, &centre, &spread)
              : Rgba{};
      w.advance(next, backEnd);
    } else {
      const float value = trilinear(v, p, x0, x1, x2, p.ownCellLo, p.ownCellHi);
      c = finite<T>(value) ? classify1D(p, value) : Rgba{};
    }
    ++samples;
    if constexpr (kShaded) {
      if (!(c.a > 0)) continue;
      // Pre-integrated: lit where the segment emits (preint_lighting.h).
      if constexpr (kPreintegrated) {
        c = shadeSegment(v, p, ray, float(s), 1.0f, centre, spread, c);
      } else {
        c = shade<T, kPower>(v, p, ray, x0, x1, x2, c);
      }
    }
    acc.addBehind(c);
    if (acc.a >= p.earlyTermination) return true;
  }
  return false;
}

// One sample standing for the segment [from, to] of the ray (in steps),
// composited into acc: plain, classified and shaded at `at`, then
// stretched from one step to the segment's length; pre-integrated from
// `from` to `to` over the segment's own length and shaded where it emits.
// `at` is a sample this brick owns (or a short chord's midpoint), and
// `from` and `to` lie within a step of it, so every read stays within the
// ghost layers (ghostLayers()). Returns true at early termination.
// Out of line and cold: it runs at most twice per ray.
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kTablePower>
[[gnu::noinline, gnu::cold]] bool runSegment(const KernelParams& p, const RaySetup& ray,
                                             double at, double from, double to,
                                             Accumulator& acc, std::uint64_t& samples) {
  const T* v = static_cast<const T*>(p.voxels);
  auto position = [&](double k, float* x) {
    for (int a = 0; a < 3; ++a) x[a] = float(ray.origin[a] + k * ray.step[a]);
  };
  float x[3];
  Rgba c;
  float centre = 0.5f, spread = 0.0f;  // pre-integrated: where to light it
  if constexpr (kPreintegrated) {
    // Integrated over its own length: no stretching.
    float f[3], b[3];
    position(from, f);
    position(to, b);
    const float front = around(v, p, f[0], f[1], f[2]), back = around(v, p, b[0], b[1], b[2]);
    if (finite<T>(front) && finite<T>(back))
      c = preint::segment(p.preint, segmentEnd<T>(p, front), segmentEnd<T>(p, back),
                          (to - from) * p.stepLength, &centre, &spread);
  } else {
    position(at, x);
    const float value = trilinear(v, p, x[0], x[1], x[2], p.ownCellLo, p.ownCellHi);
    if (finite<T>(value)) c = classify1D(p, value);
  }
  ++samples;
  if constexpr (kShaded) {
    if (c.a > 0) {
      if constexpr (kPreintegrated) c = shadeSegment(v, p, ray, float(from), float(to - from), centre, spread, c);
      else c = shade<T, kPower>(v, p, ray, x[0], x[1], x[2], c);
    }
  }
  if constexpr (!kPreintegrated) c = stretch(c, to - from);
  acc.addBehind(c);
  return acc.a >= p.earlyTermination;
}

// Sample s at an end of the chord (see ChordEnds): its segment stretched or
// cut to the chord.
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kTablePower>
inline bool runEnd(const KernelParams& p, const RaySetup& ray, const ChordEnds& ends,
                   std::int64_t s, Accumulator& acc, std::uint64_t& samples) {
  // Plain: the half steps around s; pre-integrated: s to s + 1 (the chord's
  // entry to s is runSpan's segment of its own).
  const double before = kPreintegrated ? 0.0 : 0.5, after = kPreintegrated ? 1.0 : 0.5;
  const double from = double(s) - (s == ends.first && !kPreintegrated ? ends.head : before);
  const double to = double(s) + (s == ends.last ? ends.tail : after);
  return runSegment<T, kShaded, kPreintegrated, kPower>(p, ray, double(s), from, to, acc, samples);
}

// A walk's next chunk, asked for by the batch loop as a chunk ends
// (runSpan, runBatched): next(at) is where the chunk the walk would take
// at `at` ends (`at` when it would take none there: an empty macrocell, or
// past the walk's end), take(exit) tells the walk that the samples up to
// `exit` were taken in this call.
struct NoChunks {
  std::int64_t next(std::int64_t at) const { return at; }
  void take(std::int64_t) const {}
};

// Samples [start, exit) of a visible run: the chord's end samples by
// runEnd, the others in one loop. Returns true at early termination.
// `chunks`: where the batches reach `exit`, the walk's next chunk follows
// on in the same loop when it starts at `exit` and holds a whole batch
// before the chord's last sample (plain batches ending exactly at `exit`;
// pre-integrated ones also from a partial batch).
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kTablePower, typename Chunks = NoChunks>
inline bool runSpan(const KernelParams& p, const RaySetup& ray, const ChordEnds& ends,
                    std::int64_t start, std::int64_t exit, Accumulator& acc, std::uint64_t& samples,
                    [[maybe_unused]] Chunks&& chunks = Chunks{}) {
  if (start == ends.first && start < exit) {
    if constexpr (kPreintegrated) {
      // The chord's entry to its first sample is a segment of its own, and
      // the first sample's segment a segment of the body, between curved
      // nodes. One segment from the entry to the second sample, up to two
      // steps long with the scalar linear along it, was the largest error
      // left where the volume's faces are not empty (CT head at step 1:
      // RMSE 5.8e-3 against 5.0e-3; bench/results/preint_error.md). It is
      // not counted as a sample: the samples are the chord's, one a step.
      std::uint64_t entry = 0;
      if (ends.head > 0 &&
          runSegment<T, kShaded, kPreintegrated, kPower>(p, ray, double(start), double(start) - ends.head,
                                                         double(start), acc, entry))
        return true;
    } else {
      if (runEnd<T, kShaded, kPreintegrated, kPower>(p, ray, ends, start, acc, samples)) return true;
      ++start;
    }
  }
  std::int64_t body = std::min(exit, ends.last);
  if (start < body) {
#ifdef PVR_HAVE_BATCH_KERNEL
    if (p.indices32) {
      // The follow-on chunk's samples after the chord's last one are
      // taken where the walk would take them: by runEnd, below.
      auto more = [&](std::int64_t at) __attribute__((always_inline)) {
        const std::int64_t next = chunks.next(at);
        if (std::min(next, ends.last) < at + 8) return at;
        chunks.take(next);
        exit = next;
        body = std::min(next, ends.last);
        return body;
      };
      if constexpr (kPreintegrated) {
        if (runBatchedPreintegrated<T, kShaded>(p, ray, start, body, acc, samples, more)) return true;
      } else {
        if (runBatched<T, kShaded, kPower>(p, ray, start, body, acc, samples, more)) return true;
      }
    }
#endif
    // What no batch kernel took: the whole run without one (no AVX2, or
    // indices past 32 bits), the pre-integrated run's last 1 to 7 segments
    // without AVX-512; runBatched takes its run's tail itself.
    if (start < body && runScalar<T, kShaded, kPreintegrated, kPower>(p, ray, start, body, acc, samples)) return true;
    start = body;
  }
  if (start == ends.last && start < exit)
    return runEnd<T, kShaded, kPreintegrated, kPower>(p, ray, ends, start, acc, samples);
  return false;
}

// Where the ray goes on from sample k: k itself when k's macrocell is
// visible; else past the empty box ahead of it that `field` proves
// (emptyExit): p.leapField[octantOf(ray)], whose box reaches forward from
// the macrocell in the ray's direction (or the cube around it). o and d:
// the ray's origin and step in float, as the samples'. Each axis's float
// position is monotonic in k, so the samples after k never fall behind
// k's macrocell, where a forward box proves nothing.
[[gnu::always_inline]] inline std::int64_t pastEmpty(const KernelParams& p, const std::uint8_t* field,
                                                     const CubeExit& cube, const float* o, const float* d,
                                                     std::int64_t k, int mcShift) {
  int m[3];
  for (int a = 0; a < 3; ++a)
    m[a] = std::clamp(int(walkMulAdd(float(k), d[a], o[a])) >> mcShift, p.mcFirst[a], p.mcFirst[a] + p.mcCount[a] - 1);
  const int distance = field[macrocellIndex(p, m)];
  if (distance == 0) return k;
  return cube.exit(m, distance, k);
}

}  // namespace kernel

namespace kernel {

// The ray's origin and step in float, as its samples' positions take them.
inline void floatRay(const RaySetup& ray, float o[3], float d[3]) {
  for (int a = 0; a < 3; ++a) {
    o[a] = float(ray.origin[a]);
    d[a] = float(ray.step[a]);
  }
}

// What RayWalk and LevelWalk share: where the walk is (sample k_, to the
// last sample in the visible box end_, and the chord's ends), how it leaps
// past empty space (pastEmpty: the ray's float origin and step, its cube
// exit and distance field), the colour so far, and the step that is a
// look-up past empty space or, where the look-up finds sample k's
// macrocell visible, the walk's own chunk there (Walk::chunkAt(k, ...)).
// walkInLanes makes the look-ups of sixteen walks in vector lanes (toLane)
// and calls chunkAt() and finish() itself.
template <typename Walk>
class LeapingWalk {
 public:
  // One look-up, and a chunk of samples where it finds something visible.
  // False when the ray is done (out holds its result).
  bool step(const KernelParams& p, const RaySetup& ray, int mcShift, RayResult& out) {
    if (const std::int64_t next = pastEmptyFrom(p, k_, mcShift); next != k_) {
      k_ = next;
      return k_ <= end_ || finish(out);
    }
    return static_cast<Walk&>(*this).chunkAt(k_, p, ray, mcShift, out);
  }

  bool finish(RayResult& out) const {
    out.colour = acc_.rgba();
    return false;
  }

  // The sample the walk looks at next.
  std::int64_t at() const { return k_; }
  // Lane i of `lanes` takes this walk's look-ups (walkInLanes).
  template <typename Lanes>
  void toLane(Lanes& lanes, int i) const {
    lanes.set(i, o_, d_, cube_, field_, k_, end_);
  }

 protected:
  void beginAt(const KernelParams& p, const RaySetup& ray, int mcShift, const WalkStart& at) {
    k_ = at.k;
    end_ = at.end;
    ends_ = at.ends;
    floatRay(ray, o_, d_);
    cube_ = CubeExit(ray, mcShift);
    field_ = p.leapField[octantOf(ray)];
  }
  // Where the walk goes on from sample k (pastEmpty).
  std::int64_t pastEmptyFrom(const KernelParams& p, std::int64_t k, int mcShift) const {
    return pastEmpty(p, field_, cube_, o_, d_, k, mcShift);
  }

  std::int64_t k_ = 0, end_ = -1;  // the next sample to look at; the last in the visible box
  ChordEnds ends_;
  Accumulator acc_;

 private:
  CubeExit cube_;
  const std::uint8_t* field_ = nullptr;  // the distance field this ray leaps by (pastEmpty)
  float o_[3], d_[3];                    // the ray's origin and step in float, as the samples'
};

// One ray's walk through the brick, a look-up at a time: castRay takes
// one ray's steps in turn; castRays takes the steps of several rays by
// turns, so that their chains of dependent arithmetic and loads a look-up
// is (position, macrocell, distance, leap) overlap in the CPU.
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kTablePower>
class RayWalk : public LeapingWalk<RayWalk<T, kShaded, kPreintegrated, kPower>> {
  using Base = LeapingWalk<RayWalk>;
  // The base's names, for use unqualified here (a template's base is not searched).
  using Base::k_, Base::end_, Base::ends_, Base::acc_;

 public:
  using Base::finish;

  // Sets the walk up; false when the ray is done already (out holds its
  // result: no sample here, a short chord, or no visible macrocell). The
  // ray's samples outside `span` are known to lie in invisible macrocells
  // (tileSpan(), tile_start.h): the walk starts and ends within it.
  bool start(const KernelParams& p, const RaySetup& ray, int mcShift, const TileSpan& span, RayResult& out) {
    if (!sampleRange(p, ray, first_, last_)) {
      // No sample here; the ray may still cross the domain between two samples.
      double kIn, kOut;
      if (shortChord(p, ray, kIn, kOut)) {
        const double mid = 0.5 * (kIn + kOut);
        int m[3];
        for (int a = 0; a < 3; ++a)
          m[a] = std::clamp(int(ray.origin[a] + mid * ray.step[a]) >> mcShift, p.mcFirst[a],
                            p.mcFirst[a] + p.mcCount[a] - 1);
        out.hit = true;
        if (p.distance[macrocellIndex(p, m)] == 0)
          runSegment<T, kShaded, kPreintegrated, kPower>(p, ray, mid, kIn, kOut, acc_, out.samples);
        out.colour = acc_.rgba();
      }
      return false;
    }
    out.hit = true;
    // The walk starts and ends at the visible box; a ray that misses it
    // costs nothing more.
    WalkStart at;
    if (!walkStart(p, ray, span, first_, last_, at)) return false;
    begin(p, ray, mcShift, at);
    return true;
  }

  // Sets the walk up from where it starts (start(), or startInLanes in
  // start_lanes.h, which finds the same for eight rays at once).
  void begin(const KernelParams& p, const RaySetup& ray, int mcShift, const WalkStart& at) {
    this->beginAt(p, ray, mcShift, at);
    first_ = at.first;
    last_ = at.last;
    done_ = first_;
    leapFrom_ = std::numeric_limits<std::int64_t>::min();
    chunk_ = visibleChunk(ray);
  }

  // step() after a look-up that found sample k's macrocell visible (k at
  // or after where the walk was, past empty space, and within its end).
  bool chunkAt(std::int64_t k, const KernelParams& p, const RaySetup& ray, int mcShift, RayResult& out) {
    k_ = k;
    // Something visible: sample a fixed chunk and look again. Samples that
    // run on into an empty macrocell add nothing, and a chunk costs one
    // look-up where walking the visible macrocells exactly (a 3D DDA)
    // mispredicted a branch at nearly every macrocell face.
    std::int64_t exit = std::min(last_ + 1, k_ + chunk_);
    // A pre-integrated segment runs from one sample to the next: when the
    // sample before this run was skipped, its segment ends in here.
    std::int64_t start = k_;
    if constexpr (kPreintegrated) start = (done_ < k_) ? std::max(first_, k_ - 1) : k_;
    // The chunks after this one, while each starts in a visible macrocell,
    // follow on in the batch loop without leaving it: each entry cost the
    // loop's setup and a first batch fetched with nothing to overlap it
    // (peer scene: 2 % less CPU a frame, bench/results/plain.txt, section
    // 4). The same look-ups and the same chunks as one step each, so the
    // same samples and bits.
    struct {
      RayWalk& walk;
      const KernelParams& p;
      int mcShift;
      std::int64_t& exit;
      std::int64_t next(std::int64_t at) const {
        if (at > walk.end_) return at;
        if (const std::int64_t past = walk.pastEmptyFrom(p, at, mcShift); past != at) {
          walk.leapFrom_ = at;
          walk.leapTo_ = past;
          return at;
        }
        return std::min(walk.last_ + 1, at + walk.chunk_);
      }
      void take(std::int64_t to) const { exit = to; }
    } chunks{*this, p, mcShift, exit};
    if (runSpan<T, kShaded, kPreintegrated, kPower>(p, ray, ends_, start, exit, acc_, out.samples, chunks))
      return finish(out);
    done_ = exit;
    // Where the batch loop asked for a chunk at `exit` and the look-up
    // found it empty, the leap it found is taken here: the next step would
    // make the same look-up at `exit` again. The same leaps and samples, one
    // step fewer (16 % fewer steps on the peer scene, 3 % less CPU a frame;
    // CT head shaded 14 %, 1 %: bench/results/shade.txt, session 11).
    k_ = exit == leapFrom_ ? leapTo_ : exit;
    return k_ <= end_ || finish(out);
  }

  // Where the walk started (begin), before it took a step.
  WalkStart started() const { return {first_, last_, k_, end_, ends_}; }

 private:
  std::int64_t first_ = 0, last_ = -1;  // the ray's samples in the brick
  std::int64_t done_ = 0;               // next sample not yet composited or skipped
  std::int64_t chunk_ = 0;
  // The last look-up the batch loop made that found no chunk: at leapFrom_,
  // leap to leapTo_ (walks go forward, so an older one is never met again).
  std::int64_t leapFrom_ = std::numeric_limits<std::int64_t>::min(), leapTo_ = 0;
};

// One ray by a Walk (RayWalk, or cast_ray_levels.h's LevelWalk): its
// steps in turn.
template <typename Walk>
RayResult castWalk(const KernelParams& p, const RaySetup& ray, int mcShift, const TileSpan& span) {
  RayResult out;
  Walk walk;
  if (walk.start(p, ray, mcShift, span, out))
    while (walk.step(p, ray, mcShift, out)) {
    }
  return out;
}

// Rays rays[0, n) into out[0, n), n <= kRaysAtOnce, each as castWalk
// would take it (with the same `span`): their walks by turns, a step of
// each, with the look-ups of all of them in the lanes of one vector where
// the CPU has AVX-512 (walk_lanes.h), and their starts there eight at once
// too (start_lanes.h).
template <typename Walk>
void castWalks(const KernelParams& p, const RaySetup* rays, int n, int mcShift, const TileSpan& span,
               RayResult* out) {
  Walk walk[kRaysAtOnce];
  bool going[kRaysAtOnce];
#ifdef PVR_HAVE_WALK_LANES
  const int left = startInLanes(p, rays, n, mcShift, span, walk, going, out);
  if (left > 0) walkInLanes(p, rays, n, mcShift, walk, going, out);
#else
  int left = 0;
  for (int i = 0; i < n; ++i) {
    out[i] = RayResult{};
    going[i] = walk[i].start(p, rays[i], mcShift, span, out[i]);
    left += going[i];
  }
  while (left > 0) {
    for (int i = 0; i < n; ++i) {
      if (!going[i]) continue;
      going[i] = walk[i].step(p, rays[i], mcShift, out[i]);
      left -= !going[i];
    }
  }
#endif
}

}  // namespace kernel

// One ray; its samples outside `span` lie in invisible macrocells
// (tileSpan(), tile_start.h; by default nothing is known).
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kernel::kTablePower>
RayResult castRay(const KernelParams& p, const RaySetup& ray, int mcShift, const kernel::TileSpan& span = {}) {
  return kernel::castWalk<kernel::RayWalk<T, kShaded, kPreintegrated, kPower>>(p, ray, mcShift, span);
}

// Rays rays[0, n) into out[0, n), n <= kRaysAtOnce, each as castRay
// would take it (with the same `span`), several at once (castWalks).
template <typename T, bool kShaded, bool kPreintegrated, int kPower = kernel::kTablePower>
void castRays(const KernelParams& p, const RaySetup* rays, int n, int mcShift, const kernel::TileSpan& span,
              RayResult* out) {
  kernel::castWalks<kernel::RayWalk<T, kShaded, kPreintegrated, kPower>>(p, rays, n, mcShift, span, out);
}

}  // namespace pvr::core
