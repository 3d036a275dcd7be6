// Helpers the frame actions share: cameras as action arguments, images cut
// to scanline bands and blended, and sub-images sent between ranks with a
// status byte so that a receiver always gets a message, failure or image.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "camera.h"
#include "communicator.h"
#include "image.h"
#include "image_codec.h"
#include "scene.h"

namespace pvr::node {

// Tags of the runtime's own messages on the world communicator; the
// strategies use small tags on cluster communicators, the default
// collectives tags from comm::kFirstReservedTag up.
constexpr int kPartialTag = 25001;  // render rank -> composite cluster
constexpr int kTreeTag = 25002;     // composite rank -> composite rank
constexpr int kBandTag = 25003;     // finished band -> collector
constexpr int kPingTag = 25004;     // calibration
constexpr int kOrderTag = 25005;    // render cluster root -> composite cluster: visibility order

nlohmann::json cameraToJson(const core::CameraSpec& camera);
core::CameraSpec cameraFromJson(const nlohmann::json& j);

// The part of `image` inside `rect` (an image whose rect is the intersection).
core::Image cropToRect(const core::Image& image, const core::PixelRect& rect);
// acc = acc over back; acc grows to cover back's rect.
void blendOver(core::Image& acc, const core::Image& back);
// `part` written into `frame` (a full-frame image) at its rect.
void paste(core::Image& frame, const core::Image& part);

// An image or a failure, as one message.
struct SubImage {
  std::optional<comm::Failure> failure;
  core::Image image;
};
void sendSubImage(comm::Communicator& comm, int to, int tag, const SubImage& message, core::ImageCodec codec,
                  std::uint64_t* bytesSent = nullptr);
SubImage receiveSubImage(comm::Communicator& comm, int from, int tag, std::uint64_t* bytesReceived = nullptr);

}  // namespace pvr::node
