// The batched lighting (renderer/raycast/shade_lanes.h): eight samples'
// gradients and Blinn-Phong in vector lanes, against kernel::gradient() and
// kernel::shade() one sample at a time.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "raycast/kernel_batch.h"
#include "kernel_fixture.h"
#include "reference.h"

#ifdef PVR_HAVE_BATCH_KERNEL

namespace pvr::core {
namespace {

TransferFunctionSpec opaqueRamp() {
  TransferFunctionSpec tf;
  tf.points = {{0.0, 1, 1, 1, 0.5}, {1.0, 1, 1, 1, 0.5}};
  tf.unitDistance = 1.0;
  return tf;
}

// A brick's kernel parameters, shading on.
KernelFixture setup(const Brick& brick) {
  RenderOptions o = makeOptions(0.5, false, true);
  o.shading.shininess = 24;
  return KernelFixture(brick, opaqueRamp(), o);
}

// The two ways a shaded kernel raises the specular power
// (specular_power.h): from the table, and by steps (shininess 24 is whole).
using TablePower = std::integral_constant<int, kernel::kTablePower>;
using StepsPower = std::integral_constant<int, kernel::kPowerBits>;

// A field with detail in every direction; in float32 some voxels NaN or
// infinite, which the gradients around them carry.
Brick volumeOf(ScalarType type, const GridGeometry& grid) {
  return makeVolume(grid, type, [&](Vec3 q) {
    if (type == ScalarType::kFloat32) {
      if (int(q.x) % 7 == 3 && int(q.y) % 5 == 2 && int(q.z) % 3 == 0) return std::numeric_limits<double>::quiet_NaN();
      if (int(q.x) % 11 == 5 && int(q.z) % 4 == 1 && int(q.y) % 2 == 0) return std::numeric_limits<double>::infinity();
    }
    const double f = 0.5 + 0.45 * std::sin(q.x * 0.7) * std::cos(q.y * 0.45 + q.z * 0.33) + 0.02 * q.z;
    return type == ScalarType::kUInt8 ? 255 * f : type == ScalarType::kInt16 ? 3000 * f - 1000 : f;
  });
}

// Positions in the brick's owned box, in index units: random ones, and
// ones on whole and half nodes at and next to the owned and stored boxes'
// faces and the domain's (where the interior form stops applying).
std::vector<std::array<float, 3>> positions(const KernelParams& p, std::mt19937& random) {
  std::vector<std::array<float, 3>> out;
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int n = 0; n < 2000; ++n) {
    std::array<float, 3> u;
    for (int a = 0; a < 3; ++a) u[a] = float(p.ownLo[a]) + unit(random) * float(p.ownHi[a] - p.ownLo[a]);
    out.push_back(u);
  }
  for (int n = 0; n < 800; ++n) {
    std::array<float, 3> u;
    for (int a = 0; a < 3; ++a) {
      const float lo = float(p.ownLo[a]), hi = float(p.ownHi[a]);
      const float faces[] = {lo, lo + 0.5f, lo + 1.0f, hi - 1.0f, hi - 0.5f, hi};
      u[a] = random() % 3 ? faces[random() % 6] : lo + unit(random) * (hi - lo);
    }
    out.push_back(u);
  }
  return out;
}

bool near(float a, float b) {
  if (!std::isfinite(a) || !std::isfinite(b)) return std::isfinite(a) == std::isfinite(b);
  return std::abs(a - b) <= 2e-5f * std::max(1.0f, std::abs(b));
}

}  // namespace

