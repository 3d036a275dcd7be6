// Compositing benchmark: one rendering per image size, composited by every
// strategy with each sparse codec, a few times; rank 0 appends one CSV row
// per (size, strategy, codec) with the max-over-ranks time breakdown of
// the binary-swap paper's Table 1 (dist, rend, comp, comm, send), the
// messages and bytes sent, and the compression ratio; and, with
// --memory-csv, the voxel bytes per rank for both decompositions.
//
//   mpirun -np N pvr-bench-compositing --scene SCENE.json --size 512 [--size 1024]
//          [--repeat 3] [--radix 4] --csv OUT.csv [--memory-csv MEM.csv]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "frame.h"
#include "report.h"
#include "mpi_communicator.h"

namespace {

using namespace pvr;

struct Args {
  std::string scene, csv, memoryCsv;
  std::vector<int> sizes;
  int repeat = 3, radix = 4;
};

Args parseArgs(int argc, char** argv) {
  Args a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i], v = argv[i + 1];
    if (arg == "--scene") a.scene = v;
    else if (arg == "--size") a.sizes.push_back(std::stoi(v));
    else if (arg == "--repeat") a.repeat = std::max(1, std::stoi(v));
    else if (arg == "--radix") a.radix = std::stoi(v);
    else if (arg == "--csv") a.csv = v;
    else if (arg == "--memory-csv") a.memoryCsv = v;
    else throw Error(ErrorCode::kInvalidArgument, "unknown argument " + arg);
  }
  if (a.scene.empty() || a.csv.empty() || a.sizes.empty())
    throw Error(ErrorCode::kInvalidArgument, "need --scene, --csv and at least one --size");
  return a;
}

std::ofstream appendCsv(const std::string& path, const char* header) {
  const bool fresh = !std::filesystem::exists(path);
  std::ofstream out(path, std::ios::app);
  if (!out) throw Error(ErrorCode::kIo, path + ": cannot open for appending");
  if (fresh) out << header << '\n';
  return out;
}

double maxOver(const std::vector<node::RankReport>& ranks, double (*f)(const node::RankReport&)) {
  double m = 0;
  for (const auto& r : ranks) m = std::max(m, f(r));
  return m;
}

struct Sample {
  double composite = 0, comp = 0, comm = 0, send = 0;
};

void benchSize(const Args& args, core::Scene scene, int size, comm::Communicator& comm) {
  scene.image.width = scene.image.height = size;
  node::FrameOptions options;
  const node::PreparedFrame prepared = node::prepareFrame(scene, options, comm);
  std::vector<double> distRend{prepared.report.dist, prepared.report.rend};  // max over ranks
  comm.allReduceMax(distRend);

  struct Case {
    const char* strategy;
    int radix;
  };
  const std::vector<Case> cases = {{"binary-swap", 2}, {"radix-k", args.radix}, {"direct-send", 2}, {"tree", 2}};
  for (const Case& c : cases)
    for (auto [codec, codecName] : {std::pair{core::ImageCodec::kRle, "rle"}, {core::ImageCodec::kRleZlib, "rle-zlib"}}) {
      options.strategy = c.strategy;
      options.strategyParams.radix = c.radix;
      options.codec = codec;
      std::vector<Sample> samples;
      node::FrameResult last;
      for (int k = 0; k < args.repeat; ++k) {
        comm.barrier();
        last = node::compositeFrame(prepared, options, comm);
        Sample s;
        s.composite = maxOver(last.ranks, [](const node::RankReport& r) { return r.comp + r.comm + r.send; });
        s.comp = maxOver(last.ranks, [](const node::RankReport& r) { return r.comp; });
        s.comm = maxOver(last.ranks, [](const node::RankReport& r) { return r.comm; });
        s.send = maxOver(last.ranks, [](const node::RankReport& r) { return r.send; });
        samples.push_back(s);
      }
      if (comm.rank() != 0) continue;
      // The median repetition by composite time.
      std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.composite < b.composite; });
      const Sample& s = samples[samples.size() / 2];
      const node::TrafficTotals traffic = node::sumTraffic(last.ranks);
      const std::uint64_t messages = traffic.messages, maxMessages = traffic.maxMessagesPerRank,
                          raw = traffic.rawBytes, encoded = traffic.encodedBytes, pixels = traffic.pixels,
                          gather = traffic.gatherBytes;
      const std::string name = c.radix != 2 ? std::string(c.strategy) + "-" + std::to_string(c.radix) : c.strategy;
      const double frame = distRend[1] + s.composite;
      std::ofstream out = appendCsv(
          args.csv,
          "ranks,width,height,strategy,codec,composite_s,comp_s,comm_s,send_s,dist_s,rend_s,frame_s,"
          "composite_share,messages,max_messages_per_rank,raw_bytes,encoded_bytes,compression,pixels_sent,"
          "gather_bytes");
      out << comm.size() << ',' << size << ',' << size << ',' << name << ',' << codecName << ',' << s.composite
          << ',' << s.comp << ',' << s.comm << ',' << s.send << ',' << distRend[0] << ',' << distRend[1] << ','
          << frame << ',' << s.composite / frame << ',' << messages << ',' << maxMessages << ',' << raw << ','
          << encoded << ',' << (encoded ? double(raw) / double(encoded) : 1.0) << ',' << pixels << ','
          << gather << '\n';
      std::printf("%2d ranks %4d^2 %-12s %-8s composite %.4f s (comp %.4f comm %.4f send %.4f), rend %.4f s, "
                  "%llu msgs, %.2f MB -> %.2f MB\n",
                  comm.size(), size, name.c_str(), codecName, s.composite, s.comp, s.comm, s.send, distRend[1],
                  (unsigned long long)messages, raw * 1e-6, encoded * 1e-6);
    }
}

// Voxel bytes per rank against (1/n) of the volume, for every decomposition.
void benchMemory(const Args& args, core::Scene scene, comm::Communicator& comm) {
  scene.image.width = scene.image.height = 64;  // the rendering is not the point here
  for (const auto& entry : node::decompositions()) {
    node::FrameOptions options;
    options.decomposition = entry.value;
    const node::FrameResult r = node::renderFrame(scene, options, comm);
    if (comm.rank() != 0) continue;
    std::uint64_t mx = 0, mn = ~0ull, sum = 0;
    for (const auto& rank : r.ranks) {
      mx = std::max(mx, rank.brickBytes);
      mn = std::min(mn, rank.brickBytes);
      sum += rank.brickBytes;
    }
    const double n = double(comm.size());
    std::ofstream out = appendCsv(args.memoryCsv,
                                  "ranks,decomposition,max_brick_bytes,mean_brick_bytes,min_brick_bytes,"
                                  "volume_bytes,volume_over_n,ghost_layers,max_over_share");
    out << comm.size() << ',' << entry.name << ','
        << mx << ',' << sum / n << ',' << mn << ',' << r.volumeBytes << ',' << r.volumeBytes / n << ','
        << r.ghostLayers << ',' << mx / (r.volumeBytes / n) << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  comm::MpiEnvironment mpi(&argc, &argv);
  comm::Communicator& comm = mpi.world();
  try {
    const Args args = parseArgs(argc, argv);
    core::Scene scene;
    comm::runAgreed(comm, [&] { scene = core::loadSceneFile(args.scene); });
    for (int size : args.sizes) benchSize(args, scene, size, comm);
    if (!args.memoryCsv.empty()) benchMemory(args, scene, comm);
    return 0;
  } catch (const Error& e) {
    if (comm.rank() == 0) std::fprintf(stderr, "pvr-bench-compositing: %s\n", e.what());
    return 1;
  }
}
