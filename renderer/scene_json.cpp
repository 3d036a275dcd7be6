#include "scene_json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "error.h"

namespace pvr::core::scene_json {

namespace {

// `text` with every control byte (below 0x20, and DEL) shown as '?'. Keys
// and names come from the document as they are: a NUL would cut the message
// short where it is read as a C string (what(), the wire's error text), and
// an escape sequence would reach the user's terminal or pvrd's log.
std::string maskControlBytes(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return text;
}

}  // namespace

void fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, maskControlBytes(path.empty() ? what : path + ": " + what));
}

std::string childPath(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string indexPath(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string numberText(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  if (v == std::trunc(v) && std::abs(v) < 1e15) return std::to_string(std::int64_t(v));
  return json(v).dump();
}

std::string describeValue(const json& v) {
  if (v.is_null()) return "null";
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(v.type_name()) + " " + text;
}

void requireObject(const json& v, const std::string& path, std::initializer_list<const char*> known) {
  if (!v.is_object()) fail(path.empty() ? "scene" : path, "must be an object, got " + describeValue(v));
  for (const auto& item : v.items()) {
    const bool isKnown = std::any_of(known.begin(), known.end(),
                                     [&](const char* k) { return item.key() == k; });
    if (!isKnown) fail(childPath(path, item.key()), "unknown key (known: " + joinNames(known) + ")");
  }
}

const json* find(const json& object, const char* key) {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

std::string exactlyOneOf(const json& object, const std::string& path,
                         std::initializer_list<const char*> alternatives, const std::string& what) {
  const char* held = nullptr;
  for (const char* key : alternatives) {
    if (!object.contains(key)) continue;
    if (held) fail(path, "needs exactly one of " + what);
    held = key;
  }
  if (!held) fail(path, "needs exactly one of " + what);
  return held;
}

double asNumber(const json& v, const std::string& path) {
  if (!v.is_number()) fail(path, "must be a number, got " + describeValue(v));
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(path, "must be finite, got " + numberText(d));
  return d;
}

std::int64_t asInteger(const json& v, const std::string& path) {
  if (!v.is_number_integer()) fail(path, "must be an integer, got " + describeValue(v));
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(INT64_MAX))
    fail(path, "is too large, got " + v.dump());
  return v.get<std::int64_t>();
}

bool asBool(const json& v, const std::string& path) {
  if (!v.is_boolean()) fail(path, "must be true or false, got " + describeValue(v));
  return v.get<bool>();
}

std::string asString(const json& v, const std::string& path) {
  if (!v.is_string()) fail(path, "must be a string, got " + describeValue(v));
  return v.get<std::string>();
}

Vec3 asVec3(const json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3) fail(path, "must be an array of 3 numbers, got " + describeValue(v));
  return {asNumber(v[0], indexPath(path, 0)), asNumber(v[1], indexPath(path, 1)),
          asNumber(v[2], indexPath(path, 2))};
}

double positive(const json& v, const std::string& path) {
  const double d = asNumber(v, path);
  if (!(d > 0)) fail(path, "must be > 0, got " + numberText(d));
  return d;
}

double nonNegative(const json& v, const std::string& path) {
  const double d = asNumber(v, path);
  if (!(d >= 0)) fail(path, "must be >= 0, got " + numberText(d));
  return d;
}

double unitInterval(const json& v, const std::string& path) {
  const double d = asNumber(v, path);
  if (!(d >= 0 && d <= 1)) fail(path, "must be in [0, 1], got " + numberText(d));
  return d;
}

json toJson(Vec3 v) { return json::array({v.x, v.y, v.z}); }

std::string resolvePath(const std::string& file, const std::string& baseDir) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  if (p.is_absolute() || baseDir.empty()) return file;
  return (fs::path(baseDir) / p).lexically_normal().string();
}

}  // namespace pvr::core::scene_json
