// The module pvr-node loads to write an image file (node/image_output.cpp):
// writeImage behind a C entry point, so nothing but plain data and an error
// text crosses the dlopen boundary.
#include <cstddef>
#include <cstring>
#include <exception>

#include "image_io.h"

extern "C" int pvr_write_image(const pvr::core::Image* image, const double background[4], const char* path,
                               char* error, std::size_t errorBytes) {
  try {
    pvr::core::writeImage(*image, {background[0], background[1], background[2], background[3]}, path);
    return 0;
  } catch (const std::exception& e) {
    if (errorBytes > 0) {
      std::strncpy(error, e.what(), errorBytes - 1);
      error[errorBytes - 1] = '\0';
    }
    return 1;
  }
}
