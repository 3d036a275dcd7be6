#include "report.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <functional>

#include "error.h"
#include "hosts.h"

namespace pvr::node {

namespace {

struct Column {
  const char* name;
  std::function<double(const RankReport&)> value;
};

// The phases in the order they follow one another on every rank.
std::vector<Column> timeColumns() {
  return {{"start", [](const RankReport& r) { return r.start; }},
          {"read", [](const RankReport& r) { return r.read; }},
          {"prep", [](const RankReport& r) { return r.prep; }},
          {"dist", [](const RankReport& r) { return r.dist; }},
          {"rend", [](const RankReport& r) { return r.rend; }},
          {"comp", [](const RankReport& r) { return r.comp; }},
          {"comm", [](const RankReport& r) { return r.comm; }},
          {"send", [](const RankReport& r) { return r.send; }}};
}

std::string line(const char* format, auto... args) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}

}  // namespace

TrafficTotals sumTraffic(const std::vector<RankReport>& ranks) {
  TrafficTotals t;
  for (const RankReport& r : ranks) {
    t.messages += r.composite.messagesSent;
    t.maxMessagesPerRank = std::max(t.maxMessagesPerRank, r.composite.messagesSent);
    t.rawBytes += r.composite.rawBytesSent;
    t.encodedBytes += r.composite.encodedBytesSent;
    t.pixels += r.composite.pixelsSent;
    t.gatherBytes += r.composite.gatherBytesSent;
  }
  return t;
}

std::string formatReport(const FrameResult& result, const FrameOptions& options,
                         const std::vector<std::string>& hosts, const OutputTimes& output) {
  const auto& ranks = result.ranks;
  const int n = int(ranks.size());
  std::string out;
  out += line("%s, %d ranks, %s, %s decomposition, %dx%d\n", result.volume.c_str(), n,
              options.strategy.c_str(), std::string(decompositionName(options.decomposition)).c_str(),
              result.scene.image.width, result.scene.image.height);
  out += "hosts: " + hostRuns(hosts) + "\n";
  out += "time (s)    max       mean    median       min\n";
  double sumOfMax = output.write;
  for (const Column& c : timeColumns()) {
    std::vector<double> v;
    for (const RankReport& r : ranks) v.push_back(c.value(r));
    std::sort(v.begin(), v.end());
    double sum = 0;
    for (double x : v) sum += x;
    const std::size_t half = v.size() / 2;
    const double median = v.size() % 2 ? v[half] : 0.5 * (v[half - 1] + v[half]);
    sumOfMax += v.back();
    out += line("%-8s %9.4f %9.4f %9.4f %9.4f\n", c.name, v.back(), sum / n, median, v.front());
  }
  out += line("%-8s %9.4f   (rank 0 writes the image)\n", "write", output.write);
  out += line("%-8s %9.4f   (phases follow one another on each rank; read and prep are the reader's "
              "own seconds and overlap only where it preprocesses on other threads while reading)\n",
              "sum", sumOfMax);
  out += line("%-8s %9.4f   (rank 0, from its process start to the written image)\n", "wall", output.wall);
  const TrafficTotals traffic = sumTraffic(ranks);
  const std::uint64_t messages = traffic.messages, maxMessages = traffic.maxMessagesPerRank,
                      raw = traffic.rawBytes, encoded = traffic.encodedBytes, pixels = traffic.pixels,
                      gatherBytes = traffic.gatherBytes;
  std::uint64_t maxBrick = 0, sumBrick = 0;
  for (const RankReport& r : ranks) {
    maxBrick = std::max(maxBrick, r.brickBytes);
    sumBrick += r.brickBytes;
  }
  out += line("compositing: %llu messages (at most %llu per rank), %llu pixels, %.3f MB as float RGBA, "
              "%.3f MB sent (%.1fx smaller)\n",
              (unsigned long long)messages, (unsigned long long)maxMessages, (unsigned long long)pixels,
              raw * 1e-6, encoded * 1e-6, encoded ? double(raw) / double(encoded) : 1.0);
  out += line("gather: %.3f MB to rank 0\n", gatherBytes * 1e-6);
  out += line("voxels per rank: at most %.3f MB, mean %.3f MB; volume / ranks = %.3f MB (%d ghost layers, %s)\n",
              maxBrick * 1e-6, sumBrick * 1e-6 / n, result.volumeBytes * 1e-6 / n, result.ghostLayers,
              result.readPartially ? "each rank read its own brick" : "rank 0 read the volume and scattered");
  if (!result.readPartially)
    out += line("rank 0 held the whole volume (%.3f MB) while scattering\n", result.rootReadBytes * 1e-6);
  out += "peak resident memory per rank (MB, and over its voxel bytes):";
  for (int i = 0; i < n; ++i)
    out += line("%s %d: %.1f (%.2fx)", i ? "," : "", i, ranks[i].peakRssBytes * 1e-6,
                ranks[i].brickBytes ? double(ranks[i].peakRssBytes) / double(ranks[i].brickBytes) : 0.0);
  out += "\n";
  return out;
}

void writeStatsCsv(const std::string& path, const FrameResult& result, const FrameOptions& options,
                   const OutputTimes& output) {
  std::ofstream out(path);
  if (!out) throw Error(ErrorCode::kIo, path + ": cannot open for writing");
  out << "rank,ranks,strategy,decomposition,width,height,dist,rend,comp,comm,send,messages,"
         "raw_bytes,encoded_bytes,pixels_sent,gather_messages,gather_bytes,brick_bytes,volume_bytes,"
         "start,read,prep,write,wall,peak_rss_bytes\n";
  for (std::size_t i = 0; i < result.ranks.size(); ++i) {
    const RankReport& r = result.ranks[i];
    out << i << ',' << result.ranks.size() << ',' << options.strategy << ','
        << decompositionName(options.decomposition) << ',' << result.scene.image.width << ','
        << result.scene.image.height << ',' << r.dist << ',' << r.rend << ',' << r.comp << ',' << r.comm
        << ',' << r.send << ',' << r.composite.messagesSent << ',' << r.composite.rawBytesSent << ','
        << r.composite.encodedBytesSent << ',' << r.composite.pixelsSent << ','
        << r.composite.gatherMessagesSent << ',' << r.composite.gatherBytesSent << ',' << r.brickBytes
        << ',' << result.volumeBytes << ',' << r.start << ',' << r.read << ',' << r.prep << ','
        << (i == 0 ? output.write : 0.0) << ',' << (i == 0 ? output.wall : 0.0) << ',' << r.peakRssBytes << '\n';
  }
  if (!out) throw Error(ErrorCode::kIo, path + ": write failed");
}

}  // namespace pvr::node
