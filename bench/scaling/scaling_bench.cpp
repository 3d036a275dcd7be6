// pvr-bench-scaling: one session of pvr-node --server, driven as pvrd's
// session handler drives it, timing a rotation.
//
//   pvr-bench-scaling --np N --data-dir DIR --dataset NAME --scene PATCH.json
//       [--layout r2:0,r2:1,c1:0] [--frames 72] [--size 256] [--threads 1]
//       [--label TEXT] [--mpirun PATH]
//   pvr-bench-scaling --generate DIR/NAME N     (N^3 uint8 raw + sidecar)
//
// Prints one CSV row: label, np, layout, frames, size, wall seconds per
// frame, the mean per-frame breakdown (dist, rend, comp, comm, send: each
// the max over ranks), and the largest dataset bytes held by one rank.
// Layout entries: r|c RANKS : GROUP (render or composite cluster).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "pvr_protocol.h"

namespace {

using namespace pvr;
using Clock = std::chrono::steady_clock;

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "pvr-bench-scaling: %s\n", why.c_str());
  std::exit(1);
}

// Spheres of different densities in a 0..255 background ramp: content
// everywhere, denser towards one corner (so balanced trees differ).
void generate(const std::string& base, int n) {
  std::FILE* f = std::fopen((base + ".raw").c_str(), "wb");
  if (!f) die("cannot write " + base + ".raw");
  std::vector<std::uint8_t> slab(std::size_t(n) * n);
  for (int z = 0; z < n; ++z) {
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double u = double(x) / n - 0.5, v = double(y) / n - 0.5, w = double(z) / n - 0.5;
        const double r = std::sqrt(u * u + v * v + w * w);
        double value = r < 0.45 ? 60 + 120 * (0.45 - r) / 0.45 : 10;
        const double ru = u - 0.15, rv = v + 0.1, rw = w - 0.05;
        if (ru * ru + rv * rv + rw * rw < 0.02) value = 230;
        slab[std::size_t(y) * n + x] = std::uint8_t(value + 15 * std::sin(40 * u) * std::sin(37 * v));
      }
    std::fwrite(slab.data(), 1, slab.size(), f);
  }
  std::fclose(f);
  const std::string name = base.substr(base.rfind('/') + 1);
  std::ofstream(base + ".json") << nlohmann::json{{"dims", {n, n, n}}, {"dtype", "uint8"}, {"spacing", {1, 1, 1}},
                                                  {"raw_file", name + ".raw"}}
                                       .dump();
}

std::vector<proto::ClusterSpec> parseLayout(const std::string& text) {
  std::vector<proto::ClusterSpec> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    proto::ClusterSpec c;
    c.role = item[0] == 'c' ? proto::ClusterRole::kComposite : proto::ClusterRole::kRender;
    unsigned ranks = 0, group = 0;
    if (std::sscanf(item.c_str() + 1, "%u:%u", &ranks, &group) != 2) die("bad layout entry " + item);
    c.ranks = ranks;
    c.group = group;
    out.push_back(c);
  }
  return out;
}

struct Session {
  int fd = -1;
  pid_t pid = -1;
  std::uint32_t id = 0;
  proto::FrameDecoder decoder{proto::Limits{}};

