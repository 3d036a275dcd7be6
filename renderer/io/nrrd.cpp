// NRRD volumes: attached headers (.nrrd, data after the first blank line)
// and detached ones (.nhdr naming a "data file"), encodings raw and gzip,
// "byte skip" (-1: the data ends the file) and "line skip".
//
// Why not Teem: nrrdLoad reads and decodes the whole data, while a rank of
// the renderer wants only its brick read in place; it reports through biff
// strings that would have to be reshaped into messages naming the file; and
// a header is a few "field: value" lines. So nrrd_header.cpp parses them and
// the data goes through the same raw/gzip box reader as every other format.
// Teem stays the referee: the tests load their NRRD files with it too and
// require the same bytes.
#include <algorithm>
#include <filesystem>
#include <vector>

#include "byte_stream.h"
#include "formats.h"
#include "orientation.h"
#include "nrrd_header.h"
#include "raw_reader.h"
#include "source_util.h"

namespace pvr::core {

namespace {

// Real headers are a few hundred bytes; this bounds what a garbled file costs.
constexpr std::size_t kMaxHeaderBytes = std::size_t(1) << 20;

std::string readHeaderText(const std::string& path, bool& complete) {
  const std::uint64_t size = fileSizeOf(path);
  const std::size_t n = std::size_t(std::min<std::uint64_t>(size, kMaxHeaderBytes));
  std::string text(n, '\0');
  FileStream(path).read(0, reinterpret_cast<std::byte*>(text.data()), n);
  complete = n == size;
  return text;
}

// The offset just past `lines` newlines from `start` of the data file.
std::uint64_t skipLines(const std::string& dataPath, std::uint64_t start, std::int64_t lines) {
  FileStream file(dataPath);
  std::vector<std::byte> buf(std::size_t(1) << 16);
  std::uint64_t pos = start;
  while (lines > 0) {
    const std::size_t got = file.readSome(pos, buf.data(), buf.size());
    if (got == 0)
      failAt(ErrorCode::kBadFile, dataPath, "file ends before the header's line skip is done");
    for (std::size_t i = 0; i < got && lines > 0; ++i, ++pos)
      if (buf[i] == std::byte{'\n'}) --lines;
  }
  return pos;
}

}  // namespace

bool isNrrdPath(const std::string& path) {
  return pathEndsWith(path, ".nrrd") || pathEndsWith(path, ".nhdr");
}

std::unique_ptr<VolumeSource> openNrrd(const std::string& path, const DataDirectory* within) {
  bool complete = false;
  const std::string text = readHeaderText(path, complete);
  const NrrdHeader h = parseNrrdHeader(text, complete, path);

  // Step: which file holds the data, and where it starts in it.
  RawLayout layout;
  layout.headerPath = path;
  std::uint64_t start = 0;
  if (!h.dataFile.empty()) {
    const std::filesystem::path named(h.dataFile);
    layout.dataPath = confineTo(within,
                                named.is_absolute() ? named.string()
                                                    : (std::filesystem::path(path).parent_path() / named).string(),
                                path);
  } else if (h.dataStart) {
    layout.dataPath = path;
    start = *h.dataStart;
  } else {
    failAt(ErrorCode::kBadFile, path,
           "header names no 'data file' and has no blank line before attached data");
  }
  layout.bigEndian = h.bigEndian.value_or(false);
  if (h.lineSkip > 0)
    start = withHeaderNamed(layout, [&] { return skipLines(layout.dataPath, start, h.lineSkip); });

  // Step: byte skip counts raw file bytes, or decoded bytes for gzip (as in Teem).
  if (h.encoding == NrrdEncoding::kGzip) {
    if (h.byteSkip < 0)
      failAt(ErrorCode::kUnsupported, path, "byte skip -1 needs raw encoding, not gzip");
    layout.encoding = RawEncoding::kGzip;
    layout.gzipStart = start;
    layout.offset = std::uint64_t(h.byteSkip);
  } else if (h.byteSkip >= 0) {
    layout.offset = start + std::uint64_t(h.byteSkip);
  } else {
    // The data is the last bytes of the file; if the file is too short the
    // offset stays at `start` and the size check reports it.
    const std::uint64_t data = voxelBytes(h.grid, h.type, path);
    const std::uint64_t size = withHeaderNamed(layout, [&] { return fileSizeOf(layout.dataPath); });
    layout.offset = size >= start + data ? size - data : start;
  }
  // Step: the space directions orient the grid (orientation.h).
  if (!h.spaceDirections)
    return openRawVolume(fileNameOf(path), h.grid, h.type, std::move(layout), SizeRule::kExact);
  const Orientation o = orientationOf({*h.spaceDirections, h.grid.origin}, h.grid.dims, path);
  return reoriented(openRawVolume(fileNameOf(path) + obliqueNote(o), h.grid, h.type, std::move(layout), SizeRule::kExact), o);
}

}  // namespace pvr::core
