// Several volumes in one rendering (SceneRenderer, mix_kernel.h) against
// the several-volume reference (reference.h) and against the identities
// of overlapping media: extinctions add, colours mix weighted by them
// (docs/scene.md, "Several volumes").
//
// Errors are of the same two kinds as in raycast_accuracy_test.cpp: float
// rounding, ~1e-7 per quantity, and quadrature error O(h^2), which the
// caster keeps to that order across every volume's faces by cutting each
// ray at every entry and exit, so no sample stands for a stretch on both
// sides of a face. Caps are the single-volume accuracy tests' (1e-2 at a
// step of 1 voxel seen from outside, 1.5e-3 at half a voxel from inside;
// voxel meaning the smallest spacing of the volumes, as the default step
// does).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "raycast/raycaster.h"
#include "raycast/scene_renderer.h"
#include "mixed_scenes.h"
#include "reference.h"

namespace pvr::core {
namespace {

using namespace test;


Image castOne(const Brick& brick, const TransferFunctionSpec& tf, const Camera& camera, const RenderOptions& o) {
  BrickRenderer renderer(brick);
  renderer.classify(tf, o);
  return renderer.render(camera, o, pool()).toFullFrame();
}

Image referenceScene(const std::vector<TestVolume>& volumes, const Camera& camera, const RenderOptions& o) {
  std::vector<ReferenceVolume> refs;
  for (const TestVolume& v : volumes) refs.emplace_back(v.brick);
  std::vector<ReferenceLayer> layers;
  for (std::size_t i = 0; i < volumes.size(); ++i)
    if (volumes[i].visible) layers.push_back({&refs[i], &volumes[i].tf});
  ReferenceOptions r;
  r.step = o.step / 32;
  r.shading = o.shading;
  return renderReference(layers, camera, r, pool());
}

// The caster at step h and h / 2 against the reference: the largest error
// below maxAbs at h and maxAbs / 2 at h / 2, the RMSE falling at least
// 2.5-fold (O(h^2)).
void checkAgainstReference(const std::vector<TestVolume>& volumes, const Camera& camera, RenderOptions o,
                           double maxAbs) {
  const Image ref = referenceScene(volumes, camera, o);
  const ImageError coarse = compareImages(castScene(volumes, camera, o), ref);
  o.step /= 2;
  const ImageError fine = compareImages(castScene(volumes, camera, o), ref);
  INFO("RMSE " << coarse.rmse << " -> " << fine.rmse << ", max " << coarse.maxAbs << " -> " << fine.maxAbs);
  CHECK(coarse.maxAbs < maxAbs);
  CHECK(fine.maxAbs < maxAbs / 2);
  CHECK((fine.rmse * 2.5 < coarse.rmse || fine.rmse < 2e-6));
  // Something was seen: the scene is not empty.
  CHECK(maxAlpha(ref) > 0.2);
}

}  // namespace

// Identity: with one visible volume the scene renderer IS the brick
// renderer: every option, every scalar type, with or without more
// volumes that are invisible. Bit for bit (maxAbs == 0).
TEST_CASE("one visible volume renders bit for bit as the brick renderer", "[raycast][mixed]") {
  const GridGeometry grid = boxGrid({20, 18, 16}, 1.0, {0, 0, 0});
  const Camera camera = perspective(Vec3{-20, -25, 18}, grid.center(), 35);
  for (ScalarType type : {ScalarType::kUInt8, ScalarType::kFloat32}) {
    const Brick brick = smoothVolume(grid, {0.4, 0.5, 0.5}, type);
    const TransferFunctionSpec tf = type == ScalarType::kUInt8 ? tfOf({{0, 0.2, 0, 0, 0}, {255, 1, 0.9, 0.6, 0.3}}, 1.0)
                                                               : warm(1.0);
    for (int options = 0; options < 4; ++options) {
      const RenderOptions o = makeOptions(0.5, options & 1, options & 2);
      INFO("type " << int(type) << ", preintegrated " << (options & 1) << ", shaded " << (options & 2));
      const Image alone = castOne(brick, tf, camera, o);
      CHECK(maxAlpha(alone) > 0.2);
      CHECK(compareImages(castScene({{Brick(brick), tf}}, camera, o), alone).maxAbs == 0);
      // A second, overlapping volume that is not visible.
      std::vector<TestVolume> two;
      two.push_back({Brick(brick), tf});
      two.push_back({smoothVolume(boxGrid({9, 9, 9}, 1.3, {3, 2, 1}), {0.5, 0.5, 0.5}), cool(1.0), false});
      CHECK(compareImages(castScene(two, camera, o), alone).maxAbs == 0);
    }
  }
}

// Identity: caster == reference for two volumes that overlap partly, with
// different spacings (1 and 0.7), seen from outside and from inside both.
TEST_CASE("two overlapping volumes of different spacing match the reference", "[raycast][mixed]") {
  const std::vector<TestVolume> volumes = overlappingVolumes();
  const Vec3 c{14, 12, 10};
  SECTION("eye outside") {
    const Vec3 d = normalize(Vec3{-0.6, 0.7, -0.4});
    checkAgainstReference(volumes, orthographic(c - d * 50.0, c, 40), makeOptions(1.0), 1e-2);
    checkAgainstReference(volumes, perspective(c - d * 60.0, c, 40), makeOptions(1.0), 1e-2);
  }
  SECTION("eye inside both") {
    const Vec3 eye{15, 12, 10};
    checkAgainstReference(volumes, perspective(eye, eye + Vec3{1, 0.2, 0.1}, 90), makeOptions(0.35), 1.5e-3);
    checkAgainstReference(volumes, perspective(eye, eye + Vec3{-0.3, -0.8, 0.5}, 90), makeOptions(0.35), 1.5e-3);
  }
}

// Identity: caster == reference for a small fine volume (spacing 0.5)
// wholly inside a coarse one, from outside, from inside the outer only,
// and from inside both.
TEST_CASE("a volume inside another matches the reference", "[raycast][mixed]") {
  const std::vector<TestVolume> volumes = nestedVolumes();
  const Vec3 c{13.5, 13.5, 13.5};
  SECTION("eye outside") {
    const Vec3 d = normalize(Vec3{0.7, 0.5, -0.5});
    checkAgainstReference(volumes, orthographic(c - d * 50.0, c, 44), makeOptions(1.0), 1e-2);
  }
  SECTION("eye inside the outer volume") {
    const Vec3 eye{3, 4, 5};
    checkAgainstReference(volumes, perspective(eye, c, 60), makeOptions(0.25), 1.5e-3);
  }
  SECTION("eye inside both") {
    const Vec3 eye{14, 13, 14};
    checkAgainstReference(volumes, perspective(eye, eye + Vec3{0.4, 1, -0.3}, 100), makeOptions(0.25), 1.5e-3);
  }
  SECTION("shaded") {
    const Vec3 d = normalize(Vec3{0.7, 0.5, -0.5});
    checkAgainstReference(volumes, orthographic(c - d * 50.0, c, 44), makeOptions(1.0, false, true), 2.5e-2);
  }
}

// Identity: caster == reference for two disjoint volumes one behind the
// other along the view (a gap between them), from outside and from inside
// the nearer one.
TEST_CASE("disjoint volumes side by side along the view match the reference", "[raycast][mixed]") {
  const std::vector<TestVolume> volumes = disjointVolumes();
  SECTION("eye outside") {
    const Vec3 at{18, 7.5, 7.5};
    checkAgainstReference(volumes, perspective(at + Vec3{-40, -6, 5}, at, 30), makeOptions(1.0), 1e-2);
  }
  SECTION("eye inside the nearer volume") {
    const Vec3 eye{8, 7.5, 7.5};
    checkAgainstReference(volumes, perspective(eye, eye + Vec3{1, 0.05, 0.02}, 90), makeOptions(0.4), 1.5e-3);
  }
}

// Identity: a volume whose transfer function is transparent everywhere
// has zero extinction, so the other volume alone remains. Tolerance: the
// two paths classify through different tables (opacity per step against
// optical depth per step, both float, interpolated between the same
// entries): float rounding, 1e-5.
TEST_CASE("a transparent volume leaves the other volume's image", "[raycast][mixed]") {
  const Brick solid = smoothVolume(boxGrid({24, 22, 20}, 1.0, {0, 0, 0}), {0.4, 0.45, 0.5});
  std::vector<TestVolume> volumes;
  volumes.push_back({Brick(solid), warm(1.0)});
  volumes.push_back({smoothVolume(boxGrid({22, 22, 22}, 0.7, {5.3, 4.1, 3.7}), {0.6, 0.5, 0.4}),
                     tfOf({{0, 1, 1, 1, 0}, {1, 1, 1, 1, 0}}, 0.7)});
  const Vec3 c{12, 11, 10};
  const Camera camera = perspective(c + Vec3{-30, -40, 25}, c, 35);
  for (bool shaded : {false, true}) {
    const RenderOptions o = makeOptions(0.5, false, shaded);
    const Image alone = castOne(solid, warm(1.0), camera, o);
    const ImageError e = compareImages(castScene(volumes, camera, o), alone);
    INFO("shaded " << shaded << ": max " << e.maxAbs);
    CHECK(maxAlpha(alone) > 0.2);
    CHECK(e.maxAbs < 1e-5);
  }
}

// Identity: two copies of a volume with opacity a(s) each are one medium
// of twice the extinction, opacity 1 - (1 - a(s))^2, same colour. The
// doubled transfer function is given at every table entry's scalar, so
// both paths interpolate the same entries. Tolerance as above, 1e-5.
TEST_CASE("two identical copies equal one volume of doubled extinction", "[raycast][mixed]") {
  const GridGeometry grid = boxGrid({24, 22, 20}, 1.0, {0, 0, 0});
  const Brick brick = smoothVolume(grid, {0.4, 0.45, 0.5});
  const TransferFunctionSpec half = warm(1.0);
  TransferFunctionSpec doubled = half;
  doubled.points.clear();
  for (int i = 0; i < TransferTable::kEntries; ++i) {
    const double s = double(i) / (TransferTable::kEntries - 1);
    TransferPoint p{s, 0, 0, 0, 0};
    // The colour and opacity as given, between half's control points.
    const auto& h = half.points;
    std::size_t j = 0;
    while (j + 2 < h.size() && s > h[j + 1].scalar) ++j;
    const double w = std::clamp((s - h[j].scalar) / (h[j + 1].scalar - h[j].scalar), 0.0, 1.0);
    p.r = h[j].r + w * (h[j + 1].r - h[j].r);
    p.g = h[j].g + w * (h[j + 1].g - h[j].g);
    p.b = h[j].b + w * (h[j + 1].b - h[j].b);
    const double a = h[j].opacity + w * (h[j + 1].opacity - h[j].opacity);
    p.opacity = 1 - (1 - a) * (1 - a);
    doubled.points.push_back(p);
  }
  std::vector<TestVolume> copies;
  copies.push_back({Brick(brick), half});
  copies.push_back({Brick(brick), half});
  const Vec3 c = grid.center();
  for (const Camera& camera : {perspective(c + Vec3{-30, -40, 25}, c, 35), perspective(c, c + Vec3{1, 0.3, 0.2}, 90)}) {
    const RenderOptions o = makeOptions(0.5);
    const Image one = castOne(brick, doubled, camera, o);
    const ImageError e = compareImages(castScene(copies, camera, o), one);
    INFO("max " << e.maxAbs);
    CHECK(maxAlpha(one) > 0.2);
    CHECK(e.maxAbs < 1e-5);
  }
}

// Identity: empty-space skipping on the combined classification changes
// nothing (a run is skipped only where every volume present is empty
// there) and saves samples: two narrow bands, each volume's own, with
// empty space around them and between the volumes.
TEST_CASE("several volumes skip empty space together without changing the image", "[raycast][mixed]") {
  auto band = [](double at, double r, double g, double b, double unit) {
    return tfOf({{0, 0, 0, 0, 0}, {at - 0.02, r, g, b, 0}, {at, r, g, b, 0.6}, {at + 0.02, r, g, b, 0}, {1, 0, 0, 0, 0}},
                unit);
  };
  std::vector<TestVolume> volumes;
  volumes.push_back({smoothVolume(boxGrid({40, 40, 40}, 1.0, {0, 0, 0}), {0.4, 0.45, 0.5}), band(0.7, 1, 0.6, 0.2, 1)});
  volumes.push_back({smoothVolume(boxGrid({40, 40, 40}, 0.6, {12.3, 10.2, 8.9}), {0.6, 0.5, 0.4}),
                     band(0.6, 0.2, 0.6, 1, 0.6)});
  const Vec3 c{20, 20, 20};
  for (bool shaded : {false, true}) {
    const Camera camera = perspective(c + Vec3{-50, -60, 30}, c, 40);
    RenderOptions on = makeOptions(0.5, false, shaded), off = on;
    off.skipEmpty = false;
    RenderStats skipping, full;
    const Image a = castScene(volumes, camera, on, &skipping);
    const Image b = castScene(volumes, camera, off, &full);
    INFO("shaded " << shaded << ": samples " << skipping.samples << " of " << full.samples);
    CHECK(maxAlpha(a) > 0.2);
    CHECK(compareImages(a, b).maxAbs <= 1e-6);
    CHECK(skipping.samples * 2 < full.samples);
  }
}

}  // namespace pvr::core
