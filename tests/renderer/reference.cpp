#include "reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <type_traits>

#include "error.h"

namespace pvr::core {

ReferenceVolume::ReferenceVolume(const Brick& whole) : grid_(whole.grid()) {
  if (whole.stored() != grid_.allNodes())
    throw Error(ErrorCode::kInvalidArgument,
                "ReferenceVolume: the brick stores " + toString(whole.stored()) +
                    ", not the whole grid " + toString(grid_.allNodes()));
  v_.resize(std::size_t(grid_.allNodes().nodeCount()));
  dispatchScalar(whole.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* src = whole.as<T>();
    for (std::size_t i = 0; i < v_.size(); ++i) v_[i] = double(src[i]);
    return 0;
  });
}

double ReferenceVolume::value(Vec3 u) const {
  // Cell and weights per axis; an axis one node thick has no second node.
  std::int64_t c[3], next[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const std::int64_t lastCell = std::max<std::int64_t>(0, grid_.dims[a] - 2);
    c[a] = std::clamp(std::int64_t(std::floor(u[a])), std::int64_t(0), lastCell);
    next[a] = grid_.dims[a] > 1 ? 1 : 0;
    f[a] = grid_.dims[a] > 1 ? u[a] - double(c[a]) : 0.0;
  }
  auto at = [&](int dx, int dy, int dz) {
    return node(c[0] + dx * next[0], c[1] + dy * next[1], c[2] + dz * next[2]);
  };
  // x, then y, then z, as the caster interpolates.
  const double c00 = at(0, 0, 0) + f[0] * (at(1, 0, 0) - at(0, 0, 0));
  const double c10 = at(0, 1, 0) + f[0] * (at(1, 1, 0) - at(0, 1, 0));
  const double c01 = at(0, 0, 1) + f[0] * (at(1, 0, 1) - at(0, 0, 1));
  const double c11 = at(0, 1, 1) + f[0] * (at(1, 1, 1) - at(0, 1, 1));
  const double c0 = c00 + f[1] * (c10 - c00);
  const double c1 = c01 + f[1] * (c11 - c01);
  return c0 + f[2] * (c1 - c0);
}

Vec3 ReferenceVolume::gradient(Vec3 u) const {
  Vec3 inside;
  for (int a = 0; a < 3; ++a) inside[a] = std::clamp(u[a], 0.0, double(grid_.dims[a] - 1));
  Vec3 g;
  for (int a = 0; a < 3; ++a) {
    Vec3 up = inside, dn = inside;
    up[a] = std::min(inside[a] + 1.0, double(grid_.dims[a] - 1));
    dn[a] = std::max(inside[a] - 1.0, 0.0);
    const double dist = up[a] - dn[a];
    g[a] = dist > 0 ? (value(up) - value(dn)) / (dist * grid_.spacing[a]) : 0.0;
  }
  return g;
}

Chord domainChord(const GridGeometry& grid, const Ray& ray) {
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] < 2) return {};
  const Vec3 lo = grid.domainMin(), hi = grid.domainMax();
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double o = ray.origin[a], d = ray.direction[a];
    if (d == 0) {
      // Parallel to this pair of faces: inside the closed slab or nowhere.
      if (o < lo[a] || o > hi[a]) return {};
      continue;
    }
    double ta = (lo[a] - o) / d, tb = (hi[a] - o) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 <= t1)) return {};
  return {t0, t1, true};
}

Vec3 referenceLight(const Camera& camera, const ShadingSpec& shading) {
  return normalize(camera.toWorld(shading.lightDirection));
}

RgbaD integrateRay(const ReferenceVolume& volume, const TransferFunctionSpec& tf, const Ray& ray,
                   Vec3 lightWorld, const ReferenceOptions& options) {
  return integrateRay({ReferenceLayer{&volume, &tf}}, ray, lightWorld, options);
}

