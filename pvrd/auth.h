// Challenge-response authentication: HMAC-SHA256(token, 32-byte nonce).
#pragma once

#include <array>
#include <optional>
#include <string>

#include "pvr_protocol.h"

namespace pvr::daemon {

using Nonce = std::array<std::uint8_t, proto::kNonceBytes>;
using Mac = std::array<std::uint8_t, proto::kMacBytes>;

// Fresh random bytes from the OpenSSL generator; nullopt if it fails.
std::optional<Nonce> makeNonce();

Mac hmacSha256(const std::string& token, const Nonce& nonce);

// Constant-time comparison of the expected and received MAC.
bool verifyMac(const std::string& token, const Nonce& nonce, const Mac& received);

// The token in a file, trailing whitespace removed; nullopt when it cannot
// be read or is empty.
std::optional<std::string> readToken(const std::string& path, std::string& error);

}  // namespace pvr::daemon
