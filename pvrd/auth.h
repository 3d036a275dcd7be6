// Challenge-response authentication of clients, HMAC-SHA256(token, 32-byte
// nonce), and the one-time secret that proves a connect-back is the job
// this session launched.
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

// A per-session job secret (docs/pvrd.md, "The job's secret"): 32 random
// bytes as 64 lowercase hex characters, which survive an environment
// variable and a protocol string alike; nullopt if the generator fails.
std::optional<std::string> makeJobSecret();

// Whether `received` is `expected`, compared in constant time (the length,
// 64 characters for every secret pvrd makes, is no secret).
bool sameSecret(const std::string& expected, const std::string& received);

// The token in a file, trailing whitespace removed; nullopt when it cannot
// be read or is empty.
std::optional<std::string> readToken(const std::string& path, std::string& error);

}  // namespace pvr::daemon
