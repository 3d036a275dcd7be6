// The message parseScene refuses a document with, for the scene tests.
#pragma once

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>
#include <string>

#include "error.h"
#include "scene.h"

namespace pvr::core::test {

// parseScene's error text for `doc` (relative paths against "/base"), which
// must be an invalid argument; "(no error)" if it parses.
inline std::string sceneParseError(const nlohmann::json& doc) {
  try {
    parseScene(doc, "/base");
  } catch (const pvr::Error& e) {
    CHECK(e.code() == pvr::ErrorCode::kInvalidArgument);
    return e.what();
  }
  return "(no error)";
}

}  // namespace pvr::core::test
