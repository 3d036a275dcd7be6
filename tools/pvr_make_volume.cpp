// pvr-make-volume: write a procedural volume as raw + JSON sidecar, the form
// of ../shared/data, so a pvrd data directory can serve it.
//
//   pvr-make-volume NAME N OUT_DIR      (NAME: shepp-logan, marschner-lobb, constant-slab)
//
// Writes OUT_DIR/<name>/<name>.raw and <name>.json (float32, N^3).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

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
    const std::filesystem::path dir = std::filesystem::path(argv[3]) / stem;
    std::filesystem::create_directories(dir);
    const std::filesystem::path raw = dir / (stem + ".raw");
    std::ofstream(raw, std::ios::binary)
        .write(reinterpret_cast<const char*>(volume.bytes()), std::streamsize(volume.byteSize()));
    const GridGeometry& g = volume.grid();
    const nlohmann::json sidecar = {
        {"dims", {g.dims.x, g.dims.y, g.dims.z}},
        {"dtype", std::string(scalarName(volume.type()))},
        {"spacing", {g.spacing.x, g.spacing.y, g.spacing.z}},
        {"origin", {g.origin.x, g.origin.y, g.origin.z}},
        {"raw_file", raw.filename().string()},
        {"endian", "little"},
        {"description", "procedural " + name + " volume written by pvr-make-volume"}};
    std::ofstream(dir / (stem + ".json")) << sidecar.dump(2) << "\n";
    std::printf("%s\n", (dir / (stem + ".json")).c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pvr-make-volume: %s\n", e.what());
    return 1;
  }
}
