// Writes one encoded frame per message type into a directory: the libFuzzer
// seed corpus (fuzz/corpus/protocol). Run after changing a message:
//   pvr_protocol_write_corpus fuzz/corpus/protocol
// The test "seed corpus holds the current encoding of every message" fails
// until it is run.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sample_messages.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIRECTORY\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  const auto samples = pvr::proto::testing::sampleMessages();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto frame = pvr::proto::testing::seedFrame(samples[i], i);
    const auto path = dir / pvr::proto::testing::seedFileName(samples[i]);
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
    if (!out) {
      std::fprintf(stderr, "%s: cannot write\n", path.c_str());
      return 1;
    }
  }
  std::printf("wrote %zu frames to %s\n", samples.size(), dir.c_str());
  return 0;
}
