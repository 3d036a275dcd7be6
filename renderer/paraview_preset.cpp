#include "paraview_preset.h"

#include <algorithm>
#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "error.h"
#include "io/json_file.h"
#include "scene_json.h"

namespace pvr::core {

namespace {

using namespace scene_json;

// A piecewise-linear function of the scalar with K components, given by
// knots sorted by x. Equal x are allowed and make a jump; outside the knots
// the function is clamped. left/right are the limits from below and above,
// equal except at a jump; at a knot of several equal x, left is the first
// knot's value and right the last's.
template <std::size_t K>
struct PiecewiseLinear {
  std::vector<double> x;
  std::vector<std::array<double, K>> y;

  std::array<double, K> left(double s) const {
    if (s <= x.front()) return y.front();
    if (s > x.back()) return y.back();
    const std::size_t i = std::size_t(std::lower_bound(x.begin(), x.end(), s) - x.begin());
    return x[i] == s ? y[i] : lerp(i - 1, s);
  }
  std::array<double, K> right(double s) const {
    if (s < x.front()) return y.front();
    if (s >= x.back()) return y.back();
    const std::size_t j = std::size_t(std::upper_bound(x.begin(), x.end(), s) - x.begin()) - 1;
    return x[j] == s ? y[j] : lerp(j, s);
  }

 private:
  // Between knots i and i + 1, which differ in x.
  std::array<double, K> lerp(std::size_t i, double s) const {
    const double t = (s - x[i]) / (x[i + 1] - x[i]);
    std::array<double, K> out;
    for (std::size_t c = 0; c < K; ++c) out[c] = y[i][c] + t * (y[i + 1][c] - y[i][c]);
    return out;
  }
};

// The knots of a flat array of 4-number groups ("RGBPoints": x, r, g, b;
// "Points": x, opacity, midpoint, sharpness), sorted by x. `value(v, path)`
// reads component c >= 1 of a group; the first K of them are the knot's y.
template <std::size_t K, typename ReadComponent>
PiecewiseLinear<K> readKnots(const json& v, const std::string& path, ReadComponent value) {
  constexpr std::size_t kStride = 4;
  if (!v.is_array() || v.empty() || v.size() % kStride != 0)
    fail(path, "must be a non-empty array of groups of 4 numbers, got " + describeValue(v));
  PiecewiseLinear<K> f;
  for (std::size_t i = 0; i < v.size(); i += kStride) {
    const double x = asNumber(v[i], indexPath(path, i));
    if (!f.x.empty() && x < f.x.back())
      fail(indexPath(path, i), "scalar " + numberText(x) + " is below the previous point's " +
                                   numberText(f.x.back()) + "; points must be sorted by scalar");
    std::array<double, K> y{};
    for (std::size_t c = 1; c < kStride; ++c) {
      const double component = value(v[i + c], indexPath(path, i + c), c);
      if (c <= K) y[c - 1] = component;
    }
    f.x.push_back(x);
    f.y.push_back(y);
  }
  return f;
}

}  // namespace

TransferFunctionSpec paraViewPresetFromJson(const json& doc, const std::string& path) {
  // Pick the preset: the document itself, or the first of an array.
  if (doc.is_array() && doc.empty())
    fail(path, "is an empty array (a preset file holds one preset object or an array of them)");
  const std::string at = doc.is_array() ? indexPath(path, 0) : path;
  const json& preset = doc.is_array() ? doc.front() : doc;
  if (!preset.is_object())
    fail(at, "must be a ParaView preset object, got " + describeValue(preset));
  const json* rgb = find(preset, "RGBPoints");
  if (!rgb) fail(at, "has no \"RGBPoints\" (not a colour transfer-function preset)");

  // Colour: x, r, g, b groups, linear RGB >= 0.
  const PiecewiseLinear<3> colour = readKnots<3>(
      *rgb, childPath(at, "RGBPoints"),
      [](const json& v, const std::string& p, std::size_t) { return nonNegative(v, p); });

  // Opacity: x, opacity, midpoint, sharpness groups. Midpoint and sharpness
  // shape ParaView's curve between points; here every segment is linear,
  // so they only have to be numbers.
  PiecewiseLinear<1> opacity;
  if (const json* points = find(preset, "Points")) {
    opacity = readKnots<1>(*points, childPath(at, "Points"),
                           [](const json& v, const std::string& p, std::size_t c) {
                             return c == 1 ? unitInterval(v, p) : asNumber(v, p);
                           });
  } else {
    opacity.x = {colour.x.front(), colour.x.back()};
    opacity.y = {{0.0}, {1.0}};
  }

  // Merge: both functions evaluated at the union of their knots; a jump in
  // either becomes two points at the same scalar.
  std::vector<double> xs = colour.x;
  xs.insert(xs.end(), opacity.x.begin(), opacity.x.end());
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  TransferFunctionSpec tf;
  for (double s : xs) {
    const auto cl = colour.left(s), cr = colour.right(s);
    const auto ol = opacity.left(s), orr = opacity.right(s);
    tf.points.push_back({s, cl[0], cl[1], cl[2], ol[0]});
    if (cl != cr || ol != orr) tf.points.push_back({s, cr[0], cr[1], cr[2], orr[0]});
  }
  return tf;
}

TransferFunctionSpec loadParaViewPreset(const std::string& path) {
  const json doc = readJsonFile(path);
  try {
    return paraViewPresetFromJson(doc, "");
  } catch (const Error& e) {
    throw Error(ErrorCode::kBadFile, path + ": " + e.what());
  }
}

}  // namespace pvr::core
