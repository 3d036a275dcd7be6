// Small helpers every volume source shares: error messages that start with
// the file, box checks, file sizes, byte counts that cannot overflow.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "../error.h"
#include "../grid.h"

namespace pvr::core {

// Throws pvr::Error(code, "<where>: <what>"): every loader message starts
// with the file (or procedural name) it is about.
[[noreturn]] void failAt(ErrorCode code, std::string_view where, std::string_view what);

// Throws naming `where` unless `stored` contains `owned` and lies in the grid:
// the Brick constructor would throw too, but without saying which file.
void checkReadBoxes(std::string_view where, const GridGeometry& grid, const NodeBox& owned,
                    const NodeBox& stored);

// The size of a regular file; throws kIo starting with `where` (default:
// the path) when it is missing or not a regular file.
std::uint64_t fileSizeOf(const std::string& path, std::string_view where = {});

// dims.product() * scalarSize(type), throwing kBadFile naming `where` when
// the product does not fit comfortably in 63 bits (a hostile header).
std::uint64_t voxelBytes(const GridGeometry& grid, ScalarType type, std::string_view where);

// "256x256x108 int16": the shape in messages and describe().
std::string shapeText(const GridGeometry& grid, ScalarType type);

// The last path component, for describe() ("ct.nhdr: 256x256x108 int16").
std::string fileNameOf(const std::string& path);

// Case-insensitive suffix test on a path ("x.NII.GZ" ends with ".nii.gz").
bool pathEndsWith(std::string_view path, std::string_view suffix);

// A file's text with non-printable bytes masked and long text cut, so a
// garbled header can be quoted in a message safely.
std::string quoteForMessage(std::string_view text, std::size_t maxChars = 40);

}  // namespace pvr::core
