// pvr-make-volume: write a procedural volume as raw + JSON sidecar, the form
// of ../shared/data, so a pvrd data directory can serve it.
//
//   pvr-make-volume NAME N OUT_DIR      (NAME: shepp-logan, marschner-lobb, constant-slab)
//
// Writes OUT_DIR/<name>/<name>.raw and <name>.json (float32, N^3).
#include <cstdio>
#include <filesystem>
#include <string>

#include "error.h"
#include "io/volume_io.h"

namespace {

// The command line, one place: --help prints it, a bad one its first line.
std::string usage() {
  std::string names;
  for (const auto& n : pvr::core::proceduralNames()) names += (names.empty() ? "" : ", ") + n;
  return "usage: pvr-make-volume NAME N OUT_DIR\n"
         "\n"
         "Writes the procedural volume NAME at N^3 float32 nodes as OUT_DIR/<name>/<name>.raw and\n"
         "<name>.json (the raw + sidecar form a pvrd data directory serves) and prints the sidecar's path.\n"
         "\n"
         "arguments:\n"
         "  NAME        " + names + "\n"
         "  N           nodes per axis, 2..2048\n"
         "  OUT_DIR     the data directory to write into\n"
         "  -h, --help  print this help and exit\n"
         "\n"
         "example:\n"
         "  pvr-make-volume shepp-logan 128 /data/volumes\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pvr::core;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "-h" || std::string(argv[i]) == "--help") {
      std::fputs(usage().c_str(), stdout);
      return 0;
    }
  if (argc != 4) {
    const std::string text = usage();
    std::fprintf(stderr, "%s(pvr-make-volume --help for more)\n", text.substr(0, text.find('\n') + 1).c_str());
    return 2;
  }
  try {
    const std::string name = argv[1];
    const long n = std::stol(argv[2]);
    if (n < 2 || n > 2048) throw pvr::Error(pvr::ErrorCode::kInvalidArgument, "N must be in 2..2048");
    const auto source = openProcedural(name, {n, n, n});
    const Brick volume = source->readAll();

    std::string stem = name;
    for (char& c : stem) c = c == '-' ? '_' : c;
    const std::string sidecar = writeRawJsonVolume(volume, (std::filesystem::path(argv[3]) / stem).string(), stem,
                                                   "procedural " + name + " volume written by pvr-make-volume");
    std::printf("%s\n", sidecar.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pvr-make-volume: %s\n", e.what());
    return 1;
  }
}
