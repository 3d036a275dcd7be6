// The nesting depth of JSON text a peer sends, checked before any parser
// sees it: nlohmann's parser recurses on nesting, and 100000 nested
// brackets (700 KB, well inside a SetScene's size limit) crashed rank 0.
// Every place that parses JSON from the wire (the master's SetScene,
// pvrsh's PerformanceReply) calls checkJsonDepth first.
#pragma once

#include <optional>
#include <string_view>

#include "protocol_error.h"

namespace pvr::proto {

// The deepest nesting any JSON the protocol carries may have: scene
// documents and reports nest a handful of levels.
inline constexpr int kMaxJsonDepth = 64;

// MALFORMED_PAYLOAD naming `what` when `text` nests objects and arrays
// deeper than `maxDepth` (brackets inside strings do not count); nullopt
// otherwise. A linear scan without recursion; it does not validate the rest.
std::optional<ProtocolError> checkJsonDepth(std::string_view text, std::string_view what,
                                            int maxDepth = kMaxJsonDepth);

}  // namespace pvr::proto
