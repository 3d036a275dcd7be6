// Frames as they arrive: pixel decoding, PNG files, Tk photo images.
#pragma once

#include <tcl.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::tcl {

// A decoded frame: rows top to bottom, 8-bit sRGB, `channels` 3 (RGB) or 4
// (RGBA, straight alpha).
struct Pixels {
  int width = 0;
  int height = 0;
  int channels = 4;
  std::vector<std::uint8_t> bytes;
};

// The pixels of an ImageFrame, decoded by the protocol's pixel codec
// (proto::decompressPixels: none, RLE or zlib, into exactly width * height *
// channels bytes). A frame it refuses throws TclError {PVR PROTOCOL <code>}
// with the codec's text (MALFORMED_PAYLOAD for damaged pixels).
Pixels decodePixels(const proto::ImageFrame& frame);

// Writes `pixels` as an 8-bit PNG (colour type 2 or 6, no filtering, zlib
// level 1). Throws TclError {PVR IO} when the file cannot be written.
void writePng(const Pixels& pixels, const std::string& path);

// `pixels` zoomed by `zoom` (each pixel a zoom x zoom block, as Tk's
// `copy -zoom` does) and cut to width x height: an interactive render's
// coarse frame at the image size (docs/pvrsh.md).
Pixels zoomPixels(const Pixels& pixels, int zoom, int width, int height);

// Puts `pixels` into the Tk photo image `photo`, resizing it to the frame;
// with `zoom` > 1, zoomed and cut to width x height as zoomPixels does
// (Tk zooms it into the photo, with no copy of the pixels).
// Throws TclError {PVR IMAGE NOTK} when Tk is not loaded in `interp` and
// {PVR IMAGE NOPHOTO} when no photo image has that name.
void putPhoto(Tcl_Interp* interp, const std::string& photo, const Pixels& pixels);
void putPhoto(Tcl_Interp* interp, const std::string& photo, const Pixels& pixels, int zoom, int width, int height);

// True when Tk is loaded in `interp` and its stubs are ready for putPhoto.
bool tkAvailable(Tcl_Interp* interp);

}  // namespace pvr::tcl
