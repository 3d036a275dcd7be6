// A stand-in for the MPI job in the daemon process tests: pvrd runs it as
// its --mpirun, it connects back to the session handler like the master
// rank and answers requests with frames the test chooses, including frames
// pvrd must refuse. The scene JSON of a SetScene names what the next
// RenderFrame gets (kScript*).
#pragma once

#include <cstdint>
#include <string_view>

#include "pvr_protocol.h"

namespace pvr::daemon::testing {

// A valid ImageFrame, FINAL (the default).
inline constexpr std::string_view kScriptGood = "good";
// An ImageFrame header one byte over the frame limit and that many payload
// bytes, then the good frame for the same request, FINAL.
inline constexpr std::string_view kScriptOversize = "oversize";
// An uncompressed ImageFrame, FINAL, one pixel byte short.
inline constexpr std::string_view kScriptInconsistent = "inconsistent";
// Bytes that are no frame: the stream cannot go on.
inline constexpr std::string_view kScriptGarbage = "garbage";

// The good frame: a 64 x 48 RGBA gradient, zlib-compressed by the codec.
inline proto::ImageFrame fakeGoodFrame() {
  proto::ImageFrame frame;
  frame.width = 64;
  frame.height = 48;
  frame.format = proto::PixelFormat::kRgba8;
  frame.timing = {0.5, 0.25, 0.125, 0.0625, 0.03125};
  std::vector<std::uint8_t> raw(64 * 48 * 4);
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = std::uint8_t(i / 256);
  proto::setPixels(frame, raw, proto::Compression::kZlib);
  return frame;
}

}  // namespace pvr::daemon::testing
