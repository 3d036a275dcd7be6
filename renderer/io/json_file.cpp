#include "json_file.h"

#include <fstream>
#include <sstream>

#include "source_util.h"

namespace pvr::core {

nlohmann::json readJsonFile(const std::string& path) {
  const std::uint64_t size = fileSizeOf(path);
  if (size > kMaxJsonFileBytes)
    failAt(ErrorCode::kBadFile, path,
           "has " + std::to_string(size) + " bytes, more than the " + std::to_string(kMaxJsonFileBytes) +
               " a JSON description may have");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) failAt(ErrorCode::kIo, path, "cannot read");
  try {
    return nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    failAt(ErrorCode::kBadFile, path, std::string("not valid JSON: ") + e.what());
  }
}

}  // namespace pvr::core
