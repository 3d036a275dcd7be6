// What the wave action's steps share: its frames as action arguments carry
// them, images cut to scanline bands and blended, and sub-images sent
// between ranks with a status byte so that a receiver always gets a
// message, failure or image.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <tuple>

#include "camera.h"
#include "communicator.h"
#include "image.h"
#include "image_codec.h"

namespace pvr::node {

// Tags of the node's own messages on the world communicator; the
// strategies use small tags on cluster communicators, the default
// collectives tags from comm::kFirstReservedTag up.
constexpr int kPartialTag = 25001;  // render rank -> composite cluster
constexpr int kTreeTag = 25002;     // composite rank -> composite rank
constexpr int kBandTag = 25003;     // finished band -> collector
constexpr int kPingTag = 25004;     // calibration
constexpr int kOrderTag = 25005;    // render cluster root -> composite cluster: visibility order
constexpr int kStepTag = 25006;     // cache rank -> render rank: a time step's brick (cache_cluster.h)

// Sub-images between ranks: the smaller of the sparse codes, per image.
constexpr core::ImageCodec kSubImageCodec = core::ImageCodec::kAuto;

// A camera in a form the field codec carries (protocol/field_codec.h).
struct CameraArgs {
  bool perspective = true;
  std::array<double, 3> eye{}, lookAt{}, up{0, 0, 1};
  double height = 0, fovYDeg = 30;
  static auto fields(auto& self) {
    return std::tie(self.perspective, self.eye, self.lookAt, self.up, self.height, self.fovYDeg);
  }
};
CameraArgs cameraArgs(const core::CameraSpec& camera);
core::CameraSpec cameraSpec(const CameraArgs& camera);  // never automatic

// One frame of a wave: its number in the request, its camera and the time
// step it shows.
struct FrameView {
  std::uint32_t number = 0;
  CameraArgs camera;
  std::int32_t timestep = 0;
  static auto fields(auto& self) { return std::tie(self.number, self.camera, self.timestep); }
};

// The part of `image` inside `rect` (an image whose rect is the
// intersection): `image` itself, moved, when it lies inside `rect` already,
// so that the collector holds a frame once (issue 11: nothing kept twice).
core::Image cropToRect(core::Image image, const core::PixelRect& rect);
// acc = acc over back; acc grows to cover back's rect.
void blendOver(core::Image& acc, const core::Image& back);
// `part` written into `frame` (a full-frame image) at its rect.
void paste(core::Image& frame, const core::Image& part);

// An image or a failure, as one message.
struct SubImage {
  std::optional<comm::Failure> failure;
  core::Image image;
};
// Sends `message` (its image in kSubImageCodec); adds the bytes sent to *bytesSent.
void sendSubImage(comm::Communicator& comm, int to, int tag, const SubImage& message,
                  std::uint64_t* bytesSent = nullptr);
SubImage receiveSubImage(comm::Communicator& comm, int from, int tag, std::uint64_t* bytesReceived = nullptr);

}  // namespace pvr::node
