// The shared token of pvrd and its clients, read from a file: the one
// reader both sides use (pvrd --token-file, pvrsh's open -token-file).
#pragma once

#include <string>
#include <variant>

namespace pvr::proto {

// What is wrong with a token file, in words for the user.
struct TokenFileError {
  std::string text;
};

// The token in `path`, trailing whitespace removed. Refused: a file that
// cannot be read, is empty, is not a regular file, or that users other
// than its owner may read or write (a token anyone on the host can read
// guards nothing; the message says how to fix it: chmod 600).
std::variant<std::string, TokenFileError> readTokenFile(const std::string& path);

}  // namespace pvr::proto
