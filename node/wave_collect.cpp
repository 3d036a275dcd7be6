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

// Every rank's timings of a wave, flat: first the charges not yet made to
// a frame (read, preprocess, distribute), then rend, comp, comm per slot.
constexpr std::size_t kPending = 3, kPerSlot = 3;
constexpr std::size_t kRead = 0, kPreprocess = 1, kDistribute = 2;
constexpr std::size_t kRend = 0, kComp = 1, kComm = 2;
std::size_t at(std::size_t slot, std::size_t phase) { return kPending + slot * kPerSlot + phase; }

// A wave's phases from every rank's: read, preprocess, distribute, rend and
// comp are the slowest rank's; comm is the longest a rank spent in
// compositing messages beyond waiting for a slower rank's brick (a rank
// that finished rendering early waits in its first exchange), so the
// phases add up to the frame's time instead of counting the render
// imbalance twice.
std::vector<double> frameTimes(const std::vector<comm::Bytes>& perRank, std::size_t slots) {
  const std::size_t count = at(slots, 0);
  std::vector<std::vector<double>> ranks;
  for (const comm::Bytes& b : perRank) {
    if (b.size() != count * sizeof(double)) throw Error(ErrorCode::kInternal, "wave timings of the wrong size");
    std::vector<double> t(count);
    std::memcpy(t.data(), b.data(), b.size());
    ranks.push_back(std::move(t));
  }
  std::vector<double> out(count, 0.0);
  for (const auto& t : ranks)
    for (std::size_t i = 0; i < count; ++i)
      if (i < kPending || (i - kPending) % kPerSlot != kComm) out[i] = std::max(out[i], t[i]);
  for (std::size_t s = 0; s < slots; ++s)
    for (const auto& t : ranks) {
      const double waitForRender = out[at(s, kRend)] - t[at(s, kRend)];
      out[at(s, kComm)] = std::max(out[at(s, kComm)], t[at(s, kComm)] - waitForRender);
    }
  return out;
}

// Slot s's frame from its bands: the one band itself when it covers the
// whole frame (one band, nothing cropped), so that the collector does not
// hold the frame twice; else the bands pasted into a transparent frame.
core::Image framePieces(decltype(NodeState::bands)& bands, int s, int width, int height) {
  const core::PixelRect whole{0, 0, width, height};
  for (auto& [key, band] : bands)
    if (key.first == s && band.rect() == whole) return std::move(band);
  core::Image frame = core::Image::fullFrame(width, height);
  for (const auto& [key, band] : bands)
    if (key.first == s) paste(frame, band);
  return frame;
}

}  // namespace

void collectWave(NodeState& state, std::uint32_t request, std::uint32_t lastFrame, bool coarse,
                 std::optional<comm::Failure>& failure) {
  // Timings of every rank, gathered; the pending charges go to the wave's
  // first frame. A coarse wave gathers nothing: the collector's own
  // timings go with its frame, and the pending charges wait for the full
  // frame's wave.
  const std::size_t slots = state.wave.size();
  std::vector<double> mine(at(slots, 0), 0.0);
  if (slots > 0 && !coarse) {
    mine[kRead] = state.pendingRead;
    mine[kPreprocess] = state.pendingPreprocess;
    mine[kDistribute] = state.pendingDist;
    state.pendingRead = state.pendingPreprocess = state.pendingDist = 0;
  }
  for (std::size_t s = 0; s < slots; ++s) {
    mine[at(s, kRend)] = state.wave[s].rend;
    mine[at(s, kComp)] = state.wave[s].comp;
    mine[at(s, kComm)] = state.wave[s].comm;
  }
  const std::vector<double> times = coarse ? mine : frameTimes(state.world.allGather(std::as_bytes(std::span(mine))), slots);
  if (state.world.rank() != 0 || failure) return;

  const int width = state.scene.image.width, height = state.scene.image.height;
  try {
    for (std::size_t s = 0; s < slots; ++s) {
      const auto start = std::chrono::steady_clock::now();
      core::Image frame = framePieces(state.bands, int(s), width, height);
      const std::uint32_t number = state.wave[s].number;
      if (!state.dumpDir.empty()) dumpFloat(state.dumpDir, request, number, frame);
      proto::ImageFrame out;
      out.frameNumber = number;
      out.width = std::uint32_t(width);
      out.height = std::uint32_t(height);
      out.format = state.settings.format;
      setFramePixels(out, frame, state.scene.image.background, state.settings.compression);
      if (s == 0) {
        out.timing.read = times[kRead];
        out.timing.preprocess = times[kPreprocess];
        out.timing.distribute = times[kDistribute] + state.commandSeconds;
      }
      out.timing.render = times[at(s, kRend)];
      out.timing.composite = times[at(s, kComp)];
      out.timing.communicate = times[at(s, kComm)];
      out.timing.send = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (state.sendFrame) state.sendFrame(std::move(out), number == lastFrame);
    }
  } catch (...) {
    failure = comm::failureOf(std::current_exception(), state.world.rank());
  }
}

}  // namespace pvr::node
