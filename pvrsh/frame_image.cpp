#include "frame_image.h"

#include <tk.h>
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>

#include "tcl_util.h"

namespace pvr::tcl {
namespace {

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(std::uint8_t(v >> shift));
}

// One PNG chunk: length, type, data, CRC over type and data.
void putChunk(std::vector<std::uint8_t>& out, const char type[4], const std::vector<std::uint8_t>& data) {
  putU32(out, std::uint32_t(data.size()));
  const std::size_t crcStart = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  putU32(out, std::uint32_t(crc32(0, out.data() + crcStart, uInt(out.size() - crcStart))));
}

}  // namespace

Pixels decodePixels(const proto::ImageFrame& frame) {
  auto decoded = proto::decompressPixels(frame);
  if (auto* error = std::get_if<proto::ProtocolError>(&decoded))
    throw TclError({"PVR", "PROTOCOL", std::string(proto::errorCodeName(error->code))}, "bad image frame: " + error->text);
  Pixels p;
  p.width = int(frame.width);
  p.height = int(frame.height);
  p.channels = int(proto::channelCount(frame.format));
  p.bytes = std::move(std::get<std::vector<std::uint8_t>>(decoded));
  return p;
}

void writePng(const Pixels& pixels, const std::string& path) {
  // Raw scanlines, each led by filter byte 0 (None).
  const std::size_t row = std::size_t(pixels.width) * std::size_t(pixels.channels);
  std::vector<std::uint8_t> raw;
  raw.reserve((row + 1) * std::size_t(pixels.height));
  for (int y = 0; y < pixels.height; ++y) {
    raw.push_back(0);
    const auto* src = pixels.bytes.data() + row * std::size_t(y);
    raw.insert(raw.end(), src, src + row);
  }
  uLongf zsize = compressBound(uLong(raw.size()));
  std::vector<std::uint8_t> idat(zsize);
  if (compress2(idat.data(), &zsize, raw.data(), uLong(raw.size()), 1) != Z_OK)
    throw TclError({"PVR", "IO"}, "cannot compress PNG data for " + path);
  idat.resize(zsize);

  std::vector<std::uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<std::uint8_t> ihdr;
  putU32(ihdr, std::uint32_t(pixels.width));
  putU32(ihdr, std::uint32_t(pixels.height));
  // Bit depth 8; colour type 6 (RGBA) or 2 (RGB); deflate; filter 0; no interlace.
  ihdr.insert(ihdr.end(), {8, std::uint8_t(pixels.channels == 4 ? 6 : 2), 0, 0, 0});
  putChunk(png, "IHDR", ihdr);
  putChunk(png, "sRGB", {0});  // perceptual rendering intent: the bytes are sRGB
  putChunk(png, "IDAT", idat);
  putChunk(png, "IEND", {});

  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "wb"), std::fclose);
  if (!f) throw TclError({"PVR", "IO"}, "cannot write " + path + ": " + std::strerror(errno));
  if (std::fwrite(png.data(), 1, png.size(), f.get()) != png.size())
    throw TclError({"PVR", "IO"}, "cannot write " + path + ": " + std::strerror(errno));
  if (std::fclose(f.release()) != 0) throw TclError({"PVR", "IO"}, "cannot write " + path + ": " + std::strerror(errno));
}

bool tkAvailable(Tcl_Interp* interp) {
  if (!Tcl_PkgPresent(interp, "Tk", "8.6", 0)) {
    Tcl_ResetResult(interp);
    return false;
  }
  // Tk loaded after this package: its stubs table is fetched on first use.
  if (!tkStubsPtr && !Tk_InitStubs(interp, "8.6", 0)) {
    Tcl_ResetResult(interp);
    return false;
  }
  return true;
}

Pixels zoomPixels(const Pixels& pixels, int zoom, int width, int height) {
  Pixels out;
  out.width = width;
  out.height = height;
  out.channels = pixels.channels;
  const std::size_t c = std::size_t(pixels.channels);
  out.bytes.resize(std::size_t(width) * std::size_t(height) * c);
  std::uint8_t* o = out.bytes.data();
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* row = pixels.bytes.data() + std::size_t(std::min(y / zoom, pixels.height - 1)) * std::size_t(pixels.width) * c;
    for (int x = 0; x < width; ++x, o += c) std::memcpy(o, row + std::size_t(std::min(x / zoom, pixels.width - 1)) * c, c);
  }
  return out;
}

void putPhoto(Tcl_Interp* interp, const std::string& photo, const Pixels& pixels) {
  putPhoto(interp, photo, pixels, 1, pixels.width, pixels.height);
}

void putPhoto(Tcl_Interp* interp, const std::string& photo, const Pixels& pixels, int zoom, int width, int height) {
  if (!tkAvailable(interp))
    throw TclError({"PVR", "IMAGE", "NOTK"}, "image window needs Tk: package require Tk first (or run pvrsh with a display)");
  Tk_PhotoHandle handle = Tk_FindPhoto(interp, photo.c_str());
  if (!handle) throw TclError({"PVR", "IMAGE", "NOPHOTO"}, "image \"" + photo + "\" is not a photo image");
  Tk_PhotoImageBlock block{};
  block.pixelPtr = const_cast<unsigned char*>(pixels.bytes.data());
  block.width = pixels.width;
  block.height = pixels.height;
  block.pixelSize = pixels.channels;
  block.pitch = pixels.width * pixels.channels;
  block.offset[0] = 0;
  block.offset[1] = 1;
  block.offset[2] = 2;
  block.offset[3] = pixels.channels == 4 ? 3 : 0;
  const auto put = [&] {
    return zoom == 1 ? Tk_PhotoPutBlock(interp, handle, &block, 0, 0, width, height, TK_PHOTO_COMPOSITE_SET)
                     : Tk_PhotoPutZoomedBlock(interp, handle, &block, 0, 0, width, height, zoom, zoom, 1, 1,
                                              TK_PHOTO_COMPOSITE_SET);
  };
  if (Tk_PhotoSetSize(interp, handle, width, height) != TCL_OK || put() != TCL_OK)
    throw TclError({"PVR", "IMAGE", "PHOTO"}, std::string("cannot put the frame into ") + photo + ": " +
                                                 Tcl_GetStringResult(interp));
}

}  // namespace pvr::tcl
