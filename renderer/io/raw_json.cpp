// Raw voxels plus a JSON sidecar, the form of ../shared/data/<name>/<name>.json:
//   {"dims": [nx, ny, nz], "dtype": "int16", "spacing": [sx, sy, sz],
//    "origin": [ox, oy, oz]            (optional, default 0),
//    "raw_file": "<name>.raw"          (optional, default: the .raw beside the sidecar),
//    "pattern": "step_%04d.raw", "steps": N, ...
//                                      (instead of raw_file: a time series, one raw
//                                       file per step, keys of series.h patternSteps),
//    "endian": "little" | "big"        (optional, default little), ...}
// Other keys (provenance, licence, statistics) are ignored. Either file may
// be given: a .raw finds its sidecar beside it, <stem>.json. The writer of
// the same form is here too.
#include <bit>
#include <filesystem>
#include <fstream>

#include "formats.h"
#include "json_file.h"
#include "raw_reader.h"
#include "series.h"
#include "source_util.h"

namespace pvr::core {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json readSidecar(const std::string& path) {
  json doc = readJsonFile(path);
  if (!doc.is_object()) failAt(ErrorCode::kBadFile, path, "sidecar is not a JSON object");
  return doc;
}

const json& member(const json& doc, const char* key, const std::string& path) {
  const auto it = doc.find(key);
  if (it == doc.end()) failAt(ErrorCode::kBadFile, path, std::string("sidecar has no '") + key + "' key");
  return *it;
}

bool isTriple(const json& v) { return v.is_array() && v.size() == 3; }

IVec3 readDims(const json& doc, const std::string& path) {
  const json& v = member(doc, "dims", path);
  IVec3 dims;
  if (isTriple(v))
    for (int a = 0; a < 3; ++a)
      if (v[a].is_number_integer() && v[a].get<std::int64_t>() >= 1) dims[a] = v[a].get<std::int64_t>();
  if (dims.x < 1 || dims.y < 1 || dims.z < 1)
    failAt(ErrorCode::kBadFile, path, "'dims' must be 3 positive integers, got " + v.dump());
  return dims;
}

Vec3 readTriple(const json& v, const char* key, const std::string& path) {
  Vec3 out;
  bool ok = isTriple(v);
  for (int a = 0; ok && a < 3; ++a) {
    ok = v[a].is_number();
    if (ok) out[a] = v[a].get<double>();
  }
  if (!ok) failAt(ErrorCode::kBadFile, path, std::string("'") + key + "' must be 3 numbers, got " + v.dump());
  return out;
}

std::string readString(const json& v, const char* key, const std::string& path) {
  if (!v.is_string())
    failAt(ErrorCode::kBadFile, path, std::string("'") + key + "' must be a string, got " + v.dump());
  return v.get<std::string>();
}

bool readBigEndian(const json& doc, const std::string& path) {
  const auto it = doc.find("endian");
  if (it == doc.end()) return false;
  const std::string endian = readString(*it, "endian", path);
  if (endian != "little" && endian != "big")
    failAt(ErrorCode::kBadFile, path, "'endian' must be \"little\" or \"big\", got \"" + endian + "\"");
  return endian == "big";
}

// The raw file the sidecar describes. Given a .raw, it must be that file.
std::string rawPathFor(const json& doc, const std::string& jsonPath, const std::string& givenRaw) {
  const auto it = doc.find("raw_file");
  if (it == doc.end())
    return givenRaw.empty() ? fs::path(jsonPath).replace_extension(".raw").string() : givenRaw;
  const fs::path named = fs::path(jsonPath).parent_path() / readString(*it, "raw_file", jsonPath);
  if (!givenRaw.empty()) {
    std::error_code ec;
    if (!fs::equivalent(named, givenRaw, ec))
      failAt(ErrorCode::kBadFile, givenRaw,
             "sidecar " + jsonPath + " describes '" + named.string() + "', not this file");
  }
  return named.string();
}

// A sidecar with "pattern": step k's voxels are the whole raw file the
// pattern names for it; the sidecar's grid, type and byte order apply to
// every step.
std::unique_ptr<VolumeSource> openRawSeries(const json& doc, const std::string& jsonPath, const std::string& givenRaw,
                                            const GridGeometry& grid, ScalarType type, const RawLayout& layout,
                                            const DataDirectory* within) {
  if (!givenRaw.empty())
    failAt(ErrorCode::kBadFile, givenRaw,
           "sidecar " + jsonPath + " describes a time series ('pattern'); open the sidecar, not a step's raw file");
  if (doc.contains("raw_file")) failAt(ErrorCode::kBadFile, jsonPath, "give 'raw_file' or 'pattern', not both");
  std::vector<SeriesStep> steps;
  for (const PatternStep& named : patternSteps(doc, jsonPath)) {
    const std::int64_t k = std::int64_t(steps.size());
    RawLayout step = layout;
    step.dataPath = confineTo(within, stepFilePath(jsonPath, named.file, jsonPath, k), jsonPath);
    step.headerPath.clear();  // the step's label names the sidecar already
    auto volume = openStep(jsonPath, k, named.file, step.dataPath, [&] {
      return openRawVolume(fileNameOf(step.dataPath), grid, type, step, SizeRule::kExact);
    });
    steps.push_back({named.time, std::move(volume), named.file, step.dataPath});
  }
  return makeSeries(jsonPath, fileNameOf(jsonPath), std::move(steps));
}

}  // namespace

