// How long a rank may make no progress before its job ends: pvrd's
// --stall-timeout, which pvrd passes on to pvr-node's. One range, one
// default and one message for both programs.
#pragma once

#include <string>
#include <string_view>

namespace pvr::proto {

// Below a few heartbeats (one a second) every rank would look stalled.
inline constexpr int kMinStallSeconds = 2;
inline constexpr int kMaxStallSeconds = 86400;
inline constexpr int kDefaultStallSeconds = 30;

inline bool stallSecondsInRange(double seconds) {
  return seconds >= kMinStallSeconds && seconds <= kMaxStallSeconds;
}

inline std::string stallTimeoutRefusal(std::string_view given) {
  return "--stall-timeout takes seconds from " + std::to_string(kMinStallSeconds) + " to " +
         std::to_string(kMaxStallSeconds) + ", not '" + std::string(given) + "'";
}

}  // namespace pvr::proto
