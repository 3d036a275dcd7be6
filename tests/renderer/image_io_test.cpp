// Image files (EXR exact, PNG as sRGB bytes) and the image operations they
// rely on (compositeUnder, compareImages).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include <nlohmann/json.hpp>

#include "error.h"
#include "image.h"
#include "image_io.h"
#include "paraview_preset.h"
#include "reference.h"

using namespace pvr::core;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(PVR_TEST_TMP) / "image_io";
  fs::create_directories(dir);
  return dir / name;
}

// The straight RGBA bytes of a PNG as stored (no alpha association on read).
std::vector<std::uint8_t> readPngBytes(const std::string& path, int& width, int& height) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  REQUIRE(in);
  const OIIO::ImageSpec& spec = in->spec();
  REQUIRE(spec.nchannels == 4);
  width = spec.width;
  height = spec.height;
  std::vector<std::uint8_t> bytes(std::size_t(width) * std::size_t(height) * 4);
  REQUIRE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, bytes.data()));
  return bytes;
}

std::string errorOf(void (*f)(const std::string&), const std::string& path) {
  try {
    f(path);
  } catch (const pvr::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("EXR write then read gives back the exact floats", "[image]") {
  // A partial rect: the file holds the full frame, transparent outside it.
  Image image(7, 5, {1, 1, 6, 4});
  float v = 0;
  for (int y = 1; y < 4; ++y)
    for (int x = 1; x < 6; ++x, v += 1) {
      image.at(x, y) = {v / 7.0f, 1e-30f + v, std::nextafter(1.0f, 2.0f) * v, 1.0f / (v + 3.0f)};
    }
  const std::string path = scratch("roundtrip.exr").string();
  writeExr(image, path);
  const Image back = readExr(path);
  CHECK(back.frameWidth() == 7);
  CHECK(back.frameHeight() == 5);
  CHECK(back.rect() == PixelRect{0, 0, 7, 5});
  CHECK(maxAbsDifference(back, image) == 0);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      const Rgba p = back.at(x, y), q = image.sample(x, y);
      CHECK((p.r == q.r && p.g == q.g && p.b == q.b && p.a == q.a));
    }
}

TEST_CASE("EXR holds the image alone, not composited over the background", "[image]") {
  Image image = Image::fullFrame(2, 1);
  image.at(0, 0) = {0.25f, 0, 0, 0.5f};
  const std::string path = scratch("no_background.exr").string();
  writeImage(image, {1, 1, 1, 1}, path);
  const Image back = readExr(path);
  CHECK(back.at(0, 0).r == 0.25f);
  CHECK(back.at(0, 0).a == 0.5f);
  CHECK(back.at(1, 0).a == 0.0f);
}

TEST_CASE("linearToSrgb8 follows the sRGB curve", "[image]") {
  // Expected codes: round(255 * (1.055 v^(1/2.4) - 0.055)), or 12.92 v below 0.0031308.
  CHECK(linearToSrgb8(0.0) == 0);
  CHECK(linearToSrgb8(1.0) == 255);
  CHECK(linearToSrgb8(0.5) == 188);
  CHECK(linearToSrgb8(0.18) == 118);
  CHECK(linearToSrgb8(0.001) == 3);
  CHECK(linearToSrgb8(0.2) == 124);
  CHECK(linearToSrgb8(-0.5) == 0);
  CHECK(linearToSrgb8(7.0) == 255);
  CHECK(linearToSrgb8(std::numeric_limits<double>::quiet_NaN()) == 0);
}

TEST_CASE("linearToSrgb8's tables give the curve's code for every value, at each code's edge too", "[image]") {
  // Identity checked: linearToSrgb8(v) == linearToSrgb8ByCurve(v), where a
  // code changes (the values around the inverse curve at k - 0.5, a few
  // hundred doubles either side) and across (0, 1) and near 0.
  int wrong = 0;
  const auto check = [&](double v) {
    if (linearToSrgb8(v) != linearToSrgb8ByCurve(v) && ++wrong <= 5)
      FAIL_CHECK("v = " << v << ": " << int(linearToSrgb8(v)) << " against " << int(linearToSrgb8ByCurve(v)));
  };
  for (int k = 1; k <= 255; ++k) {
    const double e = (k - 0.5) / 255.0;
    const double edge = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    double up = edge, down = edge;
    for (int i = 0; i < 300; ++i) {
      check(up);
      check(down);
      up = std::nextafter(up, 2.0);
      down = std::nextafter(down, -1.0);
    }
  }
  for (int i = 0; i < (1 << 20); ++i) check((i + 0.5) / (1 << 20));
  for (double v = 1e-12; v < 1; v *= 1.001) check(v);
  CHECK(wrong == 0);
}

TEST_CASE("PNG pixels are composited over the background and sRGB encoded", "[image]") {
  // Frame 4x1, rect covers pixels 0..2; pixel 3 is background only.
  Image image(4, 1, {0, 0, 3, 1});
  image.at(0, 0) = {0.5f, 0.18f, 1.0f, 1.0f};  // opaque
  image.at(1, 0) = {0.25f, 0, 0, 0.5f};        // half coverage, premultiplied
  image.at(2, 0) = {0, 0, 0, 0};               // transparent
  const std::string path = scratch("known.png").string();
  writePng(image, {0, 0, 1, 1}, path);

  int w = 0, h = 0;
  const std::vector<std::uint8_t> b = readPngBytes(path, w, h);
  REQUIRE(w == 4);
  REQUIRE(h == 1);
  const std::vector<std::uint8_t> expected = {
      188, 118, 255, 255,  // linear 0.5, 0.18, 1
      137, 0, 188, 255,    // 0.25 + 0.5 * 0 = 0.25 -> 137; blue 0.5 * 1 -> 188
      0, 0, 255, 255,      // background
      0, 0, 255, 255,      // outside the rect: background
  };
  CHECK(b == expected);
}

TEST_CASE("PNG over a translucent background keeps straight alpha", "[image]") {
  Image image = Image::fullFrame(2, 1);
  image.at(0, 0) = {0.25f, 0.25f, 0.25f, 0.5f};
  const std::string path = scratch("translucent.png").string();
  // Background (0.2, 0.4, 0.6) at alpha 0: contributes nothing.
  writeImage(image, {0.2, 0.4, 0.6, 0.0}, path);
  int w = 0, h = 0;
  const std::vector<std::uint8_t> b = readPngBytes(path, w, h);
  REQUIRE(b.size() == 8);
  // Straight colour 0.25 / 0.5 = 0.5 -> 188; alpha 0.5 -> 128 (127.5 rounds up).
  CHECK(std::vector<std::uint8_t>(b.begin(), b.begin() + 4) == std::vector<std::uint8_t>{188, 188, 188, 128});
  CHECK(std::vector<std::uint8_t>(b.begin() + 4, b.end()) == std::vector<std::uint8_t>{0, 0, 0, 0});

  // An opaque background shows through fully where the image is empty, as
  // the display colour it was given (0.2 -> 51).
  writeImage(image, {0.2, 0.4, 0.6, 1.0}, path);
  const std::vector<std::uint8_t> c = readPngBytes(path, w, h);
  CHECK(std::vector<std::uint8_t>(c.begin() + 4, c.end()) == std::vector<std::uint8_t>{51, 102, 153, 255});
}

// Another program's PNG read number for number: the code values / 255,
// neither decoded from sRGB nor multiplied by alpha (the second pixel's
// alpha is 128 and its colour still reads as stored).
TEST_CASE("readPngCodes gives a PNG's code values over 255", "[image]") {
  Image image(3, 1, {0, 0, 2, 1});
  image.at(0, 0) = {0.5f, 0.18f, 1.0f, 1.0f};  // encodes to 188, 118, 255
  image.at(1, 0) = {0.25f, 0.25f, 0.25f, 0.5f};  // straight 0.5 -> 188, alpha 128
  const std::string path = scratch("codes.png").string();
  writePng(image, {0, 0, 0, 0}, path);
  const Image codes = readPngCodes(path);
  REQUIRE(codes.frameWidth() == 3);
  REQUIRE(codes.frameHeight() == 1);
  CHECK(codes.at(0, 0).r == 188 / 255.0f);
  CHECK(codes.at(0, 0).g == 118 / 255.0f);
  CHECK(codes.at(0, 0).b == 1.0f);
  CHECK(codes.at(1, 0).r == 188 / 255.0f);
  CHECK(codes.at(1, 0).a == 0.0f);
  CHECK(codes.at(2, 0).r == 0.0f);

  const std::string missing = scratch("missing.png").string();
  CHECK(errorOf([](const std::string& p) { readPngCodes(p); }, missing).rfind(missing + ": cannot read", 0) == 0);
  const std::string exr = scratch("not_png.exr").string();
  writeExr(image, exr);
  CHECK(errorOf([](const std::string& p) { readPngCodes(p); }, exr).rfind(exr + ": not a PNG file", 0) == 0);
}

TEST_CASE("image file errors name the path", "[image]") {
  const Image image = Image::fullFrame(2, 2);
  const std::string jpg = scratch("frame.jpg").string();
  try {
    writeImage(image, {0, 0, 0, 1}, jpg);
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(std::string(e.what()) == jpg + ": unsupported image extension '.jpg' (use .exr or .png)");
    CHECK(e.code() == pvr::ErrorCode::kInvalidArgument);
  }

  // Upper-case extensions are recognised.
  const std::string upper = scratch("FRAME.EXR").string();
  writeImage(image, {0, 0, 0, 1}, upper);
  CHECK(readExr(upper).frameWidth() == 2);

  const std::string unwritable = "/nonexistent-pvr-dir/frame.exr";
  const std::string w = errorOf([](const std::string& p) { writeExr(Image::fullFrame(1, 1), p); }, unwritable);
  CHECK(w.rfind(unwritable + ": ", 0) == 0);

  const std::string missing = scratch("missing.exr").string();
  const std::string r = errorOf([](const std::string& p) { readExr(p); }, missing);
  CHECK(r.rfind(missing + ": cannot read", 0) == 0);

  const std::string png = scratch("not_exr.png").string();
  writePng(image, {0, 0, 0, 1}, png);
  const std::string n = errorOf([](const std::string& p) { readExr(p); }, png);
  CHECK(n.rfind(png + ": not an OpenEXR file", 0) == 0);
}

TEST_CASE("compositeUnder is premultiplied over on the back image's rect", "[image]") {
  // c = c_f + (1 - a_f) c_b, exact for these binary fractions.
  Image front = Image::fullFrame(3, 1);
  front.at(0, 0) = {0.5f, 0, 0, 0.5f};
  front.at(1, 0) = {0.25f, 0.25f, 0.25f, 1};
  front.at(2, 0) = {0, 0, 0, 0};
  Image back(3, 1, {0, 0, 2, 1});
  back.at(0, 0) = {0, 0, 1, 1};
  back.at(1, 0) = {1, 1, 1, 1};
  compositeUnder(front, back);
  const Rgba p = front.at(0, 0), q = front.at(1, 0), r = front.at(2, 0);
  CHECK((p.r == 0.5f && p.g == 0 && p.b == 0.5f && p.a == 1));
  CHECK((q.r == 0.25f && q.g == 0.25f && q.b == 0.25f && q.a == 1));
  CHECK((r.r == 0 && r.a == 0));  // outside the back rect: untouched

  // A front that does not cover the back is a broken invariant.
  Image small(3, 1, {0, 0, 1, 1});
  try {
    compositeUnder(small, back);
    FAIL("no error");
  } catch (const pvr::Error& e) {
    CHECK(e.code() == pvr::ErrorCode::kInternal);
  }
}

TEST_CASE("compareImages reports RMSE, PSNR and max error over the full frame", "[image]") {
  Image a = Image::fullFrame(2, 1);
  Image b(2, 1, {0, 0, 1, 1});  // pixel 1 is transparent by being outside the rect
  a.at(0, 0) = {0.5f, 0.5f, 0.5f, 1};
  b.at(0, 0) = {0.5f, 0.5f, 0.5f, 1};
  ImageError same = compareImages(a, b);
  CHECK(same.rmse == 0);
  CHECK(same.maxAbs == 0);
  CHECK(std::isinf(same.psnr));

  // One channel of eight off by 0.5: rmse = sqrt(0.25 / 8), psnr = 20 log10(1 / rmse).
  a.at(1, 0).g = 0.5f;
  const ImageError e = compareImages(a, b);
  CHECK(e.maxAbs == 0.5);
  CHECK(e.rmse == Approx(std::sqrt(0.25 / 8)));
  CHECK(e.psnr == Approx(15.0514997832));

  a.at(1, 0).r = std::numeric_limits<float>::quiet_NaN();
  CHECK(std::isinf(compareImages(a, b).maxAbs));

  CHECK_THROWS_AS(compareImages(Image::fullFrame(2, 2), b), pvr::Error);
}

// Transfer-function colours are display sRGB, as ParaView and colour
// pickers mean them: an opaque slab of ParaView's Cool to Warm red end
// (180, 4, 38) comes out of the PNG as (180, 4, 38), not lighter.
TEST_CASE("an opaque slab through a preset colour writes that colour to the PNG", "[image][colour]") {
  const nlohmann::json preset = {{"Name", "Cool to Warm, red end"},
                                 {"RGBPoints", {0, 0.705882, 0.0156863, 0.14902, 1, 0.705882, 0.0156863, 0.14902}},
                                 {"Points", {0, 1, 0.5, 0, 1, 1, 0.5, 0}}};
  TransferFunctionSpec tf = paraViewPresetFromJson(preset, "preset");
  tf.unitDistance = 1;
  const GridGeometry grid = cubeGrid(8);
  const Brick slab = makeVolume(grid, ScalarType::kFloat32, [](Vec3) { return 0.5; });
  BrickRenderer renderer(slab);
  const RenderOptions options = makeOptions(0.5);
  renderer.classify(tf, options);
  ThreadPool pool(1);
  const Camera camera = makeCamera(Projection::kOrthographic, {3.5, 3.5, -10}, {3.5, 3.5, 3.5}, {0, 1, 0}, 4, 8, 8);
  const std::string path = scratch("swatch.png").string();
  writeImage(renderer.render(camera, options, pool), {0, 0, 0, 1}, path);
  int w = 0, h = 0;
  const std::vector<std::uint8_t> b = readPngBytes(path, w, h);
  const std::uint8_t* centre = b.data() + (std::size_t(h / 2) * std::size_t(w) + std::size_t(w / 2)) * 4;
  CHECK(std::abs(int(centre[0]) - 180) <= 1);
  CHECK(std::abs(int(centre[1]) - 4) <= 1);
  CHECK(std::abs(int(centre[2]) - 38) <= 1);
  CHECK(int(centre[3]) == 255);
}
