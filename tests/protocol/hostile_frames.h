// Malformed frames, each with the error code decoding must answer and a
// piece of its text: the hostile-input tests feed them to the decoder, the
// relay tests check the relay refuses them alike.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::proto::testing {

struct HostileCase {
  std::string name;
  std::vector<std::uint8_t> bytes;
  ErrorCode code;
  std::string textContains;
};

std::vector<HostileCase> hostileCases();

}  // namespace pvr::proto::testing
