// NIfTI-1 single-file volumes (.nii, .nii.gz) through nifti_clib.
//
// nifti_clib converts the header (byte order, dim, pixdim, qform/sform,
// vox_offset); the voxels then go through the shared raw/gzip box reader, so
// an uncompressed .nii reads a brick in place at vox_offset and a .nii.gz
// decodes forward and keeps only the box. We look at the first 348 bytes
// ourselves before calling nifti_clib, because it reports a bad file by
// printing to stderr and returning NULL, which would leave our message
// unable to say what is wrong.
//
// Orientation: the qform (else the sform, else |pixdim| along the index
// axes from 0) places the voxels in scanner space; flipped and permuted
// axes are read in scanner order, an oblique rotation is shown on the
// nearest axes and noted (orientation.h). A scl_slope other than 0 or 1 (or a nonzero scl_inter) makes the
// volume float32 with the scaling applied, since the stored integers are
// not the values the file means.
//
// A 4-D file (dim[0] = 4, dim[4] = T > 1) is a time series (series.h): step
// k is the k-th 3-D volume, at time toffset + k * pixdim[4] (in the file's
// time units), or at time k when pixdim[4] is not positive.
#include <nifti/nifti1_io.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "byte_stream.h"
#include "formats.h"
#include "gzip_stream.h"
#include "orientation.h"
#include "raw_reader.h"
#include "series.h"
#include "source_util.h"

namespace pvr::core {

namespace {

constexpr std::size_t kNifti1HeaderBytes = 348;
// nifti_image::byteorder of big-endian data (nifti1_io.h defines MSB_FIRST
// only for nifti1_io.c itself).
constexpr int kNiftiMsbFirst = 2;

// Step 1: sizeof_hdr and the magic, read from the (decoded) file start.
void checkNifti1Header(const std::string& path, bool gzip) {
  unsigned char raw[kNifti1HeaderBytes];
  auto* bytes = reinterpret_cast<std::byte*>(raw);
  if (gzip) {
    GzipStream(path, 0).read(0, bytes, sizeof raw);
  } else {
    const std::uint64_t size = fileSizeOf(path);
    if (size < sizeof raw)
      failAt(ErrorCode::kBadFile, path,
             "file has " + std::to_string(size) + " bytes, a NIfTI-1 header needs 348");
    FileStream(path).read(0, bytes, sizeof raw);
  }
  std::int32_t sizeofHdr;
  std::memcpy(&sizeofHdr, raw, 4);
  const std::int32_t swapped = std::int32_t(__builtin_bswap32(std::uint32_t(sizeofHdr)));
  if (sizeofHdr == 540 || swapped == 540)
    failAt(ErrorCode::kUnsupported, path, "NIfTI-2 files are not supported, only NIfTI-1");
  if (sizeofHdr != 348 && swapped != 348)
    failAt(ErrorCode::kBadFile, path,
           "not a NIfTI-1 file: header size field is " + std::to_string(sizeofHdr) + ", expected 348");
  const char* magic = reinterpret_cast<const char*>(raw + 344);
  if (std::memcmp(magic, "ni1", 4) == 0)
    failAt(ErrorCode::kUnsupported, path, "a .hdr/.img pair header; only single-file .nii is supported");
  if (std::memcmp(magic, "n+1", 4) != 0)
    failAt(ErrorCode::kBadFile, path,
           "no NIfTI-1 magic 'n+1' (found " + quoteForMessage(std::string_view(magic, 4)) + ")");
}

ScalarType niftiScalarType(const nifti_image& nim, const std::string& path) {
  switch (nim.datatype) {
    case DT_UINT8: return ScalarType::kUInt8;
    case DT_UINT16: return ScalarType::kUInt16;
    case DT_INT16: return ScalarType::kInt16;
    case DT_FLOAT32: return ScalarType::kFloat32;
    default: break;
  }
  failAt(ErrorCode::kUnsupported, path,
         std::string("datatype ") + nifti_datatype_string(nim.datatype) +
             " is not supported (UINT8, UINT16, INT16, FLOAT32)");
}

// The index grid: dims and |pixdim| (orientation comes from niftiFrame).
GridGeometry niftiGrid(const nifti_image& nim, const std::string& path) {
  for (int d = 5; d <= 7; ++d)
    if (nim.dim[d] > 1)
      failAt(ErrorCode::kUnsupported, path,
             "dimension " + std::to_string(d) + " has " + std::to_string(nim.dim[d]) +
                 " entries; only 3D volumes and 4D time series are supported");
  GridGeometry grid;
  grid.dims = {std::max(nim.nx, 1), std::max(nim.ny, 1), std::max(nim.nz, 1)};
  grid.spacing = {std::fabs(nim.dx), std::fabs(nim.dy), std::fabs(nim.dz)};
  return grid;
}

// Index to scanner space: the qform, else the sform, else the index grid.
IndexFrame niftiFrame(const nifti_image& nim, const GridGeometry& grid) {
  const mat44* m = nim.qform_code > 0 ? &nim.qto_xyz : nim.sform_code > 0 ? &nim.sto_xyz : nullptr;
  IndexFrame frame;
  if (!m) {
    for (int a = 0; a < 3; ++a) frame.axes[std::size_t(a)][a] = grid.spacing[a];
    return frame;
  }
  for (int a = 0; a < 3; ++a) frame.axes[std::size_t(a)] = Vec3{m->m[0][a], m->m[1][a], m->m[2][a]};
  frame.origin = Vec3{m->m[0][3], m->m[1][3], m->m[2][3]};
  return frame;
}

// Applies value = slope * stored + inter, turning the volume into float32.
class ScaledSource final : public VolumeSource {
 public:
  ScaledSource(std::unique_ptr<VolumeSource> stored, double slope, double inter)
      : stored_(std::move(stored)), slope_(slope), inter_(inter) {}

