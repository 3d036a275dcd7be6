// Parsing the text of a NRRD header (http://teem.sourceforge.net/nrrd/format.html)
// into what a 3D scalar volume needs. nrrd.cpp turns it into a data layout.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "../grid.h"

namespace pvr::core {

enum class NrrdEncoding : std::uint8_t { kRaw, kGzip };

struct NrrdHeader {
  ScalarType type = ScalarType::kUInt8;
  GridGeometry grid;                  // sizes; spacing and origin as stated, else 1 and 0
  // "space directions" as written: the space step of one node along each
  // index axis (grid.spacing holds their lengths); absent without the field.
  std::optional<std::array<Vec3, 3>> spaceDirections;
  NrrdEncoding encoding = NrrdEncoding::kRaw;
  std::optional<bool> bigEndian;      // absent: the header has no "endian" field
  std::string dataFile;               // "data file:" as written; empty when attached
  std::int64_t lineSkip = 0;          // lines to skip at the start of the data file
  std::int64_t byteSkip = 0;          // bytes to skip after them (-1: data ends the file)
  std::optional<std::uint64_t> dataStart;  // attached: bytes up to and including the blank line
};

// Parses `text`, the first bytes of `path` (`complete` when that is the
// whole file). Throws pvr::Error naming the path and the line for a missing
// magic, a malformed line, an unknown field, unsupported values, or missing
// required fields (type, dimension, sizes, encoding; endian for multi-byte
// types).
NrrdHeader parseNrrdHeader(std::string_view text, bool complete, const std::string& path);

}  // namespace pvr::core
