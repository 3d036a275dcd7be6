// Typed reading of scene JSON with key-path errors, shared by the scene's
// sections and the ParaView preset reader. Internal to the renderer.
//
// The reader is strict on purpose: a scene is typed by hand, and a misspelt
// key that silently falls back to a default renders a plausible but wrong
// image. Every error is pvr::Error(kInvalidArgument) whose message starts
// with the key path: "camera.fov_y_deg: must be in (0, 180), got 200".
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>

#include <nlohmann/json.hpp>

#include "vec.h"

namespace pvr::core::scene_json {

using nlohmann::json;

// Throws the error "path: what", its control bytes masked as '?' (keys and
// names are quoted from the document as they are).
[[noreturn]] void fail(const std::string& path, const std::string& what);

// Key paths: childPath("camera", "eye") = "camera.eye", childPath("", "x") = "x",
// indexPath("points", 2) = "points[2]".
std::string childPath(const std::string& path, const std::string& key);
std::string indexPath(const std::string& path, std::size_t i);

// Shortest text that reads back as the same number ("0.1", "200", not "200.0").
std::string numberText(double v);
// What the document held instead: "string \"abc\"", "array [1,2]", "null".
std::string describeValue(const json& v);
// "a, b, c": the names a message lists as known.
template <typename Range>
std::string joinNames(const Range& names) {
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + std::string(n);
  return list;
}

// Checks that `v` is an object and holds only keys from `known`.
void requireObject(const json& v, const std::string& path, std::initializer_list<const char*> known);
// The member `key` of an object, or nullptr.
const json* find(const json& object, const char* key);
// The one key of `alternatives` that `object` holds; holding none or more
// than one is an error ("volume: needs exactly one of " + what).
std::string exactlyOneOf(const json& object, const std::string& path,
                         std::initializer_list<const char*> alternatives, const std::string& what);

double asNumber(const json& v, const std::string& path);  // finite
std::int64_t asInteger(const json& v, const std::string& path);
bool asBool(const json& v, const std::string& path);
std::string asString(const json& v, const std::string& path);
Vec3 asVec3(const json& v, const std::string& path);  // 3 finite numbers
double positive(const json& v, const std::string& path);
double nonNegative(const json& v, const std::string& path);
double unitInterval(const json& v, const std::string& path);  // in [0, 1]

json toJson(Vec3 v);

// A relative path names a file beside the scene that mentions it.
std::string resolvePath(const std::string& file, const std::string& baseDir);

}  // namespace pvr::core::scene_json
