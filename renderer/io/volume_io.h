// Opening volumes: files of every registered format and procedural volumes.
//
// A VolumeSource knows a volume's grid and scalar type after reading only
// its header, and reads any box of nodes on demand. Raw-encoded files read a
// box without touching the rest of the file (rank r of an MPI job reads only
// its brick plus ghosts); other encodings (gzip) read the whole and crop,
// and say so through canReadPartially() so a caller can read once and scatter.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../brick.h"

namespace pvr::core {

class DataDirectory;  // data_directory.h

class VolumeSource {
 public:
  virtual ~VolumeSource() = default;
  virtual const GridGeometry& grid() const = 0;
  virtual ScalarType type() const = 0;
  // True when readBox costs I/O proportional to the box, not the volume.
  virtual bool canReadPartially() const = 0;
  // The nodes of `stored` (which must contain `owned` and lie in the grid)
  // as a brick that renders `owned`. Throws pvr::Error naming the file.
  virtual Brick readBox(const NodeBox& owned, const NodeBox& stored) const = 0;
  // A short description for logs and catalogs ("ct.nhdr: 256x256x108 int16").
  virtual std::string describe() const = 0;
  // What the rendering does not show as the file says, for a warning in the
  // catalog, `list status` and `:s info` (an oblique orientation rendered
  // on the nearest axes, orientation.h); empty when it shows it as it is.
  virtual std::string caveat() const { return ""; }

  Brick readAll() const { return readBox(grid().allNodes(), grid().allNodes()); }

  // Whether readBox also counts the histogram's fine keys
  // (Brick::fineHistogram, value_histogram.h) where the reader fuses them
  // into the read (raw data); on by default. Off for a caller that never
  // reports a histogram (pvr-node --batch): counting is most of the
  // preprocessing of a brick that is not air. Sources over other sources
  // pass it on.
  virtual void setFineCounts(bool /*on*/) {}

  // Asks the storage to start fetching the nodes of `stored` (a later
  // readBox's stored box) without waiting for them, so that read finds
  // them in memory: raw files announce the box's byte ranges to the
  // kernel (ByteStream::willNeed). Only a hint: sources that cannot give
  // it, and any failure, change nothing. For a series step read on demand
  // after the frame now rendering (node/brick_cache.h).
  virtual void prefetchBox(const NodeBox& /*stored*/) const {}

  // A time series is steps() volumes on one grid and scalar type: step(k)
  // (0-based) is the k-th, stepTime(k) its time. A single volume is a series
  // of one step, itself. readBox of a series reads its step 0.
  virtual int steps() const { return 1; }
  virtual double stepTime(int /*k*/) const { return 0; }
  virtual const VolumeSource& step(int /*k*/) const { return *this; }
};

// A file format: `matches` looks at the path (extension), `open` reads the
// header and validates it against the data's byte count.
struct VolumeFormat {
  const char* name;
  bool (*matches)(const std::string& path);
  std::unique_ptr<VolumeSource> (*open)(const std::string& path, const DataDirectory* within);
  const char* extensions = "";  // for messages: ".nrrd .nhdr"
};

// Every registered format, in the order they are tried (volume_formats.cpp).
const std::vector<VolumeFormat>& volumeFormats();

// Opens a volume file by its extension. Throws pvr::Error naming the file and
// what is wrong (missing, unreadable header, unknown type, truncated data,
// dims that do not match the byte count). With `within` (a server opening
// what a client named), the file and every file its header or sidecar names
// must be regular files inside that directory (data_directory.h).
std::unique_ptr<VolumeSource> openVolumeFile(const std::string& path, const DataDirectory* within = nullptr);

// Writes a whole volume (a brick whose stored box is the whole grid) in the
// raw + JSON sidecar form of ../shared/data that openVolumeFile reads back:
// DIR/STEM.raw (the voxels in this machine's byte order) and DIR/STEM.json
// (dims, dtype, spacing, origin, raw_file, endian, and `description`),
// creating DIR. Returns the sidecar's path; throws pvr::Error(kIo) naming the
// file that could not be written.
std::string writeRawJsonVolume(const Brick& volume, const std::string& dir, const std::string& stem,
                               const std::string& description);

// Procedural volumes by name, any resolution, float32 values:
//   "shepp-logan"     3D Shepp-Logan head phantom (Kak & Slaney ellipsoids), values in [0, 1]
//   "marschner-lobb"  the Marschner-Lobb test signal (f_M = 6, alpha = 0.25) on [-1,1]^3, values in [0, 1]
//   "constant-slab"   1.0 everywhere (a homogeneous slab; exact references exist)
// The grid spans [-1, 1] on its longest axis with isotropic spacing unless
// `spacing` is given. Throws pvr::Error for an unknown name.
std::unique_ptr<VolumeSource> openProcedural(const std::string& name, IVec3 dims);
std::unique_ptr<VolumeSource> openProcedural(const std::string& name, IVec3 dims, Vec3 spacing);
std::vector<std::string> proceduralNames();

// The grid of a generated volume (procedural, or a user computation on the
// ranks): `dims` nodes centred on the origin, spanning [-1, 1] on the
// longest axis with isotropic spacing unless `spacing` is given. Throws
// pvr::Error naming `name` for an invalid grid or one of absurd size.
GridGeometry generatedGrid(IVec3 dims, std::optional<Vec3> spacing, const std::string& name);

// The analytic field a procedural volume samples, at a world position (the
// grid puts node (i,j,k) at origin + (i,j,k) * spacing). Reference
// integrators use it; note that the renderer sees the trilinear
// reconstruction of the grid samples, which differs from this field between
// nodes (and across the Shepp-Logan phantom's sharp edges). Throws pvr::Error
// for an unknown name.
double proceduralValue(const std::string& name, Vec3 position);

}  // namespace pvr::core
