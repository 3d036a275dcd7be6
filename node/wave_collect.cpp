#include "wave_collect.h"

#include <chrono>
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

}  // namespace

void collectWave(NodeState& state, std::uint32_t request, std::uint32_t lastFrame,
                 std::optional<comm::Failure>& failure) {
  // Timings: max over ranks; slot s holds rend, comp, comm at 4s+1..4s+3,
  // and slot 0 the distribution at 0.
  const std::size_t slots = state.wave.size();
  std::vector<double> times(slots * 4, 0.0);
  for (std::size_t s = 0; s < slots; ++s) {
    times[s * 4 + 1] = state.wave[s].rend;
    times[s * 4 + 2] = state.wave[s].comp;
    times[s * 4 + 3] = state.wave[s].comm;
  }
  if (slots > 0) times[0] = state.pendingDist;
  state.pendingDist = 0;
  state.world.allReduceMax(times);
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
