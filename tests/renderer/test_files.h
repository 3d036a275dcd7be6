// Files for the renderer's tests: the checkout they were built from, fresh
// scratch directories, text written and read back.
#pragma once

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace pvr::core::test {

namespace fs = std::filesystem;

// The source tree (docs/, examples/) of this checkout.
inline const fs::path kSourceRoot = fs::path(__FILE__).parent_path().parent_path().parent_path();

// A fresh, empty scratch directory; one name per test case, since ctest runs
// test cases as parallel processes.
inline std::string scratchDir(const std::string& name) {
  const fs::path dir = fs::path(PVR_TEST_TMP) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

inline void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  REQUIRE(out.good());
}

inline std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in.good());
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace pvr::core::test
