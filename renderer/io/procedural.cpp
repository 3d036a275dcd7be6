// Procedural volumes: analytic fields sampled on a node grid at any
// resolution, so tests and benchmarks need no data files and references can
// evaluate the exact field (proceduralValue).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "source_util.h"
#include "volume_io.h"

namespace pvr::core {

namespace {

// The 3D Shepp-Logan head phantom: the ellipsoids of Kak & Slaney,
// "Principles of Computerized Tomographic Imaging" (1988), table 3.2 (p.102),
// with the higher-contrast densities of Yu, Ye & Wang (SPIE 5535, 2004).
// Kak & Slaney's own densities (2.0, -0.98, +-0.02, ...) leave the brain
// features 1 % apart, invisible in a rendering; with these the skull is 1,
// brain 0.2, the ventricles 0 and the smaller features 0.3 to 0.6.
struct Ellipsoid {
  Vec3 center;
  Vec3 semiAxes;   // along x, y, z of the ellipsoid's own frame
  double phiDeg;   // rotation about z
  double density;  // added inside
};
constexpr std::array<Ellipsoid, 10> kSheppLogan = {{
    {{0.00, 0.000, 0.000}, {0.6900, 0.920, 0.900}, 0, 1.0},    // skull outline
    {{0.00, 0.000, 0.000}, {0.6624, 0.874, 0.880}, 0, -0.8},   // brain
    {{-0.22, 0.000, -0.250}, {0.4100, 0.160, 0.210}, 108, -0.2},  // ventricles
    {{0.22, 0.000, -0.250}, {0.3100, 0.110, 0.220}, 72, -0.2},
    {{0.00, 0.350, -0.250}, {0.2100, 0.250, 0.500}, 0, 0.2},   // smaller features
    {{0.00, 0.100, -0.250}, {0.0460, 0.046, 0.046}, 0, 0.2},
    {{-0.08, -0.650, -0.250}, {0.0460, 0.023, 0.020}, 0, 0.1},
    {{0.06, -0.650, -0.250}, {0.0460, 0.023, 0.020}, 90, 0.1},
    {{0.06, -0.105, 0.625}, {0.0560, 0.040, 0.100}, 90, 0.2},
    {{0.00, 0.100, 0.625}, {0.0560, 0.056, 0.100}, 0, -0.2},
}};

double sheppLogan(Vec3 p) {
  double sum = 0;
  for (const Ellipsoid& e : kSheppLogan) {
    // Into the ellipsoid's frame: translate, then rotate by -phi about z.
    const double phi = e.phiDeg * std::numbers::pi / 180;
    const double c = std::cos(phi), s = std::sin(phi);
    const Vec3 d = p - e.center;
    const double x = (c * d.x + s * d.y) / e.semiAxes.x;
    const double y = (-s * d.x + c * d.y) / e.semiAxes.y;
    const double z = d.z / e.semiAxes.z;
    if (x * x + y * y + z * z <= 1) sum += e.density;
  }
  return std::clamp(sum, 0.0, 1.0);
}

// Marschner & Lobb, "An evaluation of reconstruction filters for volume
// rendering" (Visualization '94), on [-1,1]^3 with f_M = 6, alpha = 0.25:
// rho = (1 - sin(pi z / 2) + alpha (1 + rho_r(sqrt(x^2 + y^2)))) / (2 (1 + alpha)),
// rho_r(r) = cos(2 pi f_M cos(pi r / 2)). Values lie in [0, 1].
double marschnerLobb(Vec3 p) {
  constexpr double kFM = 6, kAlpha = 0.25, kPi = std::numbers::pi;
  const double r = std::sqrt(p.x * p.x + p.y * p.y);
  const double rhoR = std::cos(2 * kPi * kFM * std::cos(kPi * r / 2));
  return (1 - std::sin(kPi * p.z / 2) + kAlpha * (1 + rhoR)) / (2 * (1 + kAlpha));
}

double constantSlab(Vec3) { return 1.0; }

struct Field {
  const char* name;
  double (*value)(Vec3);
};
constexpr Field kFields[] = {
    {"shepp-logan", sheppLogan},
    {"marschner-lobb", marschnerLobb},
    {"constant-slab", constantSlab},
};

const Field& findField(const std::string& name) {
  for (const Field& f : kFields)
    if (name == f.name) return f;
  std::string known;
  for (const Field& f : kFields) known += std::string(known.empty() ? "" : ", ") + f.name;
  failAt(ErrorCode::kInvalidArgument, name, "unknown procedural volume (known: " + known + ")");
}

class ProceduralSource final : public VolumeSource {
 public:
  ProceduralSource(const Field& field, const GridGeometry& grid) : field_(field), grid_(grid) {}

  const GridGeometry& grid() const override { return grid_; }
  ScalarType type() const override { return ScalarType::kFloat32; }
  bool canReadPartially() const override { return true; }
  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    checkReadBoxes(field_.name, grid_, owned, stored);
    Brick brick(grid_, ScalarType::kFloat32, owned, stored);
    float* out = brick.as<float>();
    for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
      for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
        for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x)
          *out++ = float(field_.value(grid_.nodePosition({x, y, z})));
    brick.updateValueRange();
    return brick;
  }
  std::string describe() const override {
    return std::string(field_.name) + ": " + shapeText(grid_, ScalarType::kFloat32) + " (procedural)";
  }

 private:
  const Field& field_;
  GridGeometry grid_;
};

}  // namespace

GridGeometry generatedGrid(IVec3 dims, std::optional<Vec3> spacing, const std::string& name) {
  GridGeometry grid;
  grid.dims = dims;
  if (spacing) {
    grid.spacing = *spacing;
  } else {
    // [-1, 1] on the longest axis; a single node has no extent to span, and
    // any positive spacing would do.
    const std::int64_t longest = std::max({dims.x, dims.y, dims.z});
    const double h = longest > 1 ? 2.0 / double(longest - 1) : 2.0;
    grid.spacing = Vec3{h, h, h};
  }
  // Centred on 0: node i sits at (i - (n - 1) / 2) * spacing.
  for (int a = 0; a < 3; ++a) grid.origin[a] = -double(dims[a] - 1) * grid.spacing[a] / 2;
  grid.validate(name);
  voxelBytes(grid, ScalarType::kFloat32, name);  // refuses absurd sizes
  return grid;
}

std::unique_ptr<VolumeSource> openProcedural(const std::string& name, IVec3 dims, Vec3 spacing) {
  const Field& field = findField(name);
  return std::make_unique<ProceduralSource>(field, generatedGrid(dims, spacing, name));
}

std::unique_ptr<VolumeSource> openProcedural(const std::string& name, IVec3 dims) {
  const Field& field = findField(name);
  return std::make_unique<ProceduralSource>(field, generatedGrid(dims, std::nullopt, name));
}

std::vector<std::string> proceduralNames() {
  std::vector<std::string> names;
  for (const Field& f : kFields) names.emplace_back(f.name);
  return names;
}

double proceduralValue(const std::string& name, Vec3 position) {
  return findField(name).value(position);
}

}  // namespace pvr::core
