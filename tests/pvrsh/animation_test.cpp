// The animated file's frame rate and the ffmpeg command that writes it
// (pvrsh/animation.h, issue 14 point 8), checked without ffmpeg: CI's fresh
// machine may not have it. server.test runs the same command through a
// session (a stand-in ffmpeg records it; the real one, where installed,
// writes a file whose rate ffprobe reads).
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "animation.h"
#include "tcl_error.h"

using namespace pvr::tcl;

TEST_CASE("fpsOf takes whole frame rates from 1 to 120 and names anything else with the range") {
  CHECK(fpsOf("1") == 1);
  CHECK(fpsOf("24") == 24);
  CHECK(fpsOf("120") == 120);
  for (const char* bad : {"0", "121", "-5", "+24", " 24", "24 ", "24.5", "24fps", "", "abc", "99999999999999999999"}) {
    INFO("text '" << bad << "'");
    try {
      fpsOf(bad);
      FAIL("accepted");
    } catch (const TclError& e) {
      CHECK(e.code() == std::vector<std::string>{"PVR", "ARGS", "FPS"});
      CHECK(std::string(e.what()) == std::string("image file: -fps must be a whole number of frames per second from 1 to 120, got '") + bad + "'");
    }
  }
}

TEST_CASE("ffmpegArguments gives ffmpeg the frame rate as the input rate, for MP4 and GIF alike") {
  const auto mp4 = ffmpegArguments("out/movie.mp4", "out/movie_%05d.png", 7, 24);
  CHECK(mp4 == std::vector<std::string>{"ffmpeg", "-y", "-loglevel", "error", "-framerate", "24", "-start_number", "7",
                                        "-i", "out/movie_%05d.png", "-vf",
                                        "scale=trunc(iw/2)*2:trunc(ih/2)*2,format=yuv420p", "out/movie.mp4"});
  const auto gif = ffmpegArguments("movie.gif", "movie_%05d.png", 0, 50);
  CHECK(gif == std::vector<std::string>{"ffmpeg", "-y", "-loglevel", "error", "-framerate", "50", "-start_number", "0",
                                        "-i", "movie_%05d.png", "-vf",
                                        "split[a][b];[a]palettegen=stats_mode=full[p];[b][p]paletteuse=dither=sierra2_4a",
                                        "movie.gif"});
  CHECK(ffmpegArguments("m.mp4", "m_%05d.png", 0, kDefaultFps)[5] == "10");
}
