// The largest image a session may ask for, decided once: the node checks a
// scene's image size against it when the scene is set, pvrsh when the user
// types -imagesz, and pvrd and every decoder through ImageFrame::check. A
// frame the collector sends is never larger than its uncompressed pixels
// plus the fixed fields (the collector falls back to Compression::kNone
// when compressing does not pay), so an image that passes here always fits
// in one ImageFrame.
#pragma once

#include <cstdint>
#include <optional>

#include "frame_header.h"
#include "protocol_error.h"
#include "protocol_messages.h"

namespace pvr::proto {

// Payload bytes of an ImageFrame of width x height uncompressed pixels.
std::uint64_t imageFramePayloadBytes(std::uint64_t width, std::uint64_t height, PixelFormat format);

// nullopt when a width x height image in `format` fits the limits; else a
// kLimitExceeded (or kBadArgument for an empty image) error naming the limit.
std::optional<ProtocolError> checkImageSize(std::uint64_t width, std::uint64_t height, PixelFormat format,
                                            const Limits& limits = {});

}  // namespace pvr::proto
