// libFuzzer target for the protocol decoder, relay and pixel codec.
//
// For any input: decodeFrame, applied frame after frame, and FrameDecoder,
// fed the same bytes in chunks whose sizes the input determines, must agree
// (same messages, same error code); every decoded message must re-encode to
// exactly the bytes it came from; FrameDecoder must never hold more than one
// frame. FrameRelay, fed the same chunks, must pass on exactly the frames
// the decoder accepts, byte for byte, and refuse the frame the decoder
// stops at with the same error code. Every decoded ImageFrame's pixels either
// decompress to width * height * channels bytes that setPixels compresses
// back to pixels decoding to the same bytes, or fail with an error text.
// Any disagreement aborts, which libFuzzer reports as a crash; the
// sanitizers report the rest.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <vector>

#include "pvr_protocol.h"

namespace {

using namespace pvr::proto;

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "protocol fuzz: %s\n", what);
    std::abort();
  }
}

// splitmix64: chunk sizes that depend on the input, so the fuzzer explores
// the splits too.
std::uint64_t nextRandom(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

struct WholeResult {
  std::vector<std::vector<std::uint8_t>> frames;  // each decoded frame, re-encoded
  std::optional<ProtocolError> error;
  std::size_t unfinishedBytes = 0;  // bytes of a frame still waiting for more
};

// The pixel codec on a decoded frame: decompression fails cleanly or
// round-trips through the encoder.
void checkPixels(const ImageFrame& frame, const Limits& limits) {
  auto raw = decompressPixels(frame, limits);
  if (auto* error = std::get_if<ProtocolError>(&raw)) {
    require(!error->text.empty(), "a pixel error without text");
    return;
  }
  const auto& pixels = std::get<std::vector<std::uint8_t>>(raw);
  require(pixels.size() == std::size_t{frame.width} * frame.height * channelCount(frame.format),
          "decompressed pixels of the wrong size");
  ImageFrame again = frame;
  setPixels(again, pixels, frame.compression);
  require(again.pixels.size() <= pixels.size(), "setPixels made the pixels larger");
  auto back = decompressPixels(again, limits);
  require(std::holds_alternative<std::vector<std::uint8_t>>(back) &&
              std::get<std::vector<std::uint8_t>>(back) == pixels,
          "pixels do not survive compress and decompress");
}

WholeResult decodeWhole(std::span<const std::uint8_t> input, const Limits& limits) {
  WholeResult whole;
  while (!input.empty()) {
    DecodeResult result = decodeFrame(input, limits);
    if (auto* decoded = std::get_if<Decoded>(&result)) {
      require(decoded->bytesConsumed >= kHeaderBytes && decoded->bytesConsumed <= input.size(),
              "bytesConsumed out of range");
      auto again = encode(decoded->message, decoded->info.requestId, decoded->info.flags);
      const auto original = input.first(decoded->bytesConsumed);
      require(again.size() == original.size() && std::equal(again.begin(), again.end(), original.begin()),
              "a decoded message does not re-encode to its bytes");
      whole.frames.push_back(std::move(again));
      if (const auto* image = std::get_if<ImageFrame>(&decoded->message)) checkPixels(*image, limits);
      input = input.subspan(decoded->bytesConsumed);
    } else if (auto* error = std::get_if<ProtocolError>(&result)) {
      require(!error->text.empty(), "an error without text");
      whole.error = std::move(*error);
      return whole;
    } else {
      require(std::get<NeedMore>(result).frameBytes > input.size(), "NeedMore with the frame present");
      require(std::get<NeedMore>(result).frameBytes <= limits.maxFrameBytes, "NeedMore past the frame limit");
      whole.unfinishedBytes = input.size();
      return whole;
    }
  }
  return whole;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  Limits limits;
  // Small image limits half of the time, so the pixel checks fire too.
  if (size > 0 && (data[size - 1] & 1) != 0) limits.maxImagePixels = 64;

  const WholeResult whole = decodeWhole(input, limits);

  // The same bytes in chunks of 1..64 bytes, or occasionally 1..4096.
  std::uint64_t seed = size;
  for (std::size_t i = 0; i < size && i < 8; ++i) seed = seed * 131 + data[i];
  FrameDecoder decoder(limits);
  FrameRelay relay(limits);
  std::size_t at = 0;
  std::size_t popped = 0;
  std::size_t relayed = 0;
  std::optional<ProtocolError> firstRefusal;
  while (at < size) {
    const std::uint64_t r = nextRandom(seed);
    const std::size_t chunk = 1 + static_cast<std::size_t>((r & 0xF) == 0 ? (r >> 8) % 4096 : (r >> 8) % 64);
    const std::size_t n = std::min(chunk, size - at);
    decoder.feed(input.subspan(at, n));
    relay.feed(input.subspan(at, n));
    at += n;
    require(decoder.bufferedBytes() <= limits.maxFrameBytes, "decoder holds more than one frame");
    require(relay.bufferedBytes() <= limits.maxFrameBytes, "relay holds more than one frame");
    while (auto frame = decoder.pop()) {
      require(popped < whole.frames.size(), "the decoder produced an extra message");
      const auto again = encode(frame->message, frame->info.requestId, frame->info.flags);
      require(again == whole.frames[popped], "chunked and whole decoding disagree on a message");
      ++popped;
    }
    // Up to the decoder's first error the relay passes on the same frames;
    // after a refusal it may go on where the decoder stops.
    while (auto item = relay.pop()) {
      if (firstRefusal) continue;
      if (auto* refused = std::get_if<RefusedFrame>(&*item)) {
        firstRefusal = refused->error;
        continue;
      }
      const auto& frame = std::get<RelayedFrame>(*item);
      require(relayed < whole.frames.size(), "the relay passed a frame the decoder refuses");
      require(frame.bytes == whole.frames[relayed], "the relay changed a frame's bytes");
      ++relayed;
    }
  }
  require(popped == whole.frames.size(), "the decoder lost a message");
  const auto& relayError = relay.endOfStream();
  if (!firstRefusal) {
    require(relayed == whole.frames.size(), "the relay lost a frame");
  }
  if (whole.error) {
    const ProtocolError& refusal = firstRefusal ? *firstRefusal : relayError.value_or(ProtocolError{});
    // Codes only: a wrong magic's text shows the bytes seen so far, which
    // depend on the chunking.
    require(refusal.code == whole.error->code, "the relay and the decoder disagree on the first error");
  }

  const auto& error = decoder.endOfStream();
  if (whole.error) {
    require(error.has_value() && error->code == whole.error->code, "chunked and whole decoding disagree on the error");
  } else if (whole.unfinishedBytes > 0) {
    require(error.has_value() && error->code == ErrorCode::kTruncatedFrame, "a truncated frame was not reported");
  } else {
    require(!error.has_value(), "an error on a clean stream");
  }
  return 0;
}
