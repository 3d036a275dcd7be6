#include "data_directory.h"

#include <sys/stat.h>

#include <climits>
#include <cstdlib>

#include "source_util.h"

namespace pvr::core {

DataDirectory::DataDirectory(const std::string& path) {
  char real[PATH_MAX];
  struct stat st{};
  if (!::realpath(path.c_str(), real) || ::stat(real, &st) != 0 || !S_ISDIR(st.st_mode))
    failAt(ErrorCode::kIo, path, "not a directory");
  root_ = real;
}

std::optional<std::string> DataDirectory::confine(const std::string& file) const {
  if (file.empty()) return std::nullopt;
  const std::string wanted = file[0] == '/' ? file : root_ + "/" + file;
  char real[PATH_MAX];
  if (!::realpath(wanted.c_str(), real)) return std::nullopt;
  const std::string resolved = real;
  // Inside: the root itself followed by '/' (the root "/" holds everything).
  const std::string prefix = root_ == "/" ? "/" : root_ + "/";
  if (resolved.size() <= prefix.size() || resolved.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  struct stat st{};
  if (::stat(real, &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  return resolved;
}

std::string DataDirectory::require(const std::string& file, std::string_view where) const {
  if (auto real = confine(file)) return *real;
  failAt(ErrorCode::kInvalidArgument, where,
         quoteForMessage(file, 200) + " is not a regular file inside the data directory");
}

std::string confineTo(const DataDirectory* within, const std::string& file, std::string_view where) {
  return within ? within->require(file, where) : file;
}

}  // namespace pvr::core
