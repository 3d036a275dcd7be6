// The format registry and opening a volume file by its extension.
#include <filesystem>

#include "formats.h"
#include "series.h"
#include "source_util.h"

namespace pvr::core {

const std::vector<VolumeFormat>& volumeFormats() {
  // One line per format: a new format is one new file plus one line here.
  static const std::vector<VolumeFormat> kFormats = {
      {"series", &isSeriesPath, &openSeries, ".series.json"},
      {"raw+json", &isRawJsonPath, &openRawJson, ".json .raw"},
      {"nrrd", &isNrrdPath, &openNrrd, ".nrrd .nhdr"},
      {"nifti", &isNiftiPath, &openNifti, ".nii .nii.gz"},
  };
  return kFormats;
}

bool isDatasetFileName(const std::string& name) {
  if (isRawJsonDataPath(name)) return false;
  for (const VolumeFormat& format : volumeFormats())
    if (format.matches(name)) return true;
  return false;
}

std::unique_ptr<VolumeSource> openVolumeFile(const std::string& path, const DataDirectory* within) {
  if (within) within->require(path, "dataset");
  // A missing file is the likeliest mistake: say so before talking formats.
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) failAt(ErrorCode::kIo, path, "no such file");
  for (const VolumeFormat& format : volumeFormats())
    if (format.matches(path)) return format.open(path, within);

  std::string supported;
  for (const VolumeFormat& format : volumeFormats())
    supported += std::string(supported.empty() ? "" : ", ") + format.extensions + " (" +
                 format.name + ")";
  failAt(ErrorCode::kUnsupported, path, "unknown volume file extension; supported: " + supported);
}

}  // namespace pvr::core
