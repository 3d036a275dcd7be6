// pvr-node: the MPI program. Server mode is the job a pvrd session runs
// (server_mode.h, docs/runtime.md):
//
//   mpirun -np N pvr-node --server --connect HOST:PORT --data-dir DIR
//
// Batch mode renders one scene across the ranks and writes the frame:
//
//   mpirun -np N pvr-node --batch SCENE.json -o OUT.exr|OUT.png
//          [--strategy NAME] [--radix K] [--decomposition NAME]
//          [--early-termination A] [--threads N] [--codec auto|rle|rle-zlib|raw]
//          [--size WxH] [--stats FILE.csv]
//
// Catalog mode lists the datasets of a data directory for pvrd, without
// MPI (catalog_listing.h):
//
//   pvr-node --catalog DIR
//
// (the usage text lists the registered strategies and decompositions).
// Every rank reads its own brick (or rank 0 scatters when the format cannot
// read part of a file), renders it, and the ranks composite; rank 0 writes
// the image and prints the hosts of the ranks and the time breakdown
// (every phase from process start to the written image, report.h) with
// each rank's peak resident memory. Any
// rank's failure makes every rank exit 1 with the first failure printed
// once, by rank 0, naming the rank and its host.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "catalog_listing.h"
#include "frame.h"
#include "hosts.h"
#include "image_output.h"
#include "mpi_communicator.h"
#include "report.h"
#include "server_mode.h"

namespace {

using namespace pvr;

struct Args {
  std::string scene, output, stats;
  int width = 0, height = 0;
  node::FrameOptions frame;
};

// Names joined by `separator`, from a registration table.
template <class Table>
std::string names(const Table& table, const char* separator) {
  std::string out;
  for (const auto& entry : table) out += (out.empty() ? "" : separator) + std::string(entry.name);
  return out;
}

// The command line and every option, one line each: --help prints it,
// a bad batch command line prints it to stderr, man/pvr-node.1 follows it.
std::string usage() {
  return "usage: mpirun -np N pvr-node --batch SCENE.json -o OUT.exr|OUT.png [OPTION VALUE ...]\n"
         "       mpirun -np N pvr-node --server --connect HOST:PORT --data-dir DIR\n"
         "       pvr-node --catalog DIR\n"
         "\n"
         "The MPI program of PVR: pvrd starts it in server mode for a session; batch mode renders\n"
         "one scene across the ranks and prints the time breakdown; catalog mode lists a data directory.\n"
         "\n"
         "batch options:\n"
         "  --batch SCENE.json         the scene to render (docs/scene.md); required\n"
         "  -o OUT.exr|OUT.png         the image to write (EXR: linear float; PNG: sRGB); required\n"
         "  --strategy NAME            compositing: " + names(composite::strategies(), ", ") + "\n"
         "  --radix K                  radix of the radix-k strategy\n"
         "  --decomposition NAME       bricks: " + names(node::decompositions(), ", ") + "\n"
         "  --early-termination A      stop a ray at opacity A in (0, 1]\n"
         "  --threads N                render threads per rank (default: all cores)\n"
         "  --codec auto|rle|rle-zlib|raw  image codec between ranks (default auto)\n"
         "  --size WxH                 image size (default: the scene's)\n"
         "  --stats FILE.csv           also write the per-rank times as CSV\n"
         "server options (pvrd passes them):\n"
         "  --server                   serve one pvrd session\n"
         "  --connect HOST:PORT        the session handler to connect to\n"
         "  --data-dir DIR             the data directory datasets resolve in\n"
         "  --stall-timeout S          a rank without progress for S s ends the job (default 30)\n"
         "catalog:\n"
         "  --catalog DIR              print the datasets of DIR, one per line, and exit\n"
         "  -h, --help                 print this help and exit\n"
         "\n"
         "example:\n"
         "  mpirun -np 4 pvr-node --batch examples/scenes/ct_head_bone.json -o head.png --strategy binary-swap\n";
}

[[noreturn]] void bad(const std::string& why) { throw Error(ErrorCode::kInvalidArgument, why); }

int integer(const std::string& option, const std::string& v) {
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(v, &used);
  } catch (const std::logic_error&) {
    used = 0;
  }
  if (used != v.size()) bad(option + " takes an integer, not '" + v + "'");
  return value;
}

