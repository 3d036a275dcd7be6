#include "numbered_file.h"

#include <climits>
#include <cstdio>

#include "tcl_util.h"

namespace pvr::tcl {

namespace {

// The most digits a frame number has (UINT64_MAX has 20).
constexpr int kMaxDigits = 20;

[[noreturn]] void refuse(const std::string& what) { throw TclError({"PVR", "ARGS", "FILE"}, what); }

// Refuses names the file system would cut or refuse: the last component
// over NAME_MAX, the whole over PATH_MAX (with the widest number).
NumberedFile checked(NumberedFile f, const std::string& given) {
  const std::string longest = f.prefix + std::string(std::size_t(std::max(f.width, kMaxDigits)), '0') + f.suffix;
  const auto slash = longest.rfind('/');
  const std::size_t leaf = longest.size() - (slash == std::string::npos ? 0 : slash + 1);
  if (longest.size() >= PATH_MAX)
    refuse("'" + given + "': frame file names would be " + std::to_string(longest.size()) +
           " characters, more than the " + std::to_string(PATH_MAX - 1) + " a path may have");
  if (leaf > NAME_MAX)
    refuse("'" + given + "': frame file names would be " + std::to_string(leaf) + " characters, more than the " +
           std::to_string(NAME_MAX) + " a file name may have");
  return f;
}

std::string doubledPercent(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

}  // namespace

std::string NumberedFile::name(std::uint64_t number) const {
  std::string digits = std::to_string(number);
  if (int(digits.size()) < width) digits.insert(0, std::size_t(width) - digits.size(), '0');
  return prefix + digits + suffix;
}

std::string NumberedFile::pattern() const {
  if (empty()) return "";
  return doubledPercent(prefix) + "%0" + std::to_string(width) + "d" + doubledPercent(suffix);
}

NumberedFile numberedFileOf(const std::string& file, std::string& animated) {
  animated.clear();
  const auto slash = file.rfind('/');
  const auto dot = file.rfind('.');
  const bool hasExt = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  const std::string ext = hasExt ? file.substr(dot) : "";
  const std::string stem = hasExt ? file.substr(0, dot) : file;
  if (ext == ".gif" || ext == ".mp4") {
    animated = file;
    return checked({stem + "_", 5, ".png"}, file);
  }
  // Frames are PNG: another extension would be written as NAME.avi.png.
  if (!ext.empty() && ext != ".png")
    refuse("image file: cannot write " + ext + " files; frames are .png, animations .gif or .mp4 (got '" + file + "')");
  // Only the file name may number: a directory's '%' is just a character.
  const std::size_t leaf = slash == std::string::npos ? 0 : slash + 1;
  const auto pct = file.find('%', leaf);
  if (pct == std::string::npos) return checked({stem + "_", 5, ".png"}, file);
  std::size_t end = pct + 1;
  while (end < file.size() && file[end] >= '0' && file[end] <= '9') ++end;
  if (end >= file.size() || file[end] != 'd' || file.find('%', end) != std::string::npos)
    refuse("image file: a pattern takes one %d or %0Nd, got '" + file + "'");
  const std::string digits = file.substr(pct + 1, end - pct - 1);
  if (digits.size() > 2 || (!digits.empty() && std::stoi(digits) > kMaxDigits))
    refuse("image file: '" + file + "': at most " + std::to_string(kMaxDigits) + " digits (%0" +
           std::to_string(kMaxDigits) + "d)");
  return checked({file.substr(0, pct), digits.empty() ? 1 : std::stoi(digits), file.substr(end + 1)}, file);
}

NumberedFile numberedInDirectory(const std::string& dir, const std::string& sessionName) {
  std::string base = sessionName;
  if (!base.empty() && base[0] == ':') base.erase(0, 1);
  return checked({dir + "/" + base + "_", 5, ".png"}, dir);
}

}  // namespace pvr::tcl
