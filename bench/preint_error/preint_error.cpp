// preint_error: which approximation of pre-integration makes its error.
//
//   preint_error SCENE.json [--steps LIST] [--error-size N] [--substeps N] [--threads N] [--no-skip]
//
// Renders the scene at each step (voxels) with a model of the
// pre-integrated ray caster in double, in which each of its approximations
// can be replaced by the exact computation, one at a time or together, and
// prints each variant's RMSE (linear RGBA) against the bench's reference
// (tests/renderer/reference.h, dt = smallest spacing / 64), beside the real
// caster's plain and pre-integrated errors at the same step and size. Every
// segment [t_k, t_k+1] of the caster (samples at t = k h along the ray, the
// chord's two end segments cut to the chord, as kernel.h's ChordEnds) is
// integrated on --substeps midpoint substeps per voxel, with
//   scalar  raw:     linear between the two samples
//           curved:  linear between the caster's curvature-corrected nodes
//                    (kernel::curvedNode, clamped to the sample's cell range;
//                    the chord's end segments raw, as the caster)
//           cub2:    two half segments, the midpoint from the cubic through
//                    four samples, all three nodes corrected as curvedNode
//                    does at h / 2 (samples k - 2 .. k + 3)
//           cubmid:  two half segments through the raw samples and the
//                    cubic's midpoint
//           facecut: linear between the exact field at the segment's ends
//                    and where it crosses cell faces (the field's kinks)
//           tri:     the trilinear field itself
//   tf      table:   tau and c tau linear between the 4096 nodes of
//                    PreintegratedTable (what the caster integrates)
//           fine:    the same at 64 times as many nodes (the transfer
//                    function itself, to ~1e-4 of the table's error)
//   colour  mean:    the segment emits its extinction-weighted mean colour
//                    times 1 - exp(-D) (no self-attenuation: the caster)
//           comp:    the substeps composited (exact self-attenuation)
//   lit by  gauss2:  the emission's centroid -+ its spread as
//                    preint::segment() estimates them, two colours averaged
//                    (preint_lighting.h: the caster)
//           exact:   every substep lit at its own gradient
//           faces:   lighting linear between the ends and the cell-face
//                    crossings (comp only)
//           quad3:   lighting quadratic through the segment's front, middle
//                    and back against the emission's first two moments
//           gaussM:  gauss2 at the emission's exact centroid and spread
// so "curved table mean gauss2" is the caster (its RMSE should match the
// caster's) and "tri fine comp exact" is the reference integrated on the
// caster's segments. Unshaded scenes print no light column. Rays run to the
// end (no early termination, as the bench's scenes). Not a test: a tool
// for bench/results/preint_error.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "measure.h"
#include "raycast/kernel.h"
#include "reference.h"
#include "transfer.h"