Image renderReference(const ReferenceVolume& volume, const TransferFunctionSpec& tf,
                      const Camera& camera, const ReferenceOptions& options, ThreadPool& pool) {
  return renderReference({ReferenceLayer{&volume, &tf}}, camera, options, pool);
}

namespace {

// Extinction and emitted colour per unit opacity (c * lit plus white
// specular) of one volume at index position u; tau 0 where it is empty.
struct Emission {
  double tau = 0;
  double r = 0, g = 0, b = 0;
};

Emission emission(const ReferenceLayer& layer, Vec3 u, Vec3 lightWorld, Vec3 halfway,
                  const ShadingSpec& sh) {
  const double s = layer.volume->value(u);
  if (!std::isfinite(s)) return {};  // non-finite data is empty space
  const Medium m = evaluateMedium(*layer.tf, s);
  if (!(m.tau > 0)) return {};
  double lit = 1, spec = 0;
  if (sh.enabled) {
    const Vec3 g = layer.volume->gradient(u);
    const double gg = dot(g, g);
    lit = sh.ambient + sh.diffuse;  // zero or undefined gradient: lit head-on
    if (gg > 1e-20 && std::isfinite(gg)) {
      const Vec3 nrm = g / std::sqrt(gg);
      lit = sh.ambient + sh.diffuse * std::abs(dot(nrm, lightWorld));
      spec = sh.specular * std::pow(std::abs(dot(nrm, halfway)), sh.shininess);
    }
  }
  return {m.tau, m.r * lit + spec, m.g * lit + spec, m.b * lit + spec};
}

}  // namespace

RgbaD integrateRay(const std::vector<ReferenceLayer>& layers, const Ray& ray, Vec3 lightWorld,
                   const ReferenceOptions& options) {
  if (!(options.step > 0))
    throw Error(ErrorCode::kInvalidArgument, "integrateRay: the substep must be > 0");

  // Each volume's chord, and the cuts where the set of volumes changes.
  std::vector<Chord> chords;
  std::vector<double> cuts;
  for (const ReferenceLayer& layer : layers) {
    chords.push_back(domainChord(layer.volume->grid(), ray));
    if (!(chords.back().length() > 0)) continue;
    cuts.push_back(chords.back().t0);
    cuts.push_back(chords.back().t1);
  }
  std::sort(cuts.begin(), cuts.end());

  // Blinn-Phong half vector between the light and the viewer, who looks
  // back along the ray.
  const Vec3 toViewer = -ray.direction;
  const Vec3 sum = lightWorld + toViewer;
  const Vec3 halfway = length(sum) > 1e-9 ? normalize(sum) : lightWorld;

  double transmittance = 1;
  RgbaD out;
  std::vector<std::size_t> active;
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    const double a = cuts[c], b = cuts[c + 1];
    active.clear();
    for (std::size_t i = 0; i < layers.size(); ++i)
      if (chords[i].length() > 0 && chords[i].t0 <= a && chords[i].t1 >= b) active.push_back(i);
    if (!(b > a) || active.empty()) continue;

    // Midpoint rule over n equal substeps, each attenuating exactly.
    const double L = b - a;
    const double n = std::max(1.0, std::ceil(L / options.step));
    const double dt = L / n;
    for (double i = 0; i < n; ++i) {
      const double t = a + (i + 0.5) * dt;
      const Vec3 world = ray.origin + ray.direction * t;
      Emission mixed;  // tau, and the tau-weighted colours
      for (std::size_t v : active) {
        const GridGeometry& grid = layers[v].volume->grid();
        Vec3 u;
        for (int x = 0; x < 3; ++x) u[x] = (world[x] - grid.origin[x]) / grid.spacing[x];
        const Emission e = emission(layers[v], u, lightWorld, halfway, options.shading);
        mixed.tau += e.tau;
        mixed.r += e.tau * e.r;
        mixed.g += e.tau * e.g;
        mixed.b += e.tau * e.b;
      }
      if (!(mixed.tau > 0)) continue;
      const double alpha = -std::expm1(-mixed.tau * dt);
      const double w = transmittance * alpha / mixed.tau;
      out.r += w * mixed.r;
      out.g += w * mixed.g;
      out.b += w * mixed.b;
      transmittance *= 1 - alpha;
      if (transmittance < options.minTransmittance) break;
    }
    if (transmittance < options.minTransmittance) break;
  }
  out.a = 1 - transmittance;
  return out;
}

