// The committed fuzz seed corpus holds one current frame per message type.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "sample_messages.h"

using namespace pvr::proto;
using namespace pvr::proto::testing;

TEST_CASE("seed corpus holds the current encoding of every message") {
  const std::filesystem::path dir = PVR_SEED_CORPUS_DIR;
  const auto samples = sampleMessages();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto path = dir / seedFileName(samples[i]);
    DYNAMIC_SECTION(path.filename().string()) {
      std::ifstream in(path, std::ios::binary);
      INFO("regenerate with: pvr_protocol_write_corpus " << dir.string());
      REQUIRE(in.good());
      const std::vector<std::uint8_t> stored{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      CHECK(stored == seedFrame(samples[i], i));
    }
  }
}
