#include "animation.h"

#include <cerrno>
#include <cstdlib>

#include "tcl_error.h"

namespace pvr::tcl {

int fpsOf(const std::string& text) {
  // Whole numbers only: ffmpeg takes rationals, but a GIF cannot hold
  // 29.97 frames/s anyway, and a typo such as "2 4" or "24fps" must not
  // become 2 or 24 silently.
  errno = 0;
  char* end = nullptr;
  const bool digitFirst = !text.empty() && text[0] >= '0' && text[0] <= '9';  // strtol would skip spaces
  const long v = digitFirst ? std::strtol(text.c_str(), &end, 10) : 0;
  if (!digitFirst || *end != '\0' || errno != 0 || v < kMinFps || v > kMaxFps)
    throw TclError({"PVR", "ARGS", "FPS"}, "image file: -fps must be a whole number of frames per second from " +
                                               std::to_string(kMinFps) + " to " + std::to_string(kMaxFps) +
                                               ", got '" + text + "'");
  return int(v);
}

std::vector<std::string> ffmpegArguments(const std::string& target, const std::string& inputPattern,
                                         std::uint64_t startNumber, int fps) {
  const bool gif = target.size() >= 4 && target.compare(target.size() - 4, 4, ".gif") == 0;
  // The input rate is the output rate: image2 stamps frame k at k/FPS, the
  // MP4 keeps that time base and the GIF muxer turns the stamps into
  // per-frame delays in hundredths of a second.
  const std::string filter = gif ? "split[a][b];[a]palettegen=stats_mode=full[p];[b][p]paletteuse=dither=sierra2_4a"
                                 : "scale=trunc(iw/2)*2:trunc(ih/2)*2,format=yuv420p";
  return {"ffmpeg", "-y", "-loglevel", "error", "-framerate", std::to_string(fps), "-start_number",
          std::to_string(startNumber), "-i", inputPattern, "-vf", filter, target};
}

}  // namespace pvr::tcl
