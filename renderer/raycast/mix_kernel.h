// castMixedRay: one ray through several volumes that may overlap.
//
// Each volume keeps its own grid, index space and extinction table
// (ExtinctionTable, transfer.h); sample k of the ray lies at world distance
// k * h for all of them, and stands for the ray's slot [k - 0.5, k + 0.5].
// The ray is cut at every volume's entry and exit (its chord through that
// volume's domain): a slot holding a cut is split there into pieces, each
// with a fixed set of volumes, so no piece straddles a domain face. Each
// volume's part of the ray is covered by its own samples exactly as
// ChordEnds covers one volume's chord: its first sample stands for the
// stretch from its entry, its last for the stretch to its exit, and a
// chord holding no sample is one sample at its midpoint. So a volume is
// sampled at the same points, with the same lengths, whatever the other
// volumes do, and a transparent one changes nothing.
//
// In a piece the volumes present add their optical depths and their
// depth-weighted colours, (sum c_i d_i, sum d_i) per step; a piece w
// steps long has opacity 1 - exp(-w D) and colour (sum c_i d_i) / D
// times that opacity: the emission-absorption model of overlapping media
// (docs/scene.md, "Several volumes"). Pieces are composited front to back.
//
// Empty-space skipping works on the combined classification: between cuts
// a sample is skipped only while every volume present there is in an
// empty macrocell, by the shortest leap any of them allows. A visible run
// is sampled in chunks of kVisibleChunk: each volume adds its part of the
// chunk through its own sampler (instantiated per scalar type and
// shading), then the chunk is composited; the per-sample loops allocate
// nothing, lock nothing and branch on no configuration.
#pragma once

#include <cstdint>

#include "../brick.h"
#include "kernel.h"

namespace pvr::core {

// At most this many volumes mix in one ray (the per-ray arrays live on the stack).
inline constexpr int kMaxMixedVolumes = 16;

// Adds (c d, d) of one volume, as (r, g, b, a), for `count` samples at
// k0, k0 + 1, ... into out[4 j .. 4 j + 3]; shaded, the colour is lit by
// that volume's own gradient. Non-finite values add nothing.
using MixSampler = void (*)(const KernelParams& p, const RaySetup& ray, double k0, int count, float* out);

MixSampler pickMixSampler(ScalarType type, bool shaded);

// What a volume brings to a frame: its brick's kernel parameters with the
// ExtinctionTable as the table, and its sampler.
struct MixedVolume {
  KernelParams params;
  MixSampler sample = nullptr;
};

// Which parts of a ray a brick of a decomposed scene composites (region.h):
// sample k lies at world position origin + k * step, and a piece of the
// ray belongs to the region that holds its midpoint (a slot without cuts:
// its sample). A volume's sample standing for an owned piece lies within
// a step of the region, which volumeBoxFor() stores.
struct MixOwnership {
  double origin[3], step[3];
  double lo[3], hi[3];  // the region, half-open; infinite faces bound nothing

  bool owns(double k) const {
    for (int a = 0; a < 3; ++a) {
      const double x = origin[a] + k * step[a];
      if (!(x >= lo[a] && x < hi[a])) return false;
    }
    return true;
  }
};

// `rays[i]` is the camera ray in volume i's index space (raySetup), n <=
// kMaxMixedVolumes; every volume has cells on every axis. With `own` null
// the whole ray is composited and every volume is whole; otherwise only
// the pieces `own` owns, and a volume whose sampler is null (no data near
// the region) only cuts the ray.
RayResult castMixedRay(const MixedVolume* volumes, const RaySetup* rays, int n, float earlyTermination,
                       int mcShift, const MixOwnership* own = nullptr);

}  // namespace pvr::core
