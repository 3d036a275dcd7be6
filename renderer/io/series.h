// Time series: a VolumeSource whose steps() > 1 volumes share one grid and
// scalar type (the contract is VolumeSource::steps/stepTime/step in
// volume_io.h). Three forms open through openVolumeFile (docs/scene.md,
// "Time series"):
//   NAME.series.json   {"series": [{"time": T, "file": PATH}, ...]} or a
//                      numbered pattern {"pattern": "step_%04d.nhdr", "steps": N};
//                      step files of any registered format (series_sidecar.cpp)
//   a raw+JSON sidecar with "pattern" in place of "raw_file" (raw_json.cpp)
//   a 4-D NIfTI, dim[4] > 1 (nifti.cpp)
// This header is what those three share: assembling and checking a series,
// the numbered pattern, and where a sidecar's entries may point.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "raw_reader.h"
#include "volume_io.h"

namespace pvr::core {

// A series longer than this is refused before any step file is looked at:
// opening a series opens every step's header.
inline constexpr std::int64_t kMaxSeriesSteps = std::int64_t(1) << 20;

// One step of a series being assembled.
struct SeriesStep {
  double time = 0;
  std::unique_ptr<VolumeSource> volume;
  std::string label;  // the step's file as its sidecar names it, quoted in messages
  std::string file;   // that file's path, for seriesFiles(); empty when the step has no file of its own
};

// A series of `steps` (at least one) that describe() calls `name`
// ("run.series.json: 50 steps of 256x256x256 uint8"). Checks that every step
// has step 0's dims, spacing, origin and scalar type, that no step is itself
// a series and that the times are finite and increasing; throws
// pvr::Error(kBadFile) starting with `where` (the sidecar's path) and naming
// the step: "...: step 7 'b/step_0007.nhdr': dims 64x64x65 differ from step 0's 64x64x64".
std::unique_ptr<VolumeSource> makeSeries(std::string where, std::string name, std::vector<SeriesStep> steps);

// Runs open() for step `k` named `label` in the sidecar `where`; a
// pvr::Error it throws comes back as "<where>: step k '<label>': <what>".
std::unique_ptr<VolumeSource> openStep(std::string_view where, std::int64_t k, std::string_view label,
                                       const std::string& file,
                                       const std::function<std::unique_ptr<VolumeSource>()>& open);

// The path of a file that the sidecar at `sidecarPath` names as `entry`:
// relative to the sidecar's directory and inside it. Absolute entries,
// entries with a ".." component and entries whose real path (symlinks
// resolved) leaves the directory throw pvr::Error(kBadFile) starting with
// `where` and naming the step. A missing file is returned as it is, for
// the opener to report.
std::string stepFilePath(const std::string& sidecarPath, const std::string& entry, std::string_view where,
                         std::int64_t k);

// A numbered file name from a file: "step_%04d.raw" holds exactly one
// integer conversion, %d or %0Nd with N in 1..9 ("%%" is a percent sign).
// Anything else (%s, %n, %5d, two conversions, a width over 9) throws
// pvr::Error(kBadFile) naming `where`. The pattern is never handed to printf.
class StepPattern {
 public:
  StepPattern(const std::string& pattern, std::string_view where);
  std::string fileFor(std::int64_t index) const;

 private:
  std::string prefix_, suffix_;
  int width_ = 0;  // 0: no padding (%d)
};

// The steps a "pattern" object describes: the keys "pattern", "steps",
// "first" (index of step 0, default 0) and either "times" (one number per
// step) or "time_step" (step k at time k * time_step, default 1). Returns
// each step's file name and time; throws pvr::Error(kBadFile) naming
// `where` and the key.
struct PatternStep {
  std::string file;
  double time = 0;
};
std::vector<PatternStep> patternSteps(const nlohmann::json& doc, std::string_view where);

// Steps stored back to back in one data stream (a 4-D NIfTI): step k's
// voxels start at layout.offset + k * (the grid's voxel bytes). Checks once
// that the data holds all `count` steps (as openRawVolume does, under
// `rule`) and returns one source per step, described as "<name> step k".
std::vector<std::unique_ptr<VolumeSource>> openPackedSteps(const std::string& name, const GridGeometry& grid,
                                                           ScalarType type, const RawLayout& layout,
                                                           std::int64_t count, SizeRule rule);

// For catalogs, which list each dataset once: a series, not its step files.
//
// isDatasetFileName: whether a registered format opens `name` as a dataset
// of its own (volume_formats.cpp; a .raw is its sidecar's data, not one).
// seriesFiles: the files a series reads its steps from; empty for a single
// volume or a series whose steps live in one file.
bool isDatasetFileName(const std::string& name);
std::vector<std::string> seriesFiles(const VolumeSource& source);

}  // namespace pvr::core
