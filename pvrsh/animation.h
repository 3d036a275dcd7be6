// The animated file of `image file movie.gif|movie.mp4 ?-fps N?`: its frame
// rate, checked when it is set, and the ffmpeg command line that turns a
// sequence's numbered PNGs into it. Tcl-free, so the unit tests check the
// command line without ffmpeg installed (issue 14, point 8).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pvr::tcl {

// Frames per second of an animated file: 10 unless `-fps` says otherwise.
// A GIF stores each frame's delay in whole hundredths of a second, so it
// plays 100/round(100/fps) frames/s (24 -> 25); players slow delays under
// 2/100 s (above 50 frames/s), so GIFs above 50 play slower than asked.
constexpr int kDefaultFps = 10;
constexpr int kMinFps = 1;
constexpr int kMaxFps = 120;

// The rate `-fps text` asks for: a whole number from kMinFps to kMaxFps.
// Throws TclError {PVR ARGS FPS} naming the text and the range otherwise.
int fpsOf(const std::string& text);

// The words of the ffmpeg command that writes `target` (.gif or .mp4) from
// the PNGs matching `inputPattern` (printf %0Nd, ffmpeg's image-sequence
// pattern) from number `startNumber` on, at `fps` frames per second:
// "ffmpeg -y -loglevel error -framerate FPS -start_number N -i PATTERN -vf
// FILTER TARGET". MP4: H.264 in 4:2:0 with even sides (what every player
// takes); GIF: one palette made for these frames, the frame delays from FPS.
std::vector<std::string> ffmpegArguments(const std::string& target, const std::string& inputPattern,
                                         std::uint64_t startNumber, int fps);

}  // namespace pvr::tcl
