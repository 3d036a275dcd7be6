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
  return parseJsonText(text.str(), path);
}

nlohmann::json parseJsonText(std::string_view text, const std::string& where) {
  // The parser tells the depth of each object or array it starts (0 for
  // the outermost): refuse the first one past the limit, before any
  // deeper value is built.
  using Event = nlohmann::json::parse_event_t;
  const auto refuseDeep = [&where](int depth, Event event, nlohmann::json&) {
    if ((event == Event::object_start || event == Event::array_start) && depth >= kMaxJsonDepth)
      failAt(ErrorCode::kBadFile, where,
             "nests objects and arrays deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return true;
  };
  try {
    return nlohmann::json::parse(text, refuseDeep);
  } catch (const nlohmann::json::exception& e) {
    // parse_error, and out_of_range for a number too large for a double
    // ("1e400"), which is no parse_error.
    failAt(ErrorCode::kBadFile, where, std::string("not valid JSON: ") + e.what());
  }
}

}  // namespace pvr::core
