#include "wave_collect.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <span>
#include <cstdio>
#include <string>
#include <vector>

#include "frame_pixels.h"
#include "wave_io.h"

namespace pvr::node {

namespace {

void dumpFloat(const std::string& dir, std::uint32_t request, std::uint32_t frame, const core::Image& image) {
  const std::string path = dir + "/frame-" + std::to_string(request) + "-" + std::to_string(frame) + ".f32";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Error(ErrorCode::kIo, "cannot write " + path);
  const std::int32_t size[2] = {image.frameWidth(), image.frameHeight()};
  std::fwrite(size, sizeof size, 1, f);
  std::fwrite(image.pixels().data(), sizeof(core::Rgba), image.pixels().size(), f);
  std::fclose(f);
}

// A frame's phases from every rank's: dist, rend and comp are the slowest
// rank's; comm is the longest a rank spent in compositing messages beyond
// waiting for a slower rank's brick (a rank that finished rendering early
// waits in its first exchange), so the phases add up to the frame's time
// instead of counting the render imbalance twice.
std::vector<double> frameTimes(const std::vector<comm::Bytes>& perRank, std::size_t slots) {
  std::vector<std::vector<double>> ranks;
  for (const comm::Bytes& b : perRank) {
    if (b.size() != slots * 4 * sizeof(double)) throw Error(ErrorCode::kInternal, "wave timings of the wrong size");
    std::vector<double> t(slots * 4);
    std::memcpy(t.data(), b.data(), b.size());
    ranks.push_back(std::move(t));
  }
  std::vector<double> out(slots * 4, 0.0);
  for (const auto& t : ranks)
    for (std::size_t i = 0; i < out.size(); ++i)
      if (i % 4 != 3) out[i] = std::max(out[i], t[i]);
  for (std::size_t s = 0; s < slots; ++s)
    for (const auto& t : ranks) {
      const double waitForRender = out[s * 4 + 1] - t[s * 4 + 1];
      out[s * 4 + 3] = std::max(out[s * 4 + 3], t[s * 4 + 3] - waitForRender);
    }
  return out;
}

}  // namespace

void collectWave(NodeState& state, std::uint32_t request, std::uint32_t lastFrame,
                 std::optional<comm::Failure>& failure) {
  // Timings of every rank, gathered: slot s holds rend, comp, comm at
  // 4s+1..4s+3, and slot 0 the distribution at 0.
  const std::size_t slots = state.wave.size();
  std::vector<double> mine(slots * 4, 0.0);
  for (std::size_t s = 0; s < slots; ++s) {
    mine[s * 4 + 1] = state.wave[s].rend;
    mine[s * 4 + 2] = state.wave[s].comp;
    mine[s * 4 + 3] = state.wave[s].comm;
  }
  if (slots > 0) mine[0] = state.pendingDist;
  state.pendingDist = 0;
  const std::vector<double> times = frameTimes(state.world.allGather(std::as_bytes(std::span(mine))), slots);
  if (state.world.rank() != 0 || failure) return;

  const int width = state.scene.image.width, height = state.scene.image.height;
  try {
    for (std::size_t s = 0; s < slots; ++s) {
      const auto start = std::chrono::steady_clock::now();
      core::Image frame = core::Image::fullFrame(width, height);
      for (const auto& [key, band] : state.bands)
        if (key.first == int(s)) paste(frame, band);
      const std::uint32_t number = state.wave[s].number;
      if (!state.dumpDir.empty()) dumpFloat(state.dumpDir, request, number, frame);
      proto::ImageFrame out;
      out.frameNumber = number;
      out.width = std::uint32_t(width);
      out.height = std::uint32_t(height);
      out.format = state.settings.format;
      setFramePixels(out, frame, state.scene.image.background, state.settings.compression);
      out.timing.distribute = s == 0 ? times[0] + state.commandSeconds : 0.0;
      out.timing.render = times[s * 4 + 1];
      out.timing.composite = times[s * 4 + 2];
      out.timing.communicate = times[s * 4 + 3];
      out.timing.send = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (state.sendFrame) state.sendFrame(std::move(out), number == lastFrame);
    }
  } catch (...) {
    failure = comm::failureOf(std::current_exception(), state.world.rank());
  }
}

}  // namespace pvr::node
