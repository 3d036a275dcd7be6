#include "wave_io.h"

#include <algorithm>

namespace pvr::node {

CameraArgs cameraArgs(const core::CameraSpec& c) {
  return {c.projection == core::Projection::kPerspective,
          {c.eye.x, c.eye.y, c.eye.z},
          {c.lookAt.x, c.lookAt.y, c.lookAt.z},
          {c.up.x, c.up.y, c.up.z},
          c.height,
          c.fovYDeg};
}

core::CameraSpec cameraSpec(const CameraArgs& a) {
  core::CameraSpec c;
  c.projection = a.perspective ? core::Projection::kPerspective : core::Projection::kOrthographic;
  c.eye = {a.eye[0], a.eye[1], a.eye[2]};
  c.lookAt = {a.lookAt[0], a.lookAt[1], a.lookAt[2]};
  c.up = {a.up[0], a.up[1], a.up[2]};
  c.height = a.height;
  c.fovYDeg = a.fovYDeg;
  c.automatic = false;
  return c;
}

core::Image cropToRect(core::Image image, const core::PixelRect& rect) {
  const core::PixelRect r = image.rect().intersect(rect);
  if (r == image.rect()) return image;
  core::Image out(image.frameWidth(), image.frameHeight(), r);
  for (int y = r.y0; y < r.y1; ++y)
    std::copy(&image.at(r.x0, y), &image.at(r.x0, y) + r.width(), out.row(y));
  return out;
}

void blendOver(core::Image& acc, const core::Image& back) {
  if (back.rect().empty()) return;
  if (acc.frameWidth() == 0) {
    acc = back;
    return;
  }
  if (acc.rect().intersect(back.rect()) != back.rect()) {
    core::Image grown(acc.frameWidth(), acc.frameHeight(), acc.rect().empty() ? back.rect() : acc.rect().unite(back.rect()));
    paste(grown, acc);
    acc = std::move(grown);
  }
  core::compositeUnder(acc, back);
}

void paste(core::Image& frame, const core::Image& part) {
  const core::PixelRect r = part.rect().intersect(frame.rect());
  for (int y = r.y0; y < r.y1; ++y) std::copy(&part.at(r.x0, y), &part.at(r.x0, y) + r.width(), &frame.at(r.x0, y));
}

void sendSubImage(comm::Communicator& comm, int to, int tag, const SubImage& message, std::uint64_t* bytesSent) {
  comm::Bytes bytes = comm::encodeFailure(message.failure);
  if (!message.failure) {
    const core::EncodedImage encoded = core::encodeImage(message.image, kSubImageCodec);
    bytes.insert(bytes.end(), encoded.bytes.begin(), encoded.bytes.end());
  }
  if (bytesSent) *bytesSent += bytes.size();
  comm.send(to, tag, bytes);
}

SubImage receiveSubImage(comm::Communicator& comm, int from, int tag, std::uint64_t* bytesReceived) {
  const comm::Bytes bytes = comm.receive(from, tag);
  if (bytesReceived) *bytesReceived += bytes.size();
  SubImage out;
  out.failure = comm::decodeFailure(bytes);
  if (!out.failure) out.image = core::decodeImage(std::span(bytes).subspan(1));
  return out;
}

}  // namespace pvr::node