// Identity: gradient8() is kernel::gradient() lane by lane (the interior
// form's trilinear interpolation of central differences, vectorised, and
// the clamped form elsewhere), up to float rounding; a non-finite
// component stays non-finite. Every scalar type, the whole volume and a
// brick cropped with the one ghost layer shading needs, whose owned box
// ends inside the domain.
TEST_CASE("the vector gradient equals the scalar gradient", "[raycast]") {
  const GridGeometry grid = cubeGrid(24);
  std::mt19937 random(7);
  for (ScalarType type : {ScalarType::kUInt8, ScalarType::kInt16, ScalarType::kUInt16, ScalarType::kFloat32}) {
    const Brick volume = volumeOf(type, grid);
    const Brick brick = cropBrick(volume, NodeBox{{5, 3, 9}, {15, 20, 17}}, 1);
    for (const Brick* b : {&volume, &brick}) {
      const KernelFixture s = setup(*b);
      REQUIRE(s.p.indices32);
      const std::vector<std::array<float, 3>> at = positions(s.p, random);
      int interior = 0, compared = 0, nonFinite = 0;
      for (std::size_t first = 0; first + 8 <= at.size(); first += 8) {
        alignas(32) float u[3][8];
        for (int j = 0; j < 8; ++j)
          for (int a = 0; a < 3; ++a) u[a][j] = at[first + j][a];
        const __m256 lanes[3] = {_mm256_load_ps(u[0]), _mm256_load_ps(u[1]), _mm256_load_ps(u[2])};
        __m256i cell[3];
        interior += __builtin_popcount(unsigned(_mm256_movemask_ps(kernel::interiorLanes8(s.p, lanes, cell))));
        // Every lane, then every other lane alone (the others' reads stand in).
        for (unsigned wanted : {0xFFu, 0x55u}) {
          __m256 g8[3];
          dispatchScalar(type, [&](auto tag) {
            using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
            kernel::gradient8(static_cast<const T*>(s.p.voxels), s.p, lanes, wanted, g8);
          });
          alignas(32) float g[3][8];
          for (int a = 0; a < 3; ++a) _mm256_store_ps(g[a], g8[a]);
          for (int j = 0; j < 8; ++j) {
            if (!(wanted & (1u << j))) continue;
            float one[3];
            dispatchScalar(type, [&](auto tag) {
              using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
              kernel::gradient(static_cast<const T*>(s.p.voxels), s.p, u[0][j], u[1][j], u[2][j], one);
            });
            for (int a = 0; a < 3; ++a) {
              INFO("type " << int(type) << " at " << u[0][j] << " " << u[1][j] << " " << u[2][j] << " axis " << a
                           << ": " << g[a][j] << " against " << one[a]);
              CHECK(near(g[a][j], one[a]));
              nonFinite += !std::isfinite(one[a]);
              ++compared;
            }
          }
        }
      }
      INFO("type " << int(type) << ": " << interior << " interior lanes, " << nonFinite << " non-finite of "
                   << compared);
      CHECK(interior > 1000);           // the vector form ran
      CHECK(interior < int(at.size()));  // and the scalar one for the rest
      if (type == ScalarType::kFloat32) CHECK(nonFinite > 10);
    }
  }
}

// Identity: shadeQuads() lights each sample of opacity > 0 as
// kernel::shade() does and leaves the others as they are, up to float
// rounding, NaN and infinite voxels around samples included (a non-finite
// gradient is lit head-on); the specular power from the table and by
// steps alike (specular_power.h).
TEMPLATE_TEST_CASE("batched lighting equals lighting one sample at a time", "[raycast]", TablePower,
                   StepsPower) {
  constexpr int kPower = TestType::value;
  const GridGeometry grid = cubeGrid(24);
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (ScalarType type : {ScalarType::kInt16, ScalarType::kFloat32}) {
    const Brick volume = volumeOf(type, grid);
    const KernelFixture s = setup(volume);
    const std::vector<std::array<float, 3>> at = positions(s.p, random);
    RaySetup ray{};
    const Vec3 light = normalize(Vec3{0.3, -0.5, 0.8}), halfway = normalize(Vec3{0.1, 0.2, 0.9});
    for (int a = 0; a < 3; ++a) {
      ray.light[a] = float(light[a]);
      ray.halfway[a] = float(halfway[a]);
    }
    double worst = 0;
    for (std::size_t first = 0; first + 8 <= at.size(); first += 8) {
      alignas(32) float u[3][8];
      Rgba colour[8];
      for (int j = 0; j < 8; ++j) {
        for (int a = 0; a < 3; ++a) u[a][j] = at[first + j][a];
        const float alpha = j % 3 == 1 ? 0.0f : unit(random);
        colour[j] = {alpha * unit(random), alpha * unit(random), alpha * unit(random), alpha};
      }
      const __m256 lanes[3] = {_mm256_load_ps(u[0]), _mm256_load_ps(u[1]), _mm256_load_ps(u[2])};
      kernel::Quads c;
      for (int j = 0; j < 4; ++j)
        c.q[j] = _mm256_setr_ps(colour[j].r, colour[j].g, colour[j].b, colour[j].a, colour[j + 4].r,
                                colour[j + 4].g, colour[j + 4].b, colour[j + 4].a);
      dispatchScalar(type, [&](auto tag) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
        kernel::shadeQuads<T, kPower>(static_cast<const T*>(s.p.voxels), s.p, ray, lanes, c);
      });
      alignas(32) float out[4][8];
      for (int j = 0; j < 4; ++j) _mm256_store_ps(out[j], c.q[j]);
      for (int j = 0; j < 8; ++j) {
        Rgba expected = colour[j];
        if (expected.a > 0)
          dispatchScalar(type, [&](auto tag) {
            using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
            expected =
                kernel::shade<T, kPower>(static_cast<const T*>(s.p.voxels), s.p, ray, u[0][j], u[1][j], u[2][j], expected);
          });
        const float* got = &out[j % 4][4 * (j / 4)];
        const float want[4] = {expected.r, expected.g, expected.b, expected.a};
        for (int k = 0; k < 4; ++k) {
          REQUIRE(std::isfinite(got[k]));
          worst = std::max(worst, double(std::abs(got[k] - want[k])));
        }
      }
    }
    INFO("type " << int(type) << ", power " << kPower << ": max difference " << worst);
    CHECK(worst < 1e-5);
  }
}