bool isRawJsonPath(const std::string& path) {
  return pathEndsWith(path, ".json") || pathEndsWith(path, ".raw");
}

bool isRawJsonDataPath(const std::string& path) { return pathEndsWith(path, ".raw"); }

std::unique_ptr<VolumeSource> openRawJson(const std::string& path, const DataDirectory* within) {
  // Step: find the sidecar (the path itself, or <stem>.json beside a .raw).
  const bool givenRaw = isRawJsonDataPath(path);
  std::string jsonPath = givenRaw ? fs::path(path).replace_extension(".json").string() : path;
  if (givenRaw && !fs::exists(jsonPath))
    failAt(ErrorCode::kIo, path, "no JSON sidecar " + jsonPath + " beside it (dims, dtype, spacing)");
  if (givenRaw) jsonPath = confineTo(within, jsonPath, path);
  const json doc = readSidecar(jsonPath);

  // Step: the grid, type and byte order it states.
  GridGeometry grid;
  grid.dims = readDims(doc, jsonPath);
  grid.spacing = readTriple(member(doc, "spacing", jsonPath), "spacing", jsonPath);
  if (const auto it = doc.find("origin"); it != doc.end()) grid.origin = readTriple(*it, "origin", jsonPath);
  const ScalarType type = parseScalarType(readString(member(doc, "dtype", jsonPath), "dtype", jsonPath), jsonPath);

  RawLayout layout;
  layout.headerPath = jsonPath;
  layout.bigEndian = readBigEndian(doc, jsonPath);
  if (doc.contains("pattern"))
    return openRawSeries(doc, jsonPath, givenRaw ? path : std::string(), grid, type, layout, within);
  layout.dataPath = confineTo(within, rawPathFor(doc, jsonPath, givenRaw ? path : std::string()), jsonPath);
  return openRawVolume(fileNameOf(path), grid, type, std::move(layout), SizeRule::kExact);
}

std::string writeRawJsonVolume(const Brick& volume, const std::string& dir, const std::string& stem,
                               const std::string& description) {
  const GridGeometry& g = volume.grid();
  if (volume.stored() != g.allNodes())
    throw Error(ErrorCode::kInternal, "writeRawJsonVolume: the brick must store the whole grid");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) failAt(ErrorCode::kIo, dir, "cannot create the directory: " + ec.message());

  const fs::path raw = fs::path(dir) / (stem + ".raw");
  std::ofstream rawOut(raw, std::ios::binary);
  rawOut.write(reinterpret_cast<const char*>(volume.bytes()), std::streamsize(volume.byteSize()));
  rawOut.close();
  if (!rawOut) failAt(ErrorCode::kIo, raw.string(), "cannot write");

  const json sidecar = {{"dims", {g.dims.x, g.dims.y, g.dims.z}},
                        {"dtype", std::string(scalarName(volume.type()))},
                        {"spacing", {g.spacing.x, g.spacing.y, g.spacing.z}},
                        {"origin", {g.origin.x, g.origin.y, g.origin.z}},
                        {"raw_file", raw.filename().string()},
                        {"endian", std::endian::native == std::endian::big ? "big" : "little"},
                        {"description", description}};
  const fs::path jsonPath = fs::path(dir) / (stem + ".json");
  std::ofstream jsonOut(jsonPath);
  jsonOut << sidecar.dump(2) << "\n";
  jsonOut.close();
  if (!jsonOut) failAt(ErrorCode::kIo, jsonPath.string(), "cannot write");
  return jsonPath.string();
}

}  // namespace pvr::core
