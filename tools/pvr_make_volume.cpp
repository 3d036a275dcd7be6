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

int main(int argc, char** argv) {
  using namespace pvr::core;
  if (argc != 4) {
    std::fprintf(stderr, "usage: pvr-make-volume NAME N OUT_DIR\n");
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