// The specular power by steps (specular_power.h): the step count of each
// shininess (whole ones up to 255; the table for the others); x^n within
// the stated bound of 2 n 2^-24 relative of the exact power for every
// whole n and x in [0, 1] (near 1 and near 0 included); the vector form
// equal to the scalar one bit for bit; and more steps than n's bits give
// the same bits (the kernel takes kPowerBits for every n).
TEST_CASE("the specular power by steps is x to the shininess", "[raycast]") {
  CHECK(kernel::powerBits(1.0) == 1);
  CHECK(kernel::powerBits(24.0) == 5);
  CHECK(kernel::powerBits(32.0) == 6);
  CHECK(kernel::powerBits(255.0) == 8);
  CHECK(kernel::powerBits(24.5) == kernel::kTablePower);
  CHECK(kernel::powerBits(0.5) == kernel::kTablePower);
  CHECK(kernel::powerBits(256.0) == kernel::kTablePower);
  CHECK(kernel::powerBits(std::numeric_limits<double>::quiet_NaN()) == kernel::kTablePower);
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double worst = 0;  // relative error, in units of the bound
  for (int n = 1; n < (1 << kernel::kPowerBits); ++n) {
    float floor[kernel::kPowerBits];
    kernel::setPowerFloor(n, floor);
    for (int k = 0; k < 64; ++k) {
      alignas(32) float x[8], got8[8];
      for (int j = 0; j < 8; ++j)
        x[j] = k == 0 ? float(j) / 7.0f : j == 0 ? 1.0f - unit(random) * 1e-3f : j == 1 ? unit(random) * 1e-2f : unit(random);
      _mm256_store_ps(got8, kernel::powerBySteps8<kernel::kPowerBits>(_mm256_load_ps(x), floor));
      for (int j = 0; j < 8; ++j) {
        const float got = kernel::powerBySteps<kernel::kPowerBits>(x[j], floor);
        INFO("x " << x[j] << " n " << n);
        REQUIRE(got == got8[j]);
        if (n < 16) REQUIRE(got == kernel::powerBySteps<4>(x[j], floor));
        const double exact = std::pow(double(x[j]), double(n));
        if (exact < 1e-30) {
          CHECK(got < 1e-29f);  // underflows towards 0
          continue;
        }
        worst = std::max(worst, std::abs(got - exact) / exact / (2 * n * std::ldexp(1.0, -24)));
      }
    }
  }
  INFO("worst relative error, in units of 2 n 2^-24: " << worst);
  CHECK(worst <= 1.0);
  CHECK(worst > 0.01);  // it was measured, not rounded away
}

}  // namespace pvr::core

#endif
