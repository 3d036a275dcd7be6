#include "coarse_frame.h"

#include <algorithm>

namespace pvr::node {

int reducedSize(int size, int reduction) { return std::max(1, (size + reduction - 1) / reduction); }

ReducedImage::ReducedImage(core::ImageSpec& image, int reduction) : image_(image), full_(image) {
  image_.width = reducedSize(full_.width, reduction);
  image_.height = reducedSize(full_.height, reduction);
}

}  // namespace pvr::node
