// Reading a JSON file: scenes, ParaView presets, volume sidecars.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace pvr::core {

// Every JSON file PVR reads is a description of a few kilobytes; a larger
// one is refused before it is read (a volume named .json by mistake).
inline constexpr std::uint64_t kMaxJsonFileBytes = std::uint64_t(1) << 24;

// The parsed document. Throws pvr::Error starting with the path: kIo when
// the file is missing or unreadable, kBadFile when it holds more than
// kMaxJsonFileBytes or is not valid JSON.
nlohmann::json readJsonFile(const std::string& path);

}  // namespace pvr::core
