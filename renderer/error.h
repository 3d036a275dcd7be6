// pvr::Error — the one exception type for setup-time user errors.
//
// Thrown when a file, option or scene is wrong; never inside per-ray loops.
// The code is stable (the wire protocol carries it); the message names what
// was wrong and where ("ct.nrrd: sizes line has 2 numbers, need 3").
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace pvr {

enum class ErrorCode : std::uint16_t {
  kInvalidArgument = 1,  // an option, key or value the caller gave is wrong
  kBadFile = 2,          // a file exists but its content is wrong
  kIo = 3,               // a file could not be opened, read or written
  kUnsupported = 4,      // a valid request this build cannot serve
  kInternal = 5,         // a broken invariant; a bug
  kRemote = 6,           // an error raised on another rank or process
  kCancelled = 7,        // the work was stopped on request (a client's Cancel)
};

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

}  // namespace pvr
