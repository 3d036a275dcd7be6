// The file formats volume_formats.cpp registers: one matches/open pair per
// format file. Internal to renderer/io; callers use openVolumeFile. Every
// `open` confines the files its header names to `within` when one is given
// (data_directory.h).
#pragma once

#include <memory>
#include <string>

#include "data_directory.h"
#include "volume_io.h"

namespace pvr::core {

// series_sidecar.cpp: NAME.series.json, a time series of volume files
// (registered before raw+json, which would take any .json).
bool isSeriesPath(const std::string& path);
std::unique_ptr<VolumeSource> openSeries(const std::string& path, const DataDirectory* within);

// raw_json.cpp: a raw voxel file plus its JSON sidecar (dims, dtype, spacing, ...).
bool isRawJsonPath(const std::string& path);
std::unique_ptr<VolumeSource> openRawJson(const std::string& path, const DataDirectory* within);
// A .raw opens through the sidecar beside it: a second name for that
// sidecar's dataset, not a dataset of its own.
bool isRawJsonDataPath(const std::string& path);

// nrrd.cpp: NRRD with an attached (.nrrd) or detached (.nhdr) header.
bool isNrrdPath(const std::string& path);
std::unique_ptr<VolumeSource> openNrrd(const std::string& path, const DataDirectory* within);

// nifti.cpp: NIfTI-1 single files (.nii, .nii.gz), 3-D or 4-D (a time series).
bool isNiftiPath(const std::string& path);
std::unique_ptr<VolumeSource> openNifti(const std::string& path, const DataDirectory* within);

}  // namespace pvr::core
