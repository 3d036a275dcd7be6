// The catalog through a real pvrd and the real `pvr-node --catalog`: a time
// series is listed once with its steps and its step files not at all; a
// broken node path is the client's error and pvrd serves on.
#include <catch2/catch.hpp>

#include "daemon_harness.h"

using namespace pvr::daemon::testing;

namespace {

// Beside the harness's ball: a series sidecar over three copies of the
// ball (series/), a raw+JSON sidecar with a pattern over two raw files
// (pattern/), and a .json that is no volume.
void addSeries(const fs::path& dir) {
  const fs::path ball = dir / "ball";
  fs::create_directories(dir / "series");
  for (int k = 0; k < 3; ++k) {
    const std::string stem = "step_00" + std::to_string(k);
    fs::copy_file(ball / "ball.raw", dir / "series" / (stem + ".raw"));
    std::ofstream(dir / "series" / (stem + ".json"))
        << R"({"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1], "raw_file": ")" << stem << R"(.raw"})";
  }
  std::ofstream(dir / "series" / "run.series.json") << R"({"pattern": "step_%03d.json", "steps": 3, "time_step": 0.5})";
  fs::create_directories(dir / "pattern");
  for (int k = 0; k < 2; ++k) fs::copy_file(ball / "ball.raw", dir / "pattern" / ("t" + std::to_string(k) + ".raw"));
  std::ofstream(dir / "pattern" / "pattern.json")
      << R"({"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1], "pattern": "t%d.raw", "steps": 2})";
  std::ofstream(dir / "notes.json") << "not a volume";
}

}  // namespace

TEST_CASE("the catalog lists a time series once with its steps and not its step files") {
  Daemon d(makeDataDir("catalog_series"));
  addSeries(d.dataDir);
  Client c(d.port);
  c.hello();
  c.send(proto::CatalogRequest{});
  CHECK(c.expect<proto::CatalogReply>().datasets ==
        std::vector<proto::CatalogEntry>{{"ball", 1, "ball/ball.json", "raw+json", {32, 32, 32}, "uint8", ""},
                                         {"pattern", 2, "pattern/pattern.json", "raw+json", {32, 32, 32}, "uint8", ""},
                                         {"series/run", 3, "series/run.series.json", "series", {32, 32, 32}, "uint8", ""}});
}

TEST_CASE("a broken pvr-node path makes the catalog an error naming it, and pvrd serves on") {
  Daemon d(makeDataDir("catalog_broken"), {"--node", "/nonexistent/pvr-node"});
  Client c(d.port);
  c.hello();
  c.send(proto::CatalogRequest{});
  const auto e = c.expectError();
  CHECK(e.code == proto::ErrorCode::kIo);
  CHECK_THAT(e.text, Catch::Contains("cannot list the catalog: /nonexistent/pvr-node --catalog") &&
                         Catch::Contains("exited with status 127"));
  // The same session answers the next request, and a new client is served.
  c.send(proto::StatusRequest{});
  CHECK(c.expect<proto::StatusReply>().entries.size() > 0);
  Client again(d.port);
  again.hello();
  again.send(proto::CatalogRequest{});
  CHECK(again.expectError().code == proto::ErrorCode::kIo);
}
