#include "image_output.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>

#include "error.h"

namespace pvr::node {

namespace {

using WriteImage = int (*)(const core::Image*, const double*, const char*, char*, std::size_t);

// The module: $PVR_IMAGE_WRITER; else an installed one, PREFIX/lib/pvr
// beside PREFIX/bin/pvr-node (cmake --install puts it there); else the
// build tree's.
std::string writerModule() {
  const char* env = std::getenv("PVR_IMAGE_WRITER");
  if (env && *env) return env;
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path().parent_path() / "lib" / "pvr" / PVR_IMAGE_WRITER_NAME;
    if (std::filesystem::is_regular_file(installed, ec)) return installed.string();
  }
  return PVR_IMAGE_WRITER_MODULE;
}

WriteImage loadWriter() {
  const std::string module = writerModule();
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
