// A volume of the scene (the "volume" section, or one entry of "volumes"): a
// volume file, a procedural volume or a user computation; and the top-level
// "timestep", the step of a time-series volume to render.
#include <algorithm>

#include "io/volume_io.h"
#include "scene_json.h"
#include "scene_sections.h"

namespace pvr::core {

using namespace scene_json;

VolumeSpec parseVolume(const json& v, const std::string& baseDir, const std::string& path) {
  requireObject(v, path, {"file", "procedural", "computation", "dims", "spacing"});
  VolumeSpec spec;
  const std::string form = exactlyOneOf(v, path, {"file", "procedural", "computation"},
                                        "'file' (a volume file), 'procedural' (a generated volume) or "
                                        "'computation' (a user computation on the ranks)");
  if (form == "file") {
    for (const char* key : {"dims", "spacing"})
      if (find(v, key)) fail(childPath(path, key), "only for a procedural or computation volume (a file carries its own)");
    spec.file = asString(v["file"], path + ".file");
    if (spec.file.empty()) fail(path + ".file", "must not be empty");
    spec.file = resolvePath(spec.file, baseDir);
    return spec;
  }

  if (form == "procedural") {
    spec.procedural = asString(v["procedural"], path + ".procedural");
    const std::vector<std::string> names = proceduralNames();
    if (std::find(names.begin(), names.end(), spec.procedural) == names.end())
      fail(path + ".procedural",
           "unknown procedural volume '" + spec.procedural + "' (known: " + joinNames(names) + ")");
  } else {
    // Which computations exist is the ranks' registry's to say (node/computations/).
    spec.computation = asString(v["computation"], path + ".computation");
    if (spec.computation.empty()) fail(path + ".computation", "must not be empty");
  }
  if (const json* dims = find(v, "dims")) {
    const std::string p = path + ".dims";
    if (!dims->is_array() || dims->size() != 3)
      fail(p, "must be an array of 3 integers, got " + describeValue(*dims));
    for (int a = 0; a < 3; ++a) {
      const std::int64_t d = asInteger((*dims)[a], indexPath(p, a));
      if (d < 1 || d > INT32_MAX)
        fail(indexPath(p, a), "must be in 1.." + std::to_string(INT32_MAX) + ", got " + std::to_string(d));
      spec.dims[a] = d;
    }
  }
  if (const json* spacing = find(v, "spacing")) {
    const std::string p = path + ".spacing";
    const Vec3 s = asVec3(*spacing, p);
    for (int a = 0; a < 3; ++a)
      if (!(s[a] > 0)) fail(indexPath(p, a), "must be > 0, got " + numberText(s[a]));
    spec.spacing = s;
  }
  return spec;
}

int parseTimestep(const json& v) {
  const std::int64_t k = asInteger(v, "timestep");
  if (k < 0 || k > INT32_MAX)
    fail("timestep", "must be in 0.." + std::to_string(INT32_MAX) + " (a 0-based step), got " + std::to_string(k));
  return int(k);
}

json volumeToJson(const VolumeSpec& volume) {
  if (!volume.file.empty()) return {{"file", volume.file}};
  json out = {{"dims", json::array({volume.dims.x, volume.dims.y, volume.dims.z})}};
  if (!volume.computation.empty()) out["computation"] = volume.computation;
  else out["procedural"] = volume.procedural;
  if (volume.spacing) out["spacing"] = toJson(*volume.spacing);
  return out;
}

}  // namespace pvr::core