core::ImageCodec codecNamed(const std::string& v) {
  if (v == "auto") return core::ImageCodec::kAuto;
  if (v == "rle") return core::ImageCodec::kRle;
  if (v == "rle-zlib") return core::ImageCodec::kRleZlib;
  if (v == "raw") return core::ImageCodec::kRaw;
  bad("--codec takes auto, rle, rle-zlib or raw, not '" + v + "'");
}

// The same arguments on every rank give the same result or the same error.
Args parseArgs(int argc, char** argv) {
  Args a;
  bool batch = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) bad(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--batch") {
      batch = true;
      a.scene = value();
    } else if (arg == "-o") {
      a.output = value();
    } else if (arg == "--strategy") {
      a.frame.strategy = value();
    } else if (arg == "--radix") {
      a.frame.strategyParams.radix = integer(arg, value());
    } else if (arg == "--decomposition") {
      const std::string v = value();
      try {
        a.frame.decomposition = node::decompositionNamed(v);
      } catch (const Error& e) {
        bad("--decomposition: " + std::string(e.what()));
      }
    } else if (arg == "--early-termination") {
      const std::string v = value();
      try {
        a.frame.earlyTermination = std::stod(v);
      } catch (const std::logic_error&) {
        bad("--early-termination takes a number in (0, 1], not '" + v + "'");
      }
    } else if (arg == "--threads") {
      a.frame.threads = integer(arg, value());
    } else if (arg == "--codec") {
      a.frame.codec = codecNamed(value());
    } else if (arg == "--size") {
      const std::string v = value();
      if (std::sscanf(v.c_str(), "%dx%d", &a.width, &a.height) != 2 || a.width < 1 || a.height < 1)
        bad("--size takes WxH, not '" + v + "'");
    } else if (arg == "--stats") {
      a.stats = value();
    } else {
      bad("unknown argument '" + arg + "'");
    }
  }
  if (!batch) bad("--batch SCENE.json is required");
  if (a.output.empty()) bad("no output file (-o)");
  return a;
}

int run(const Args& args, const std::vector<std::string>& hosts, comm::Communicator& comm) {
  core::Scene scene;
  comm::runAgreed(comm, [&] {
    scene = core::loadSceneFile(args.scene);
    if (args.width > 0) scene.image.width = args.width, scene.image.height = args.height;
  });
  const node::FrameResult result = node::renderFrame(scene, args.frame, comm);
  comm::runAgreed(comm, [&] {
    if (comm.rank() != 0) return;
    const auto writeStart = std::chrono::steady_clock::now();
    node::writeImageFile(result.image, result.scene.image.background, args.output);
    node::OutputTimes output;
    output.write = std::chrono::duration<double>(std::chrono::steady_clock::now() - writeStart).count();
    output.wall = node::processAgeSeconds();
    if (!args.stats.empty()) node::writeStatsCsv(args.stats, result, args.frame, output);
    std::printf("%s: %s", args.output.c_str(), node::formatReport(result, args.frame, hosts, output).c_str());
  });
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Help before MPI starts: `pvr-node --help` works without mpirun.
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::fputs(usage().c_str(), stdout);
      return 0;
    }
  if (argc == 3 && std::string(argv[1]) == "--catalog") return node::printCatalog(argv[2], stdout, stderr);
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) != "--server") continue;
    node::ServerOptions options;
    std::string error;
    if (!node::parseServerOptions(argc, argv, options, error)) {
      std::fprintf(stderr, "pvr-node: %s\n", error.c_str());
      return 2;
    }
    return node::runServer(options);
  }
  comm::MpiEnvironment mpi(&argc, &argv);
  comm::Communicator& comm = mpi.world();
  const std::vector<std::string> hosts = node::gatherHostNames(comm);
  try {
    return run(parseArgs(argc, argv), hosts, comm);
  } catch (const Error& e) {
    if (comm.rank() == 0) {
      // A rank's failure names its host: "rank 2 on h1: ...".
      const auto* failure = dynamic_cast<const comm::FailureError*>(&e);
      std::fprintf(stderr, "pvr-node: %s\n",
                   failure ? node::describeOnHost(failure->failure(), hosts).c_str() : e.what());
      if (e.code() == ErrorCode::kInvalidArgument) std::fputs(usage().c_str(), stderr);
    }
    return e.code() == ErrorCode::kInvalidArgument ? 2 : 1;
  }
}
