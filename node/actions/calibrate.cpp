// calibrate: measures what the compositing latency model needs, once per
// session: message latency and bandwidth by ping-pong between world rank 0
// and the last rank (half the round trip of small and of 4 MiB messages),
// and the blending rate ("over" of two 256x256 images) on every rank (the
// slowest counts). Every rank ends with the same Calibration.
#include <chrono>

#include "table.h"

namespace pvr::node::actions {

namespace {

using Clock = std::chrono::steady_clock;

double pingPong(comm::Communicator& world, int peer, std::size_t bytes, int rounds) {
  const comm::Bytes message(bytes);
  const auto start = Clock::now();
  for (int i = 0; i < rounds; ++i) {
    if (world.rank() == 0) {
      world.send(peer, kPingTag, message);
      world.receive(peer, kPingTag);
    } else {
      world.receive(0, kPingTag);
      world.send(0, kPingTag, message);
    }
  }
  return std::chrono::duration<double>(Clock::now() - start).count() / (2.0 * rounds);
}

}  // namespace

void Calibrate::run(NodeState& state, const Calibrate&) {
  comm::Communicator& world = state.world;
  const int peer = world.size() - 1;
  std::vector<double> measured(3, 0.0);  // latency, seconds per byte, seconds per pixel
  if (peer > 0 && (world.rank() == 0 || world.rank() == peer)) {
    constexpr std::size_t kBig = 4u << 20;
    pingPong(world, peer, 8, 5);  // warm up the connection
    const double latency = pingPong(world, peer, 8, 50);
    const double big = pingPong(world, peer, kBig, 4);
    measured[0] = latency;
    measured[1] = std::max(big - latency, 1e-9) / double(kBig);
  }
  {
    core::Image front = core::Image::fullFrame(256, 256), back = core::Image::fullFrame(256, 256);
    for (auto& p : back.pixels()) p = {0.2f, 0.3f, 0.4f, 0.5f};
    for (auto& p : front.pixels()) p = {0.1f, 0.1f, 0.1f, 0.2f};
    const auto start = Clock::now();
    constexpr int kRounds = 8;
    for (int i = 0; i < kRounds; ++i) core::compositeUnder(front, back);
    measured[2] = std::chrono::duration<double>(Clock::now() - start).count() / (kRounds * 256.0 * 256.0);
  }
  world.allReduceMax(measured);
  state.calibration.latency = measured[0];
  state.calibration.bandwidth = measured[1] > 0 ? 1.0 / measured[1] : 0.0;
  state.calibration.blendRate = measured[2] > 0 ? 1.0 / measured[2] : 0.0;
}

}  // namespace pvr::node::actions
