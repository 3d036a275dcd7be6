// The pixel compression of an ImageFrame: encoder and decoder side by side.
//
// Uncompressed ("raw") pixels are width * height * channels bytes, rows top
// to bottom, pixels left to right, channels interleaved (RGB8: 3, RGBA8: 4).
// The compressions (docs/protocol.md, "ImageFrame pixels"):
//   kNone  the raw bytes.
//   kRle   runs of identical whole pixels, in raw order and across row ends:
//          each run is one count byte c, meaning c + 1 pixels (1..256),
//          followed by that pixel's channels. Suits the flat background of
//          volume images.
//   kZlib  an RFC 1950 zlib stream of the raw bytes.
// A sender falls back to kNone when compressing does not make the pixels
// fewer (setPixels does), so a frame is never larger than its raw pixels plus
// the fixed fields, which is what checkImageSize (image_limits.h) counts on.
#pragma once

#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "frame_header.h"
#include "protocol_error.h"
#include "protocol_messages.h"

namespace pvr::proto {

// `raw` compressed with exactly `compression`. Throws std::invalid_argument
// when raw.size() is not a whole number of pixels.
std::vector<std::uint8_t> compressPixels(std::span<const std::uint8_t> raw, PixelFormat format,
                                         Compression compression);

// What the collector puts in a frame: sets frame.pixels and
// frame.compression from `raw`, compressed with `wanted` when that makes the
// pixels fewer, else uncompressed with kNone. frame.width, height and format
// must describe `raw` (std::invalid_argument otherwise).
void setPixels(ImageFrame& frame, std::span<const std::uint8_t> raw, Compression wanted);

// The raw pixels of `frame` (width * height * channels bytes), or an error
// naming what is wrong: the frame's own check (ImageFrame::checkHead, so the
// output size is within `limits` before anything is allocated), then an RLE
// stream cut inside a run or whose runs cover more or fewer pixels than the
// image, a zlib stream that is damaged, inflates to more or fewer bytes than
// the image, or has bytes after its end. Errors are kMalformedPayload
// (kLimitExceeded for a size over the limits).
std::variant<std::vector<std::uint8_t>, ProtocolError> decompressPixels(const ImageFrame& frame,
                                                                    const Limits& limits = {});

}  // namespace pvr::proto
