// TclError: the error a pvrsh command raises, as a message and the
// -errorcode list (e.g. {PVR ARGS IMAGESZ}). It holds no Tcl type, so the
// Tcl-free parts of pvrsh (reply_book.h, and the fuzzer that compiles it)
// throw and keep it too; tcl_util.h turns it into an interpreter's result.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace pvr::tcl {

class TclError : public std::runtime_error {
 public:
  TclError(std::vector<std::string> code, const std::string& message)
      : std::runtime_error(message), code_(std::move(code)) {}
  const std::vector<std::string>& code() const { return code_; }

 private:
  std::vector<std::string> code_;
};

}  // namespace pvr::tcl
