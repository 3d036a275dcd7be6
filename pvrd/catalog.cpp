#include "catalog.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <filesystem>

namespace pvr::daemon {
namespace {

namespace fs = std::filesystem;

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string realPath(const std::string& path) {
  char buf[PATH_MAX];
  return ::realpath(path.c_str(), buf) ? std::string(buf) : std::string();
}

bool inside(const std::string& root, const std::string& path) {
  return !root.empty() && !path.empty() && path.size() > root.size() && path.compare(0, root.size(), root) == 0 &&
         (root == "/" || path[root.size()] == '/');
}

}  // namespace

bool isVolumeFileName(const std::string& name) {
  for (const char* ext : {".json", ".nhdr", ".nrrd", ".nii", ".nii.gz"})
    if (endsWith(name, ext) && name.size() > std::char_traits<char>::length(ext)) return true;
  return false;
}

std::vector<std::string> listDatasets(const std::string& dataDir) {
  std::vector<std::string> names;
  const std::string root = realPath(dataDir);
  if (root.empty()) return names;
  std::error_code ec;
  auto consider = [&](const fs::path& file, const std::string& name) {
    if (!isVolumeFileName(name)) return;
    const std::string real = realPath(file.string());
    if (inside(root, real) && fs::is_regular_file(real, ec)) names.push_back(name);
  };
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    const std::string top = entry.path().filename().string();
    if (top.empty() || top[0] == '.') continue;
    if (entry.is_directory(ec)) {
      if (!inside(root, realPath(entry.path().string()))) continue;
      for (const auto& sub : fs::directory_iterator(entry.path(), ec)) {
        const std::string leaf = sub.path().filename().string();
        if (!leaf.empty() && leaf[0] != '.') consider(sub.path(), top + "/" + leaf);
      }
    } else {
      consider(entry.path(), top);
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::variant<std::string, proto::ProtocolError> resolveDataset(const std::string& dataDir, const std::string& name) {
  using proto::ErrorCode;
  if (name.empty() || name[0] == '/' || name.find('\0') != std::string::npos)
    return proto::ProtocolError{ErrorCode::kBadArgument, "dataset names are relative to the data directory"};
  for (const auto& part : fs::path(name))
    if (part == "..") return proto::ProtocolError{ErrorCode::kBadArgument, "dataset name '" + name + "' contains '..'"};
  const std::string root = realPath(dataDir);
  const std::string real = realPath(root + "/" + name);
  std::error_code ec;
  if (root.empty() || !inside(root, real) || !isVolumeFileName(name) || !fs::is_regular_file(real, ec))
    return proto::ProtocolError{ErrorCode::kDatasetNotFound, "no dataset '" + name + "' in the catalog"};
  return real;
}

}  // namespace pvr::daemon
