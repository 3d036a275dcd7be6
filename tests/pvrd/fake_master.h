// A stand-in for the MPI job in the daemon process tests: pvrd runs it as
// its --mpirun, it connects back to the session handler like the master
// rank (JobHello with PVR_JOB_SECRET first) and answers requests with
// frames the test chooses, including frames pvrd must refuse. The scene
// JSON of a SetScene names what the next RenderFrame gets (kScript*).
//
// Before that it can try connect-backs pvrd must refuse, listed in the
// environment variable kTrialsVariable (pvrd passes its environment on),
// comma-separated, in order: kTrialWrongSecret, kTrialNoSecret,
// kTrialWrongJobHello, kTrialOtherFrame each wait until the handler closes
// them (the fake master gives up with exit status 3 after 30 s); a
// kTrialSilent connection stays open, saying nothing, while the others go
// on. Like the real master, it talks inside the secure channel keyed by
// PVR_JOB_SECRET (docs/protocol.md, "The secure channel"). Unlike the real
// master it sends no Heartbeat: a test with it must end within pvrd's
// --stall-timeout (30 s by default).
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

inline constexpr const char* kTrialsVariable = "PVR_FAKE_MASTER_TRIALS";
// The secure channel keyed by a secret that is not the session's.
inline constexpr std::string_view kTrialWrongSecret = "wrong";
// No secure channel: a plain JobHello with an empty secret.
inline constexpr std::string_view kTrialNoSecret = "none";
// The right channel, then a JobHello with a wrong secret inside it.
inline constexpr std::string_view kTrialWrongJobHello = "wronghello";
// The right channel, then a first frame other than JobHello.
inline constexpr std::string_view kTrialOtherFrame = "other";
// Connected, nothing sent.
inline constexpr std::string_view kTrialSilent = "silent";
// The wrong secret kTrialWrongSecret and kTrialWrongJobHello use, with
// bytes the log must mask.
inline constexpr std::string_view kWrongSecret = "\x01wrong\x7f";

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