namespace {

using namespace pvr;

constexpr int kPaths = 6, kTfs = 2, kColours = 2, kLights = 5;
constexpr int kVariants = kPaths * kTfs * kColours * kLights;
const char* kPathName[kPaths] = {"raw", "curved", "cub2", "cubmid", "facecut", "tri"};
const char* kTfName[kTfs] = {"table", "fine"};
const char* kColourName[kColours] = {"mean", "comp"};
const char* kLightName[kLights] = {"gauss2", "exact", "faces", "quad3", "gaussM"};
int variant(int p, int q, int c, int l) { return ((p * kTfs + q) * kColours + c) * kLights + l; }

// tau and c tau, linear between nodes x = i / refine of the table coordinate.
struct NodeTable {
  int refine = 1;
  std::vector<std::array<double, 4>> node;  // tau, k[3]
  std::vector<int> visibleBelow;            // nodes below i with tau > 0
  float scale = 0, offset = 0;
  void lookup(double s, double out[4]) const {
    const double last = double(node.size() - 1);
    const double x = std::clamp((s * double(scale) + double(offset)) * refine, 0.0, last);
    const std::size_t i = std::min(std::size_t(x), node.size() - 2);
    const double w = x - double(i);
    for (int c = 0; c < 4; ++c) out[c] = node[i][c] + w * (node[i + 1][c] - node[i][c]);
  }
  // Any extinction for scalars in [lo, hi]?
  bool visible(double lo, double hi) const {
    const double last = double(node.size() - 1);
    const double a = std::clamp((lo * double(scale) + double(offset)) * refine, 0.0, last);
    const double b = std::clamp((hi * double(scale) + double(offset)) * refine, 0.0, last);
    const std::size_t i = std::size_t(std::floor(a)), j = std::min(std::size_t(std::ceil(b)), node.size() - 1);
    return visibleBelow[j + 1] - visibleBelow[i] > 0;
  }
};

NodeTable makeTable(const core::TransferFunctionSpec& tf, const core::PreintegralTables& t, int refine) {
  NodeTable n;
  n.refine = refine;
  n.scale = t.scale;
  n.offset = t.offset;
  const std::size_t count = std::size_t(t.entries - 1) * refine + 1;
  n.node.resize(count);
  n.visibleBelow.assign(count + 1, 0);
  for (std::size_t i = 0; i < count; ++i) {
    const double x = double(i) / refine;
    const core::Medium m = core::evaluateMedium(tf, (x - double(t.offset)) / double(t.scale));
    const double tau = std::min(m.tau, 1e6);
    n.node[i] = {tau, tau * m.r, tau * m.g, tau * m.b};
    n.visibleBelow[i + 1] = n.visibleBelow[i] + (tau > 0 ? 1 : 0);
  }
  return n;
}

struct Shader {
  bool enabled = false;
  core::ShadingSpec spec;
  core::Vec3 light, halfway;
  const core::ReferenceVolume* volume = nullptr;
  // lit factor and specular per unit opacity at index position u.
  void at(core::Vec3 u, double& lit, double& spec) const {
    lit = 1;
    spec = 0;
    if (!enabled) return;
    const core::Vec3 g = volume->gradient(u);
    const double gg = dot(g, g);
    lit = this->spec.ambient + this->spec.diffuse;
    if (gg > 1e-20 && std::isfinite(gg)) {
      const core::Vec3 nrm = g / std::sqrt(gg);
      lit = this->spec.ambient + this->spec.diffuse * std::abs(dot(nrm, light));
      spec = this->spec.specular * std::pow(std::abs(dot(nrm, halfway)), this->spec.shininess);
    }
  }
};

struct Acc {
  double r = 0, g = 0, b = 0, T = 1;
  void add(double cr, double cg, double cb, double a) {
    r += T * cr;
    g += T * cg;
    b += T * cb;
    T *= 1 - a;
  }
};

struct Model {
  const core::ReferenceVolume* volume;
  const NodeTable* table[kTfs];
  Shader shader;
  double h = 0;          // world step
  int substepsPerVoxel = 64;
  double voxel = 1;

