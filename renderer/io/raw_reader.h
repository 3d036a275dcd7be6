// Raw voxel data: where a format's voxels lie, and the one box reader all
// file formats share.
//
// Every supported file format ends in the same thing: a run of scalars,
// x fastest, then y, then z, at some byte offset of a file or of a gzip
// stream, in some byte order. A format's job is only to parse its header
// into a RawLayout; reading, checking sizes and byte-swapping happen here.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "../error.h"
#include "volume_io.h"

namespace pvr::core {

enum class RawEncoding : std::uint8_t { kRaw, kGzip };

struct RawLayout {
  std::string dataPath;        // the file holding the voxels
  std::string headerPath;      // the file that described them, for messages (may equal dataPath)
  RawEncoding encoding = RawEncoding::kRaw;
  std::uint64_t gzipStart = 0; // kGzip: where the compressed stream starts in the file
  std::uint64_t offset = 0;    // bytes before voxel (0,0,0) in the (decoded) data
  bool bigEndian = false;
};

// Runs f(). A pvr::Error it throws starts with the data file; when a
// separate header named that file, the header is appended, so the message
// reads "/x/ct.raw: file has 1000 bytes, header needs ... (data file of /x/ct.nhdr)".
template <typename F>
decltype(auto) withHeaderNamed(const RawLayout& layout, F&& f) {
  try {
    return f();
  } catch (const Error& e) {
    if (layout.headerPath.empty() || layout.headerPath == layout.dataPath) throw;
    throw Error(e.code(), std::string(e.what()) + " (data file of " + layout.headerPath + ")");
  }
}

// Whether data may continue past the last voxel. Raw+JSON and NRRD demand
// an exact match (a mismatch almost always means wrong dims or type);
// NIfTI allows trailing bytes, as nifti_clib does.
enum class SizeRule : std::uint8_t { kExact, kAtLeast };

// Validates `grid` and the data's byte count against it (stat for raw files,
// the gzip trailer or a counting decode for gzip), then returns a source
// whose readBox reads only the requested box. `name` is what describe()
// shows ("ct.nhdr"). Throws pvr::Error naming the file on any mismatch:
// "/x/ct.raw: file has 1000 bytes, header needs 14155776 (256x256x108 int16)".
// A source over `layout` whose data size the caller has checked already
// (openRawVolume does; a series of steps stored back to back checks all
// steps at once instead of once per step).
std::unique_ptr<VolumeSource> rawVolumeSource(std::string name, const GridGeometry& grid, ScalarType type,
                                              RawLayout layout);

std::unique_ptr<VolumeSource> openRawVolume(std::string name, const GridGeometry& grid,
                                            ScalarType type, RawLayout layout, SizeRule rule);

// The nodes of `stored` read from the data described by `layout` into a
// brick that owns `owned`, byte-swapped to host order, slab by slab: each
// slab is preprocessed (value range, macrocell bounds; preprocess.h) right
// after it lands, while it is in cache, and the brick carries the result.
// Contiguous runs are coalesced: whole rows into a slab, whole slabs into
// groups of about a megabyte. No buffer besides the brick. Fills
// brick.loadTimes(): seconds in I/O calls and in the fused preprocessing.
// Without `fineCounts` the brick carries no fine histogram, unless summaries
// are kept (io/brick_summary.h): a summary is whole, so the read that
// writes it counts, and one that takes it has the counts.
Brick readRawBox(const RawLayout& layout, const GridGeometry& grid, ScalarType type,
                 const NodeBox& owned, const NodeBox& stored, bool fineCounts = true);

// VolumeSource::prefetchBox for raw data (gzip streams ignore it): the
// byte ranges readRawBox would read for `stored`, announced to the kernel.
// Never throws.
void prefetchRawBox(const RawLayout& layout, const GridGeometry& grid, ScalarType type, const NodeBox& stored);

}  // namespace pvr::core
