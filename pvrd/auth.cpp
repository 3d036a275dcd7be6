#include "auth.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace pvr::daemon {

std::optional<Nonce> makeNonce() {
  Nonce n{};
  if (RAND_bytes(n.data(), int(n.size())) != 1) return std::nullopt;
  return n;
}

Mac hmacSha256(const std::string& token, const Nonce& nonce) {
  Mac mac{};
  unsigned int len = 0;
  HMAC(EVP_sha256(), token.data(), int(token.size()), nonce.data(), nonce.size(), mac.data(), &len);
  return mac;
}

bool verifyMac(const std::string& token, const Nonce& nonce, const Mac& received) {
  const Mac expected = hmacSha256(token, nonce);
  return CRYPTO_memcmp(expected.data(), received.data(), expected.size()) == 0;
}

std::optional<std::string> makeJobSecret() {
  std::array<std::uint8_t, 32> bytes{};
  if (RAND_bytes(bytes.data(), int(bytes.size())) != 1) return std::nullopt;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string secret;
  for (std::uint8_t b : bytes) {
    secret += kHex[b >> 4];
    secret += kHex[b & 15];
  }
  return secret;
}

bool sameSecret(const std::string& expected, const std::string& received) {
  return !expected.empty() && received.size() == expected.size() &&
         CRYPTO_memcmp(expected.data(), received.data(), expected.size()) == 0;
}

std::optional<std::string> readToken(const std::string& path, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot read token file " + path + ": " + std::strerror(errno);
    return std::nullopt;
  }
  std::ostringstream s;
  s << in.rdbuf();
  std::string token = s.str();
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back()))) token.pop_back();
  if (token.empty()) {
    error = "token file " + path + " is empty";
    return std::nullopt;
  }
  return token;
}

}  // namespace pvr::daemon
