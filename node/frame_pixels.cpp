#include "frame_pixels.h"

#include <cstring>

#include "error.h"
#include "image_srgb.h"

namespace pvr::node {

std::vector<std::uint8_t> srgbPixels(const core::Image& frame, const std::array<double, 4>& background,
                                     proto::PixelFormat format) {
  std::vector<std::uint8_t> raw = core::toSrgbRgba8(frame, background);
  if (proto::channelCount(format) == 3) {
    // Drop alpha in place: pixel i moves from byte 4i to byte 3i.
    for (std::size_t i = 0, n = raw.size() / 4; i < n; ++i) std::memmove(&raw[i * 3], &raw[i * 4], 3);
    raw.resize(raw.size() / 4 * 3);
  }
  return raw;
}

void setFramePixels(proto::ImageFrame& out, const core::Image& frame, const std::array<double, 4>& background,
                    proto::Compression wanted) {
  proto::setPixels(out, srgbPixels(frame, background, out.format), wanted);
}

}  // namespace pvr::node
