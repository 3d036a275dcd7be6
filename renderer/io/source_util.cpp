#include "source_util.h"

#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cstring>

namespace pvr::core {

void failAt(ErrorCode code, std::string_view where, std::string_view what) {
  throw Error(code, std::string(where) + ": " + std::string(what));
}

void checkReadBoxes(std::string_view where, const GridGeometry& grid, const NodeBox& owned,
                    const NodeBox& stored) {
  if (owned.empty() || !stored.contains(owned) || !grid.allNodes().contains(stored))
    failAt(ErrorCode::kInvalidArgument, where,
           "cannot read box " + toString(stored) + " owning " + toString(owned) +
               ": it must contain the owned box and lie in the grid " +
               toString(grid.allNodes()));
}

std::uint64_t fileSizeOf(const std::string& path, std::string_view where) {
  if (where.empty()) where = path;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) failAt(ErrorCode::kIo, where, "no such file");
    failAt(ErrorCode::kIo, where, std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) failAt(ErrorCode::kIo, where, "not a regular file");
  return std::uint64_t(st.st_size);
}

std::uint64_t voxelBytes(const GridGeometry& grid, ScalarType type, std::string_view where) {
  // Each factor below 2^31 and the product below 2^62: no intermediate overflows.
  constexpr std::uint64_t kMaxDim = (std::uint64_t(1) << 31) - 1;
  constexpr std::uint64_t kMaxBytes = std::uint64_t(1) << 62;
  std::uint64_t bytes = scalarSize(type);
  for (int a = 0; a < 3; ++a) {
    if (grid.dims[a] < 1 || std::uint64_t(grid.dims[a]) > kMaxDim)
      failAt(ErrorCode::kBadFile, where,
             "dimension " + std::to_string(a) + " is " + std::to_string(grid.dims[a]) +
                 ", must be 1.." + std::to_string(kMaxDim));
    if (bytes > kMaxBytes / std::uint64_t(grid.dims[a]))
      failAt(ErrorCode::kBadFile, where, "volume of " + shapeText(grid, type) + " is too large");
    bytes *= std::uint64_t(grid.dims[a]);
  }
  return bytes;
}

std::string shapeText(const GridGeometry& grid, ScalarType type) {
  return std::to_string(grid.dims.x) + "x" + std::to_string(grid.dims.y) + "x" +
         std::to_string(grid.dims.z) + " " + std::string(scalarName(type));
}

std::string fileNameOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool pathEndsWith(std::string_view path, std::string_view suffix) {
  if (path.size() < suffix.size()) return false;
  const std::string_view tail = path.substr(path.size() - suffix.size());
  for (std::size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(tail[i])) !=
        std::tolower(static_cast<unsigned char>(suffix[i])))
      return false;
  return true;
}

std::string quoteForMessage(std::string_view text, std::size_t maxChars) {
  std::string out;
  for (char c : text.substr(0, maxChars))
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (text.size() > maxChars) out += "...";
  return "'" + out + "'";
}

}  // namespace pvr::core