Image renderReference(const std::vector<ReferenceLayer>& layers, const Camera& camera,
                      const ReferenceOptions& options, ThreadPool& pool) {
  Image image = Image::fullFrame(camera.width(), camera.height());
  const Vec3 light = referenceLight(camera, options.shading);
  pool.parallelFor(std::size_t(camera.height()), [&](std::size_t row, int) {
    const int y = int(row);
    for (int x = 0; x < camera.width(); ++x) {
      const RgbaD c = integrateRay(layers, camera.ray(x, y), light, options);
      image.at(x, y) = {float(c.r), float(c.g), float(c.b), float(c.a)};
    }
  });
  return image;
}

RgbaD constantMedium(const Medium& medium, double length) {
  const double alpha = -std::expm1(-medium.tau * length);
  return {medium.r * alpha, medium.g * alpha, medium.b * alpha, alpha};
}

Brick makeVolume(const GridGeometry& grid, ScalarType type, const std::function<double(Vec3)>& f) {
  const NodeBox all = grid.allNodes();
  Brick brick(grid, type, all, all);
  dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    T* v = brick.as<T>();
    for (std::int64_t k = 0; k < grid.dims.z; ++k)
      for (std::int64_t j = 0; j < grid.dims.y; ++j)
        for (std::int64_t i = 0; i < grid.dims.x; ++i) {
          const double x = f(grid.nodePosition({i, j, k}));
          T& out = v[brick.linearIndex({i, j, k})];
          if constexpr (std::is_floating_point_v<T>) {
            out = T(x);
          } else {
            const double lo = double(std::numeric_limits<T>::min());
            const double hi = double(std::numeric_limits<T>::max());
            out = std::isnan(x) ? T(0) : T(std::clamp(std::round(x), lo, hi));
          }
        }
    return 0;
  });
  brick.updateValueRange();
  return brick;
}

double marschnerLobb(Vec3 p) {
  constexpr double kFM = 6, kAlpha = 0.25;
  constexpr double pi = std::numbers::pi;
  const double r = std::sqrt(p.x * p.x + p.y * p.y);
  const double rhoR = std::cos(2 * pi * kFM * std::cos(pi * r / 2));
  return (1 - std::sin(pi * p.z / 2) + kAlpha * (1 + rhoR)) / (2 * (1 + kAlpha));
}

TransferFunctionSpec transfer(std::vector<TransferPoint> points, double unitDistance) {
  TransferFunctionSpec tf;
  tf.points = std::move(points);
  tf.unitDistance = unitDistance;
  return tf;
}

ThreadPool& pool() {
  static ThreadPool p(2);
  return p;
}

GridGeometry cubeGrid(std::int64_t n) {
  GridGeometry g;
  g.dims = {n, n, n};
  return g;
}

Camera makeCamera(Projection projection, Vec3 eye, Vec3 lookAt, Vec3 up, double extent,
                  int width, int height) {
  CameraSpec s;
  s.projection = projection;
  s.eye = eye;
  s.lookAt = lookAt;
  s.up = up;
  (projection == Projection::kOrthographic ? s.height : s.fovYDeg) = extent;
  s.automatic = false;
  return Camera(s, width, height);
}

RenderOptions makeOptions(double step, bool preintegrated, bool shaded) {
  RenderOptions o;
  o.step = step;
  o.preintegrated = preintegrated;
  o.shading.enabled = shaded;
  return o;
}

}  // namespace pvr::core