  core::Vec3 index(const core::Ray& ray, double t) const {
    const core::Vec3 w = ray.origin + ray.direction * t;
    const core::GridGeometry& g = volume->grid();
    core::Vec3 u;
    for (int a = 0; a < 3; ++a) u[a] = (w[a] - g.origin[a]) / g.spacing[a];
    return u;
  }
  double sample(const core::Ray& ray, double t) const {
    core::Vec3 u = index(ray, t);
    const core::GridGeometry& g = volume->grid();
    for (int a = 0; a < 3; ++a) u[a] = std::clamp(u[a], 0.0, double(g.dims[a] - 1));
    return volume->value(u);
  }
  // Node range of the cell the caster's aroundRange() reads at t.
  void cellRange(const core::Ray& ray, double t, double& lo, double& hi) const {
    const core::Vec3 u = index(ray, t);
    const core::GridGeometry& g = volume->grid();
    std::int64_t c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp<std::int64_t>(std::int64_t(std::clamp(u[a], 0.0, double(g.dims[a] - 1))), 0, g.dims[a] - 2);
    lo = 1e300;
    hi = -1e300;
    for (int n = 0; n < 8; ++n) {
      const double v = volume->node(c[0] + (n & 1), c[1] + ((n >> 1) & 1), c[2] + ((n >> 2) & 1));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  // Nodes around the segment [ta, tb]: bounds every path's scalar on it.
  void segmentRange(const core::Ray& ray, double ta, double tb, double& lo, double& hi) const {
    const core::Vec3 a = index(ray, ta), b = index(ray, tb);
    const core::GridGeometry& g = volume->grid();
    std::int64_t from[3], to[3];
    for (int x = 0; x < 3; ++x) {
      const double l = std::clamp(std::min(a[x], b[x]), 0.0, double(g.dims[x] - 1));
      const double u = std::clamp(std::max(a[x], b[x]), 0.0, double(g.dims[x] - 1));
      from[x] = std::int64_t(std::floor(l));
      to[x] = std::min<std::int64_t>(std::int64_t(std::ceil(u)), g.dims[x] - 1);
    }
    lo = 1e300;
    hi = -1e300;
    for (std::int64_t k = from[2]; k <= to[2]; ++k)
      for (std::int64_t j = from[1]; j <= to[1]; ++j)
        for (std::int64_t i = from[0]; i <= to[0]; ++i) {
          const double v = volume->node(i, j, k);
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
  }

  void ray(const core::Ray& ray, std::array<Acc, kVariants>& acc) const {
    const core::Chord chord = core::domainChord(volume->grid(), ray);
    if (!chord.hit || !(chord.t1 > chord.t0)) return;
    const std::int64_t first = std::int64_t(std::ceil(chord.t0 / h)), last = std::int64_t(std::floor(chord.t1 / h));
    std::vector<double> cuts;
    if (first > last) {
      cuts = {chord.t0, chord.t1};
    } else {
      if (double(first) * h > chord.t0) cuts.push_back(chord.t0);
      for (std::int64_t k = first; k <= last; ++k) cuts.push_back(double(k) * h);
      if (chord.t1 > double(last) * h) cuts.push_back(chord.t1);
    }
    auto curved = [&](std::int64_t k) {
      const double t = double(k) * h;
      const double before = sample(ray, t - h), at = sample(ray, t), after = sample(ray, t + h);
      double lo, hi;
      cellRange(ray, t, lo, hi);
      // The caster's own node, in float.
      return double(core::kernel::curvedNode<float>(float(before), float(at), float(after), float(lo), float(hi)));
    };
    for (std::size_t s = 0; s + 1 < cuts.size(); ++s) {
      const double ta = cuts[s], tb = cuts[s + 1];
      double lo, hi;
      segmentRange(ray, ta, tb, lo, hi);
      if (!table[0]->visible(lo, hi) && !table[1]->visible(lo, hi)) continue;
      // The caster's chord-end segments (runSpan, runEnd), the entry to the
      // first sample and the last sample to the exit, between raw samples;
      // the others between curved nodes.
      const bool onNodes = first <= last && ta >= (double(first) - 0.5) * h && tb <= (double(last) + 0.5) * h;
      const double ra = sample(ray, ta), rb = sample(ray, tb);
      double ca = ra, cb = rb, na = ra, nb = rb, mid = sample(ray, 0.5 * (ta + tb)), nm = mid;
      if (onNodes) {
        ca = curved(std::llround(ta / h));
        cb = curved(std::llround(tb / h));
        const double sm = sample(ray, ta - h), sp = sample(ray, tb + h);
        mid = (-sm + 9 * ra + 9 * rb - sp) / 16;
        // cub2: samples at h / 2, the midpoints from the cubic through four
        // samples, then curvature-corrected at h / 2 as curvedNode() does at h.
        const double smm = sample(ray, ta - 2 * h), spp = sample(ray, tb + 2 * h);
        const double mBefore = (-smm + 9 * sm + 9 * ra - rb) / 16, mAfter = (-ra + 9 * rb + 9 * sp - spp) / 16;
        na = ra - (mBefore - 2 * ra + mid) / 12;
        nb = rb - (mid - 2 * rb + mAfter) / 12;
        nm = mid - (ra - 2 * mid + rb) / 12;
      }
      // The cell-face crossings inside the segment: the knots of the
      // trilinear field along the ray (C0 there, cubic between).
      std::vector<double> knots = {ta};
      {
        const core::GridGeometry& g = volume->grid();
        for (int a = 0; a < 3; ++a) {
          if (ray.direction[a] == 0) continue;
          const double ua = index(ray, ta)[a], ub = index(ray, tb)[a];
          for (double n = std::floor(std::min(ua, ub)) + 1; n < std::max(ua, ub); n += 1)
            knots.push_back((n * g.spacing[a] + g.origin[a] - ray.origin[a]) / ray.direction[a]);
        }
        std::sort(knots.begin() + 1, knots.end());
        knots.push_back(tb);
      }
      std::vector<double> knotValue(knots.size()), knotLit(knots.size()), knotSpec(knots.size());
      for (std::size_t n = 0; n < knots.size(); ++n) {
        knotValue[n] = sample(ray, knots[n]);
        shader.at(index(ray, knots[n]), knotLit[n], knotSpec[n]);
      }
      auto alongKnots = [&](double t, const std::vector<double>& v) {
        std::size_t n = 1;
        while (n + 1 < knots.size() && knots[n] < t) ++n;
        const double span = knots[n] - knots[n - 1];
        const double w = span > 0 ? (t - knots[n - 1]) / span : 0.0;
        return v[n - 1] + w * (v[n] - v[n - 1]);
      };
      const double endLit[2] = {knotLit.front(), knotLit.back()}, endSpec[2] = {knotSpec.front(), knotSpec.back()};
      const int m = std::max(4, int(std::ceil((tb - ta) / voxel * substepsPerVoxel)));
      const double dt = (tb - ta) / m;
      // Per path and table: D, K (unlit), KL (lit), the extinction's first
      // moment, and composited C, CL, transmittance.
      double D[kPaths][kTfs] = {}, M[kPaths][kTfs] = {}, K[kPaths][kTfs][3] = {}, KL[kPaths][kTfs][3] = {};
      double W[kPaths][kTfs][3] = {};  // the emission's moments: sum of T a, T a f, T a f^2
      double C[kPaths][kTfs][3] = {}, CL[kPaths][kTfs][3] = {}, CK[kPaths][kTfs][3] = {},
             Tr[kPaths][kTfs];
      for (auto& row : Tr)
        for (double& x : row) x = 1;
      for (int j = 0; j < m; ++j) {
        const double f = (j + 0.5) / m;
        const double t = ta + f * (tb - ta);
        const double s[kPaths] = {ra + f * (rb - ra), ca + f * (cb - ca),
                                  f < 0.5 ? na + 2 * f * (nm - na) : nm + (2 * f - 1) * (nb - nm),
                                  f < 0.5 ? ra + 2 * f * (mid - ra) : mid + (2 * f - 1) * (rb - mid),
                                  alongKnots(t, knotValue), sample(ray, t)};
        double lit, spec;
        shader.at(index(ray, t), lit, spec);
        // Lighting interpolated linearly between the knots, and between the ends only.
        const double litK = alongKnots(t, knotLit), specK = alongKnots(t, knotSpec);
        for (int p = 0; p < kPaths; ++p)
          for (int q = 0; q < kTfs; ++q) {
            double e[4];
            table[q]->lookup(s[p], e);
            if (!(e[0] > 0)) continue;
            D[p][q] += e[0] * dt;
            M[p][q] += e[0] * f * dt;
            const double a = -std::expm1(-e[0] * dt);
            for (int c = 0; c < 3; ++c) {
              K[p][q][c] += e[1 + c] * dt;
              KL[p][q][c] += (e[1 + c] * lit + e[0] * spec) * dt;
              C[p][q][c] += Tr[p][q] * a * e[1 + c] / e[0];
              CL[p][q][c] += Tr[p][q] * a * (e[1 + c] * lit + e[0] * spec) / e[0];
              CK[p][q][c] += Tr[p][q] * a * (e[1 + c] * litK + e[0] * specK) / e[0];
            }
            W[p][q][0] += Tr[p][q] * a;
            W[p][q][1] += Tr[p][q] * a * f;
            W[p][q][2] += Tr[p][q] * a * f * f;
            Tr[p][q] *= 1 - a;
          }
      }
      for (int p = 0; p < kPaths; ++p)
        for (int q = 0; q < kTfs; ++q) {
          if (!(D[p][q] > 0)) continue;
          const double depth = D[p][q];
          const double alpha = -std::expm1(-depth);
          // Two lighting points as preint::segment() places them.
          double avgLit = 1, avgSpec = 0, quadLit = 1, quadSpec = 0, mLit = 1, mSpec = 0;
          if (shader.enabled) {
            double at = M[p][q] / D[p][q];
            at += depth < 1e-3 ? -depth / 12 : 1 / depth - 1 / std::expm1(depth) - 0.5;
            at = std::clamp(at, 0.0, 1.0);
            const double spread = std::sqrt(std::max(core::preint::emissionVariance(depth, alpha), 0.0));
            double l1, s1, l2, s2;
            shader.at(index(ray, ta + (tb - ta) * std::max(at - spread, 0.0)), l1, s1);
            shader.at(index(ray, ta + (tb - ta) * std::min(at + spread, 1.0)), l2, s2);
            avgLit = 0.5 * (l1 + l2);
            avgSpec = 0.5 * (s1 + s2);
            // quad3: lighting quadratic through the segment's front, middle
            // and back (front and back shared with the neighbours: two new
            // gradients a segment, as gauss2), integrated against the
            // emission's first two moments.
            double lm, sm;
            shader.at(index(ray, 0.5 * (ta + tb)), lm, sm);
            const double e1 = at, e2 = at * at + spread * spread;
            const double B[3] = {2 * e2 - 3 * e1 + 1, -4 * (e2 - e1), 2 * e2 - e1};
            quadLit = B[0] * endLit[0] + B[1] * lm + B[2] * endLit[1];
            quadSpec = B[0] * endSpec[0] + B[1] * sm + B[2] * endSpec[1];
            // gaussM: the two Gauss points from the emission's exact moments.
            const double mu = W[p][q][1] / W[p][q][0];
            const double sd = std::sqrt(std::max(W[p][q][2] / W[p][q][0] - mu * mu, 0.0));
            double g1, h1, g2, h2;
            shader.at(index(ray, ta + (tb - ta) * std::max(mu - sd, 0.0)), g1, h1);
            shader.at(index(ray, ta + (tb - ta) * std::min(mu + sd, 1.0)), g2, h2);
            mLit = 0.5 * (g1 + g2);
            mSpec = 0.5 * (h1 + h2);
          }
          const double w = alpha / depth;
          const double aComp = 1 - Tr[p][q];
          for (int l = 0; l < kLights; ++l) {
            double mean[3], comp[3];
            for (int c = 0; c < 3; ++c) {
              if (l == 0 || l >= 3) {
                const double L = l == 0 ? avgLit : l == 3 ? quadLit : mLit, S = l == 0 ? avgSpec : l == 3 ? quadSpec : mSpec;
                mean[c] = K[p][q][c] * w * L + S * alpha;
                comp[c] = C[p][q][c] * L + S * aComp;
              } else {
                // The mean-colour model lit by the other rules: not modelled.
                mean[c] = KL[p][q][c] * w;
                comp[c] = l == 1 ? CL[p][q][c] : CK[p][q][c];
              }
            }
            acc[variant(p, q, 0, l)].add(mean[0], mean[1], mean[2], alpha);
            acc[variant(p, q, 1, l)].add(comp[0], comp[1], comp[2], aComp);
          }
        }
    }
  }
};

std::vector<double> parseList(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::stod(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenePath;
  std::vector<double> steps = {1, 0.5, 0.25, 0.125};
  int edge = 128, substeps = 64, threads = 2;
  bool skip = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "preint_error: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--steps") steps = parseList(next());
    else if (a == "--error-size") edge = std::stoi(next());
    else if (a == "--substeps") substeps = std::stoi(next());
    else if (a == "--threads") threads = std::stoi(next());
    else if (a == "--no-skip") skip = false;
    else if (a == "--help" || a == "-h") {
      std::puts("preint_error SCENE.json [--steps LIST] [--error-size N (128)] [--substeps N (64)] [--threads N (2)] [--no-skip (the caster without empty-space skipping)]");
      return 0;
    } else scenePath = a;
  }
  if (scenePath.empty()) {
    std::fprintf(stderr, "preint_error: no scene given (--help)\n");
    return 2;
  }
  core::ThreadPool pool(threads);
  const bench::BenchScene scene(scenePath);
  const core::Scene& s = scene.scene();
  bench::ReferenceSettings rs;
  rs.maxEdge = edge;
  rs.cacheDir = PVR_BENCH_CACHE;
  const bench::Reference ref = bench::computeReference(scene, rs, pool);
  std::printf("%s: %s, error size %dx%d, reference dt %.4g (%s)\n", scenePath.c_str(), scene.describe().c_str(),
              ref.size.width, ref.size.height, ref.dt, ref.fromCache ? "cached" : "computed");

  const core::ReferenceVolume volume(scene.volume());
  const core::TransferFunctionSpec& tf = s.volumes.front().transfer;
  const core::PreintegratedTable pt(tf);
  const NodeTable coarse = makeTable(tf, pt.tables(), 1), fine = makeTable(tf, pt.tables(), 64);
  const core::Camera camera(s.camera, ref.size.width, ref.size.height);
  const bool shaded = s.shading.enabled;
  const int lights = shaded ? kLights : 1;

  for (double stepVoxels : steps) {
    const double h = stepVoxels * scene.voxel();
    bench::Case c;
    c.step = h;
    c.skipEmpty = skip;
    const double plain = bench::measureCase(scene, c, ref, 0, 0, 0, pool).error.rmse;
    c.preintegrated = true;
    const bench::CaseResult caster = bench::measureCase(scene, c, ref, 0, 0, 0, pool);

    Model model{&volume, {&coarse, &fine}, {}, core::preint::sampleSpacing(h, scene.voxel()), substeps, scene.voxel()};
    model.shader.enabled = shaded;
    model.shader.spec = s.shading;
    model.shader.light = core::referenceLight(camera, s.shading);
    model.shader.volume = &volume;
    std::vector<core::Image> images(kVariants, core::Image::fullFrame(ref.size.width, ref.size.height));
    pool.parallelFor(std::size_t(ref.size.height), [&](std::size_t row, int) {
      Model local = model;
      for (int x = 0; x < ref.size.width; ++x) {
        const core::Ray ray = camera.ray(x, int(row));
        const core::Vec3 sum = local.shader.light - ray.direction;
        local.shader.halfway = length(sum) > 1e-9 ? normalize(sum) : local.shader.light;
        std::array<Acc, kVariants> acc;
        local.ray(ray, acc);
        for (int v = 0; v < kVariants; ++v)
          images[v].at(x, int(row)) = {float(acc[v].r), float(acc[v].g), float(acc[v].b), float(1 - acc[v].T)};
      }
    });
    std::printf("\nstep %g voxel: caster plain %.3e, caster preint %.3e (RMSE, linear RGBA)\n", stepVoxels, plain,
                caster.error.rmse);
    std::printf("  %-7s %-6s %-5s %s\n", "scalar", "tf", "colour", shaded ? "RMSE lit by: gauss2 / exact / faces / quad3 / gaussM" : "RMSE");
    for (int p = 0; p < kPaths; ++p)
      for (int q = 0; q < kTfs; ++q)
        for (int col = 0; col < kColours; ++col) {
          std::printf("  %-7s %-6s %-6s", kPathName[p], kTfName[q], kColourName[col]);
          for (int l = 0; l < lights; ++l) {
            if (col == 0 && l == 2) {  // the mean colour lit between knots: not modelled
              std::printf(" %9s", "-");
              continue;
            }
            std::printf(" %.3e", core::compareImages(images[variant(p, q, col, l)], ref.image).rmse);
          }
          if (p == 1 && q == 0 && col == 0) {
            // Alpha alone: the extinction's integral, without colour or lighting.
            auto alphaOnly = [](core::Image image) {
              for (core::Rgba& c : image.pixels()) c.r = c.g = c.b = 0;
              return image;
            };
            std::printf("   <- the caster's model (model vs caster %.1e, alpha alone %.1e)",
                        core::compareImages(images[variant(p, q, col, 0)], caster.image).rmse,
                        core::compareImages(alphaOnly(images[variant(p, q, col, 0)]), alphaOnly(caster.image)).rmse);
          }
          std::printf("\n");
        }
    std::fflush(stdout);
  }
  (void)kLightName;
  return 0;
}
