#include "token_file.h"

#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace pvr::proto {

std::variant<std::string, TokenFileError> readTokenFile(const std::string& path) {
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0)
    return TokenFileError{"cannot read token file " + path + ": " + std::strerror(errno)};
  if (!S_ISREG(st.st_mode)) return TokenFileError{"token file " + path + " is not a regular file"};
  if (st.st_mode & (S_IRWXG | S_IRWXO)) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", unsigned(st.st_mode & 07777));
    return TokenFileError{"token file " + path + " has mode " + mode +
                          ": other users may read or change it; make it private with: chmod 600 " + path};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return TokenFileError{"cannot read token file " + path + ": " + std::strerror(errno)};
  std::ostringstream s;
  s << in.rdbuf();
  std::string token = s.str();
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back()))) token.pop_back();
  if (token.empty()) return TokenFileError{"token file " + path + " is empty"};
  return token;
}

}  // namespace pvr::proto
