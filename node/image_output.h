// Writing a frame to an image file from pvr-node (--batch -o OUT.exr|OUT.png).
//
// OpenImageIO and the libraries it pulls in cost every process that links
// them ~130 MB of resident memory before any data is read, which would put
// a rank of a large volume well over its brick's size. pvr-node therefore
// does not link it: the one rank that writes loads the image writer module
// (renderer/image_writer_module.cpp) at that moment, after its brick is gone.
#pragma once

#include <array>
#include <string>

#include "image.h"

namespace pvr::node {

// Throws pvr::Error naming the path (or the module when it cannot be loaded).
// The module is PVR_IMAGE_WRITER from the environment when set, else the one
// built beside pvr-node.
void writeImageFile(const core::Image& image, const std::array<double, 4>& background, const std::string& path);

}  // namespace pvr::node
