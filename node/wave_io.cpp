#include "wave_io.h"

#include <algorithm>
#include <cstring>

namespace pvr::node {

nlohmann::json cameraToJson(const core::CameraSpec& c) {
  return {{"perspective", c.projection == core::Projection::kPerspective},
          {"eye", {c.eye.x, c.eye.y, c.eye.z}},
          {"look_at", {c.lookAt.x, c.lookAt.y, c.lookAt.z}},
          {"up", {c.up.x, c.up.y, c.up.z}},
          {"height", c.height},
          {"fov_y_deg", c.fovYDeg}};
}

core::CameraSpec cameraFromJson(const nlohmann::json& j) {
  core::CameraSpec c;
  const auto vec = [&](const char* key) {
    const auto& a = j.at(key);
    return core::Vec3{a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>()};
  };
  c.projection = j.at("perspective").get<bool>() ? core::Projection::kPerspective : core::Projection::kOrthographic;
  c.eye = vec("eye");
  c.lookAt = vec("look_at");
  c.up = vec("up");
  c.height = j.at("height").get<double>();
  c.fovYDeg = j.at("fov_y_deg").get<double>();
  c.automatic = false;
  return c;
}

core::Image cropToRect(const core::Image& image, const core::PixelRect& rect) {
  const core::PixelRect r = image.rect().intersect(rect);
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

void sendSubImage(comm::Communicator& comm, int to, int tag, const SubImage& message, core::ImageCodec codec,
                  std::uint64_t* bytesSent) {
  comm::Bytes bytes = comm::encodeFailure(message.failure);
  if (!message.failure) {
    const core::EncodedImage encoded = core::encodeImage(message.image, codec);
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
