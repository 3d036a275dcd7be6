// The series sidecar NAME.series.json: a time series whose steps are volume
// files of any registered format, relative to the sidecar's directory:
//   {"series": [{"time": 0.0, "file": "a/step0.nhdr"}, {"time": 0.5, "file": ...}, ...]}
// or a numbered pattern (series.h, patternSteps):
//   {"pattern": "run/step_%04d.nii.gz", "steps": 50, "first": 1, "time_step": 0.1}
// plus an optional "description". Opening it opens every step's header,
// which also checks that every step file exists and holds its data.
#include <nlohmann/json.hpp>

#include "formats.h"
#include "json_file.h"
#include "series.h"
#include "source_util.h"

namespace pvr::core {

namespace {

using nlohmann::json;

// A series sidecar is typed by hand: a misspelt key would silently fall
// back to a default, so unknown keys are refused.
void requireKnownKeys(const json& doc, const std::string& path) {
  static const char* const kKnown[] = {"series", "pattern", "steps", "first", "times", "time_step", "description"};
  for (const auto& item : doc.items()) {
    bool known = false;
    for (const char* k : kKnown) known = known || item.key() == k;
    if (!known)
      failAt(ErrorCode::kBadFile, path,
             "unknown key '" + item.key() + "' (known: series, pattern, steps, first, times, time_step, description)");
  }
}

// The "series" list: each entry {"time": T, "file": PATH}.
std::vector<PatternStep> listedSteps(const json& list, const std::string& path) {
  if (!list.is_array() || list.empty())
    failAt(ErrorCode::kBadFile, path, "'series' must be a non-empty array of {\"time\": T, \"file\": PATH}");
  if (std::int64_t(list.size()) > kMaxSeriesSteps)
    failAt(ErrorCode::kBadFile, path, "'series' has more than " + std::to_string(kMaxSeriesSteps) + " steps");
  std::vector<PatternStep> steps;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& e = list[k];
    const std::string at = "series[" + std::to_string(k) + "]";
    const bool ok = e.is_object() && e.size() == 2 && e.contains("time") && e.contains("file") &&
                    e["time"].is_number() && e["file"].is_string();
    if (!ok) failAt(ErrorCode::kBadFile, path, at + " must be {\"time\": T, \"file\": PATH}, got " + e.dump());
    steps.push_back({e["file"].get<std::string>(), e["time"].get<double>()});
  }
  return steps;
}

}  // namespace

bool isSeriesPath(const std::string& path) { return pathEndsWith(path, ".series.json"); }

std::unique_ptr<VolumeSource> openSeries(const std::string& path, const DataDirectory* within) {
  const json doc = readJsonFile(path);
  if (!doc.is_object()) failAt(ErrorCode::kBadFile, path, "a series sidecar is a JSON object");
  requireKnownKeys(doc, path);
  const bool listed = doc.contains("series");
  if (listed == doc.contains("pattern"))
    failAt(ErrorCode::kBadFile, path, "needs exactly one of 'series' (a list of steps) or 'pattern' (numbered files)");
  if (listed)
    for (const char* key : {"steps", "first", "times", "time_step"})
      if (doc.contains(key)) failAt(ErrorCode::kBadFile, path, std::string("'") + key + "' belongs with 'pattern'");

  const std::vector<PatternStep> named = listed ? listedSteps(doc["series"], path) : patternSteps(doc, path);
  std::vector<SeriesStep> steps;
  steps.reserve(named.size());
  for (std::size_t k = 0; k < named.size(); ++k) {
    const std::string file = stepFilePath(path, named[k].file, path, std::int64_t(k));
    auto volume = openStep(path, std::int64_t(k), named[k].file, file, [&] {
      // Refused by name: a sidecar naming itself would never return.
      if (isSeriesPath(file)) failAt(ErrorCode::kBadFile, file, "is itself a series sidecar; a step is one volume");
      return openVolumeFile(file, within);
    });
    steps.push_back({named[k].time, std::move(volume), named[k].file, file});
  }
  return makeSeries(path, fileNameOf(path), std::move(steps));
}

}  // namespace pvr::core
