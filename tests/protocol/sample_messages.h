// One typical value of every message type, shared by the round-trip tests,
// the seed-corpus writer and the seed-corpus check.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::proto::testing {

// In Message variant order: sampleMessages()[i] holds alternative i.
std::vector<Message> sampleMessages();

// The seed-corpus file of a message: "<Name>.bin".
std::string seedFileName(const Message& message);

// The frame stored in the seed corpus for sample i: request id i + 1, the
// final flag on replies so both flag values occur.
std::vector<std::uint8_t> seedFrame(const Message& message, std::size_t index);

}  // namespace pvr::proto::testing
