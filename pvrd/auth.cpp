#include "auth.h"

#include <openssl/crypto.h>
#include <openssl/rand.h>


namespace pvr::daemon {

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


}  // namespace pvr::daemon
