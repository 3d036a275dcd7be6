#include "json_depth.h"

#include <string>

namespace pvr::proto {

std::optional<ProtocolError> checkJsonDepth(std::string_view text, std::string_view what, int maxDepth) {
  int depth = 0;
  bool inString = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') inString = false;
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > maxDepth)
        return ProtocolError{ErrorCode::kMalformedPayload,
                             std::string(what) + ": JSON nests deeper than " + std::to_string(maxDepth) +
                                 " levels (at byte " + std::to_string(i) + ")"};
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::nullopt;
}

}  // namespace pvr::proto
