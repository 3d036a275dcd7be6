// The directory a server's clients may name files in.
//
// A client names datasets (and, through their headers and sidecars, the
// data files those name); a server must never open anything else for it:
// not /etc/shadow through an absolute "raw_file", not /dev/zero through a
// symlink, not a FIFO that blocks the reader forever. Every such path
// resolves, after symlinks, to a regular file inside the directory, or is
// refused with one message whether it exists or not (so the refusal tells
// nothing about files outside). Local tools (pvr-render, tests) open files
// without one.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace pvr::core {

class DataDirectory {
 public:
  // Throws pvr::Error(kIo) naming `path` unless it is a directory.
  explicit DataDirectory(const std::string& path);

  // Its real path (symlinks resolved, no trailing '/').
  const std::string& path() const { return root_; }

  // The real path of `file` (absolute, or relative to this directory) when
  // it is a regular file inside it; nullopt when it is missing, outside,
  // or not a regular file (a directory, a FIFO, a device).
  std::optional<std::string> confine(const std::string& file) const;

  // confine(file), or pvr::Error(kInvalidArgument) "<where>: '<file>' is not
  // a regular file inside the data directory", the same text for every reason.
  std::string require(const std::string& file, std::string_view where) const;

 private:
  std::string root_;
};

// A file a header or sidecar at `where` names: `within`'s require() when
// there is a data directory, the path as it is for local use.
std::string confineTo(const DataDirectory* within, const std::string& file, std::string_view where);

}  // namespace pvr::core
