// The one-time secret that proves a connect-back is the job this session
// launched (clients prove the token inside the secure channel,
// protocol/secure_channel.h).
#pragma once

#include <array>
#include <optional>
#include <string>

#include "pvr_protocol.h"

namespace pvr::daemon {

// A per-session job secret (docs/pvrd.md, "The job's secret"): 32 random
// bytes as 64 lowercase hex characters, which survive an environment
// variable and a protocol string alike; nullopt if the generator fails.
std::optional<std::string> makeJobSecret();

// Whether `received` is `expected`, compared in constant time (the length,
// 64 characters for every secret pvrd makes, is no secret).
bool sameSecret(const std::string& expected, const std::string& received);

}  // namespace pvr::daemon
