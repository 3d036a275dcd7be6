// Numbered frame files: the name of frame N of `image file` and `image dir`.
//
// The user's text is data, never a printf format: a session named "%s" or
// a directory holding "%n" once made pvrsh pass them to snprintf (a crash),
// and an over-long directory silently truncated every frame to one name.
#pragma once

#include <cstdint>
#include <string>

namespace pvr::tcl {

struct NumberedFile {
  std::string prefix;  // text before the number
  int width = 5;       // digits, zero-padded
  std::string suffix;  // text after it

  bool empty() const { return prefix.empty() && suffix.empty(); }
  // Frame `number`'s file name.
  std::string name(std::uint64_t number) const;
  // As `image file` shows it: the number as printf's %0Nd (a '%' of the
  // text doubled), which is also ffmpeg's image-sequence input pattern;
  // "" when empty.
  std::string pattern() const;
};

// The files of `image file FILE`: FILE whose file name has one %d or %0Nd
// (N up to 20) numbers the frames (a '%' in its directory is a
// character); otherwise _00000 goes before the extension (".png" added
// when FILE has none). FILE ending in .gif or .mp4 names an animated file,
// returned in `animated`: the PNGs go beside it. Throws TclError
// {PVR ARGS FILE} for another extension (frames are PNG), a second '%' or
// a bad width, and when the longest name (20 digits) would exceed what the
// file system takes (a component over NAME_MAX or a path over PATH_MAX),
// rather than truncate.
NumberedFile numberedFileOf(const std::string& file, std::string& animated);

// The files of `image dir DIR` for the session NAME: DIR/NAME_00000.png,
// ... (NAME without its leading ':'). Throws as numberedFileOf does when
// the names would not fit.
NumberedFile numberedInDirectory(const std::string& dir, const std::string& sessionName);

}  // namespace pvr::tcl
