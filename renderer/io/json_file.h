// Reading a JSON file: scenes, ParaView presets, volume sidecars.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace pvr::core {

// Every JSON file PVR reads is a description of a few kilobytes; a larger
// one is refused before it is read (a volume named .json by mistake).
inline constexpr std::uint64_t kMaxJsonFileBytes = std::uint64_t(1) << 24;

// The deepest nesting of objects and arrays a JSON file may have: scenes,
// presets and sidecars nest a handful of levels. nlohmann's parser keeps its
// own stack, but printing, copying and comparing a document recurse on its
// nesting: a scene file of 100000 nested arrays overflowed the stack when
// the error message quoted the value. The same number as the wire's limit
// (proto::kMaxJsonDepth), which the renderer does not depend on.
inline constexpr int kMaxJsonDepth = 64;

// The parsed document. Throws pvr::Error starting with the path: kIo when
// the file is missing or unreadable, kBadFile when it holds more than
// kMaxJsonFileBytes, is not valid JSON or nests deeper than kMaxJsonDepth.
nlohmann::json readJsonFile(const std::string& path);

// The document `text` holds, read by readJsonFile's rules; `where` (the
// file's path) starts every error. Throws pvr::Error(kBadFile) when it is
// not valid JSON or nests deeper than kMaxJsonDepth.
nlohmann::json parseJsonText(std::string_view text, const std::string& where);

}  // namespace pvr::core