  std::uint32_t send(const proto::Message& m) {
    const auto bytes = proto::encode(m, ++id, proto::kFlagFinal);
    if (::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) != ssize_t(bytes.size())) die("send failed");
    return id;
  }
  proto::Decoded receive() {
    for (;;) {
      if (auto d = decoder.pop()) {
        if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) die("server: " + e->text);
        return *d;
      }
      if (decoder.error()) die("protocol error");
      std::uint8_t buf[1 << 16];
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n <= 0) die("the job ended");
      decoder.feed(std::span(buf, std::size_t(n)));
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string dataDir, dataset, scenePath, layout, label = "run", mpirun = "mpirun";
  int np = 1, frames = 72, size = 256, threads = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) die(a + " needs a value");
      return argv[++i];
    };
    if (a == "--generate") {
      const std::string base = value();
      generate(base, std::atoi(value().c_str()));
      return 0;
    }
    if (a == "--np") np = std::atoi(value().c_str());
    else if (a == "--data-dir") dataDir = value();
    else if (a == "--dataset") dataset = value();
    else if (a == "--scene") scenePath = value();
    else if (a == "--layout") layout = value();
    else if (a == "--frames") frames = std::atoi(value().c_str());
    else if (a == "--size") size = std::atoi(value().c_str());
    else if (a == "--threads") threads = std::atoi(value().c_str());
    else if (a == "--label") label = value();
    else if (a == "--mpirun") mpirun = value();
    else die("unknown argument " + a);
  }
  nlohmann::json scene = nlohmann::json::object();
  if (!scenePath.empty()) scene = nlohmann::json::parse(std::ifstream(scenePath));
  scene.erase("volume");
  scene["image"]["width"] = size;
  scene["image"]["height"] = size;
  scene["runtime"] = {{"threads", threads}};

  // Listen, start the job, accept the master.
  const int listenFd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(listenFd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(listenFd, 1) != 0)
    die("cannot listen");
  socklen_t len = sizeof addr;
  ::getsockname(listenFd, reinterpret_cast<sockaddr*>(&addr), &len);
  Session s;
  s.pid = ::fork();
  if (s.pid == 0) {
    std::vector<std::string> args{mpirun, "--oversubscribe", "--bind-to", "none", "-np", std::to_string(np),
                                  PVR_NODE_PATH, "--server", "--connect",
                                  "127.0.0.1:" + std::to_string(ntohs(addr.sin_port)), "--data-dir", dataDir};
    std::vector<char*> av;
    for (auto& x : args) av.push_back(x.data());
    av.push_back(nullptr);
    ::execvp(av[0], av.data());
    ::_exit(127);
  }
  s.fd = ::accept(listenFd, nullptr, nullptr);
  if (s.fd < 0) die("the master did not connect");

  s.send(proto::SessionOpen{std::uint32_t(np), layout.empty() ? std::vector<proto::ClusterSpec>{} : parseLayout(layout), ""});
  s.receive();
  s.send(proto::SetScene{dataset, scene.dump()});
  s.receive();
  // One frame to warm up (first-touch of bricks, thread start), then the rotation.
  s.send(proto::RenderFrame{});
  s.receive();
  const auto start = Clock::now();
  s.send(proto::RenderRotation{{0, 0, 1}, 0, frames - 1, std::uint32_t(frames)});
  double sum[5] = {0, 0, 0, 0, 0};
  for (int k = 0; k < frames; ++k) {
    const auto d = s.receive();
    const auto& f = std::get<proto::ImageFrame>(d.message);
    sum[0] += f.timing.distribute, sum[1] += f.timing.render, sum[2] += f.timing.composite;
    sum[3] += f.timing.communicate, sum[4] += f.timing.send;
  }
  const double perFrame = std::chrono::duration<double>(Clock::now() - start).count() / frames;
  s.send(proto::PerformanceRequest{proto::PerformanceQuery::kMemory, proto::kAllClusters});
  const auto memory = nlohmann::json::parse(std::get<proto::PerformanceReply>(s.receive().message).json);
  std::uint64_t most = 0;
  std::string perRank;
  for (const auto& c : memory["clusters"])
    for (const auto& b : c["bytes_per_rank"]) {
      most = std::max(most, b.get<std::uint64_t>());
      if (!perRank.empty()) perRank += ' ';
      perRank += std::to_string(b.get<std::uint64_t>());
    }
  std::printf("%s,%d,%s,%d,%d,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%llu,%s\n", label.c_str(), np,
              layout.empty() ? "default" : layout.c_str(), frames, size, perFrame, sum[0] / frames, sum[1] / frames,
              sum[2] / frames, sum[3] / frames, sum[4] / frames, static_cast<unsigned long long>(most), perRank.c_str());
  s.send(proto::Close{"done"});
  int status = 0;
  ::waitpid(s.pid, &status, 0);
  return 0;
}