  const GridGeometry& grid() const override { return stored_->grid(); }
  ScalarType type() const override { return ScalarType::kFloat32; }
  bool canReadPartially() const override { return stored_->canReadPartially(); }
  Brick readBox(const NodeBox& owned, const NodeBox& stored) const override {
    const Brick in = stored_->readBox(owned, stored);
    Brick out(in.grid(), ScalarType::kFloat32, owned, stored);
    float* v = out.as<float>();
    dispatchScalar(in.type(), [&](auto tag) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
      const T* s = in.as<T>();
      for (std::size_t i = 0, n = std::size_t(stored.nodeCount()); i < n; ++i)
        v[i] = float(slope_ * double(s[i]) + inter_);
    });
    out.updateValueRange();
    return out;
  }
  std::string caveat() const override { return stored_->caveat(); }
  void setFineCounts(bool on) override { stored_->setFineCounts(on); }
  void prefetchBox(const NodeBox& stored) const override { stored_->prefetchBox(stored); }
  std::string describe() const override {
    return stored_->describe() + " scaled to float32 (" + std::to_string(slope_) + " * v + " +
           std::to_string(inter_) + ")";
  }

 private:
  std::unique_ptr<VolumeSource> stored_;
  double slope_, inter_;
};

}  // namespace

bool isNiftiPath(const std::string& path) {
  return pathEndsWith(path, ".nii") || pathEndsWith(path, ".nii.gz");
}

// One file, no names inside: openVolumeFile confined it already.
std::unique_ptr<VolumeSource> openNifti(const std::string& path, const DataDirectory*) {
  const bool gzip = pathEndsWith(path, ".gz");
  checkNifti1Header(path, gzip);

  // Step 2: nifti_clib converts the header; the voxels are left to us.
  const std::unique_ptr<nifti_image, void (*)(nifti_image*)> nim(nifti_image_read(path.c_str(), 0),
                                                                 &nifti_image_free);
  if (!nim) failAt(ErrorCode::kBadFile, path, "nifti_clib cannot read the NIfTI-1 header");
  const ScalarType type = niftiScalarType(*nim, path);
  const GridGeometry indexGrid = niftiGrid(*nim, path);
  const Orientation orientation = orientationOf(niftiFrame(*nim, indexGrid), indexGrid.dims, path);
  // The voxels in file order: the index grid when they are reordered,
  // else already the grid in space.
  const GridGeometry grid = orientation.reorders() ? indexGrid : orientation.grid;
  const std::string name = fileNameOf(path) + obliqueNote(orientation);

  // Step 3: the voxels start at vox_offset, in the file or in the gzip stream.
  RawLayout layout;
  layout.dataPath = path;
  layout.encoding = gzip ? RawEncoding::kGzip : RawEncoding::kRaw;
  layout.offset = std::uint64_t(std::max(nim->iname_offset, 0));
  layout.bigEndian = nim->byteorder == kNiftiMsbFirst;
  const double slope = nim->scl_slope, inter = nim->scl_inter;
  const bool scaled = std::isfinite(slope) && std::isfinite(inter) && slope != 0 && (slope != 1 || inter != 0);
  // Scaled, then shown in scanner space.
  const auto applyScaling = [&](std::unique_ptr<VolumeSource> stored) -> std::unique_ptr<VolumeSource> {
    if (scaled) stored = std::make_unique<ScaledSource>(std::move(stored), slope, inter);
    return reoriented(std::move(stored), orientation);
  };
  const std::int64_t timeSteps = nim->dim[0] >= 4 ? std::max<std::int64_t>(nim->dim[4], 1) : 1;
  if (timeSteps == 1)
    return applyScaling(openRawVolume(name, grid, type, std::move(layout), SizeRule::kAtLeast));

  // Step 4: a time series, the 3-D volumes one after another.
  const double dt = std::isfinite(nim->dt) && nim->dt > 0 ? nim->dt : 1.0;
  const double t0 = nim->dt > 0 && std::isfinite(nim->toffset) ? nim->toffset : 0.0;
  std::vector<SeriesStep> steps;
  for (auto& step : openPackedSteps(name, grid, type, layout, timeSteps, SizeRule::kAtLeast))
    steps.push_back({t0 + double(steps.size()) * dt, applyScaling(std::move(step)),
                     "volume " + std::to_string(steps.size()), ""});
  return makeSeries(path, fileNameOf(path), std::move(steps));
}

}  // namespace pvr::core
