#include "image_output.h"

#include <dlfcn.h>

#include <cstdlib>

#include "error.h"

namespace pvr::node {

namespace {

using WriteImage = int (*)(const core::Image*, const double*, const char*, char*, std::size_t);

WriteImage loadWriter() {
  const char* env = std::getenv("PVR_IMAGE_WRITER");
  const std::string module = env && *env ? env : PVR_IMAGE_WRITER_MODULE;
  // Loaded once, kept for the life of the process.
  void* handle = ::dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw Error(ErrorCode::kIo, "cannot load the image writer " + module + ": " + ::dlerror());
  auto* write = reinterpret_cast<WriteImage>(::dlsym(handle, "pvr_write_image"));
  if (!write) throw Error(ErrorCode::kIo, "the image writer " + module + " has no pvr_write_image");
  return write;
}

}  // namespace

void writeImageFile(const core::Image& image, const std::array<double, 4>& background, const std::string& path) {
  static const WriteImage write = loadWriter();
  char error[1024] = "";
  if (write(&image, background.data(), path.c_str(), error, sizeof error) != 0) throw Error(ErrorCode::kIo, error);
}

}  // namespace pvr::node
