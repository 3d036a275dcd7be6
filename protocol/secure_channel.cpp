#include "secure_channel.h"

#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/kdf.h>
#include <openssl/ssl.h>

#include <array>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <algorithm>

namespace pvr::proto {

namespace {

// The PSK identity both ends name; the key, not the identity, is the secret.
constexpr unsigned char kIdentity[] = "pvr";
constexpr std::size_t kIdentityBytes = sizeof kIdentity - 1;
constexpr std::size_t kKeyBytes = 32;
// TLS_AES_128_GCM_SHA256, the one suite both ends offer: its hash, SHA-256,
// is the PSK's.
constexpr unsigned char kSuiteId[2] = {0x13, 0x01};
constexpr const char* kSuiteName = "TLS_AES_128_GCM_SHA256";

using Key = std::array<unsigned char, kKeyBytes>;

Key deriveKey(std::string_view secret, std::string_view purpose) {
  if (secret.empty()) throw std::invalid_argument("SecureChannel: empty secret");
  static constexpr unsigned char kSalt[] = "pvr secure channel v1";
  const std::string info = "pvr psk: " + std::string(purpose);
  Key key{};
  std::size_t length = key.size();
  EVP_PKEY_CTX* kdf = EVP_PKEY_CTX_new_id(EVP_PKEY_HKDF, nullptr);
  const bool ok = kdf && EVP_PKEY_derive_init(kdf) == 1 && EVP_PKEY_CTX_set_hkdf_md(kdf, EVP_sha256()) == 1 &&
                  EVP_PKEY_CTX_set1_hkdf_salt(kdf, kSalt, int(sizeof kSalt - 1)) == 1 &&
                  EVP_PKEY_CTX_set1_hkdf_key(kdf, reinterpret_cast<const unsigned char*>(secret.data()),
                                             int(secret.size())) == 1 &&
                  EVP_PKEY_CTX_add1_hkdf_info(kdf, reinterpret_cast<const unsigned char*>(info.data()),
                                              int(info.size())) == 1 &&
                  EVP_PKEY_derive(kdf, key.data(), &length) == 1 && length == key.size();
  EVP_PKEY_CTX_free(kdf);
  if (!ok) throw std::runtime_error("SecureChannel: HKDF failed");
  return key;
}

}  // namespace

struct SecureChannel::Tls {
  SSL_CTX* ctx = nullptr;
  SSL* ssl = nullptr;
  BIO* in = nullptr;   // ciphertext from the peer (owned by ssl)
  BIO* out = nullptr;  // ciphertext for the peer (owned by ssl)
  Key key{};

  ~Tls() {
    if (ssl) SSL_free(ssl);
    if (ctx) SSL_CTX_free(ctx);
    OPENSSL_cleanse(key.data(), key.size());
  }

  // The PSK as a TLS 1.3 session of the one suite.
  static SSL_SESSION* pskSession(SSL* ssl) {
    const Tls* tls = static_cast<const Tls*>(SSL_get_app_data(ssl));
    const SSL_CIPHER* suite = SSL_CIPHER_find(ssl, kSuiteId);
    SSL_SESSION* session = suite ? SSL_SESSION_new() : nullptr;
    if (!session) return nullptr;
    if (SSL_SESSION_set1_master_key(session, tls->key.data(), tls->key.size()) != 1 ||
        SSL_SESSION_set_cipher(session, suite) != 1 ||
        SSL_SESSION_set_protocol_version(session, TLS1_3_VERSION) != 1) {
      SSL_SESSION_free(session);
      return nullptr;
    }
    return session;
  }

  // Client: offer the PSK (unless OpenSSL asks for another hash, which the
  // one suite rules out).
  static int useSession(SSL* ssl, const EVP_MD* md, const unsigned char** id, std::size_t* idLength,
                        SSL_SESSION** session) {
    *session = nullptr;
    *id = nullptr;
    *idLength = 0;
    SSL_SESSION* s = pskSession(ssl);
    if (!s) return 0;
    if (md && md != SSL_CIPHER_get_handshake_digest(SSL_SESSION_get0_cipher(s))) {
      SSL_SESSION_free(s);
      return 1;
    }
    *session = s;
    *id = kIdentity;
    *idLength = kIdentityBytes;
    return 1;
  }

  // Server: accept only our identity; the binder then proves the key.
  static int findSession(SSL* ssl, const unsigned char* id, std::size_t idLength, SSL_SESSION** session) {
    *session = nullptr;
    if (idLength != kIdentityBytes || std::memcmp(id, kIdentity, kIdentityBytes) != 0) return 1;
    *session = pskSession(ssl);
    return *session ? 1 : 0;
  }
};

SecureChannel::SecureChannel(Role role, std::string_view secret, std::string_view purpose)
    : tls_(std::make_unique<Tls>()) {
  tls_->key = deriveKey(secret, purpose);
  Tls& t = *tls_;
  t.ctx = SSL_CTX_new(TLS_method());
  if (!t.ctx || SSL_CTX_set_min_proto_version(t.ctx, TLS1_3_VERSION) != 1 ||
      SSL_CTX_set_max_proto_version(t.ctx, TLS1_3_VERSION) != 1 || SSL_CTX_set_ciphersuites(t.ctx, kSuiteName) != 1)
    throw std::runtime_error("SecureChannel: OpenSSL has no TLS 1.3 with " + std::string(kSuiteName));
  // No resumption: every connection proves the secret afresh.
  SSL_CTX_set_options(t.ctx, SSL_OP_NO_TICKET);
  SSL_CTX_set_num_tickets(t.ctx, 0);
  t.ssl = SSL_new(t.ctx);
  t.in = BIO_new(BIO_s_mem());
  t.out = BIO_new(BIO_s_mem());
  if (!t.ssl || !t.in || !t.out) {
    BIO_free(t.in);
    BIO_free(t.out);
    throw std::runtime_error("SecureChannel: out of memory");
  }
  SSL_set_bio(t.ssl, t.in, t.out);
  SSL_set_app_data(t.ssl, &t);
  if (role == Role::kClient) {
    SSL_set_psk_use_session_callback(t.ssl, &Tls::useSession);
    SSL_set_connect_state(t.ssl);
    // The ClientHello, ready for takeOutgoing().
    if (auto e = pump()) throw std::runtime_error("SecureChannel: " + e->text);
  } else {
    SSL_set_psk_find_session_callback(t.ssl, &Tls::findSession);
    SSL_set_accept_state(t.ssl);
  }
}

SecureChannel::~SecureChannel() = default;

std::optional<ProtocolError> SecureChannel::receive(std::span<const std::uint8_t> ciphertext) {
  if (failure_) return failure_;
  if (!ciphertext.empty() && BIO_write(tls_->in, ciphertext.data(), int(ciphertext.size())) != int(ciphertext.size()))
    return fail("buffering");
  return pump();
}

std::optional<ProtocolError> SecureChannel::send(std::span<const std::uint8_t> plaintext) {
  if (failure_) return failure_;
  pendingPlain_.insert(pendingPlain_.end(), plaintext.begin(), plaintext.end());
  return pump();
}

std::vector<std::uint8_t> SecureChannel::takeOutgoing() {
  std::vector<std::uint8_t> out(BIO_ctrl_pending(tls_->out));
  if (!out.empty()) out.resize(std::size_t(std::max(0, BIO_read(tls_->out, out.data(), int(out.size())))));
  return out;
}

std::vector<std::uint8_t> SecureChannel::takeIncoming() { return std::exchange(incomingPlain_, {}); }

std::optional<ProtocolError> SecureChannel::pump() {
  SSL* ssl = tls_->ssl;
  if (!established_) {
    const int r = SSL_do_handshake(ssl);
    if (r == 1) {
      established_ = true;
    } else {
      const int e = SSL_get_error(ssl, r);
      if (e != SSL_ERROR_WANT_READ && e != SSL_ERROR_WANT_WRITE) return fail("the handshake");
      return std::nullopt;
    }
  }
  if (!pendingPlain_.empty()) {
    std::size_t written = 0;
    if (SSL_write_ex(ssl, pendingPlain_.data(), pendingPlain_.size(), &written) != 1 ||
        written != pendingPlain_.size())
      return fail("encrypting");
    pendingPlain_.clear();
  }
  std::array<std::uint8_t, 16384> buffer;
  for (;;) {
    std::size_t got = 0;
    const int r = SSL_read_ex(ssl, buffer.data(), buffer.size(), &got);
    if (r == 1) {
      incomingPlain_.insert(incomingPlain_.end(), buffer.begin(), buffer.begin() + std::ptrdiff_t(got));
      continue;
    }
    const int e = SSL_get_error(ssl, r);
    if (e == SSL_ERROR_WANT_READ || e == SSL_ERROR_WANT_WRITE) return std::nullopt;
    if (e == SSL_ERROR_ZERO_RETURN) {
      failure_ = ProtocolError{ErrorCode::kTruncatedFrame, "secure channel: the peer closed it"};
      return failure_;
    }
    return fail("decrypting");
  }
}

std::optional<ProtocolError> SecureChannel::fail(const char* during) {
  std::string reasons;
  while (const unsigned long code = ERR_get_error()) {
    const char* reason = ERR_reason_error_string(code);
    reasons += std::string(reasons.empty() ? "" : "; ") + (reason ? reason : "unknown");
  }
  failure_ = ProtocolError{ErrorCode::kAuthFailed,
                           std::string("secure channel: ") + during + " failed (" +
                               (reasons.empty() ? "no reason given" : reasons) +
                               "): the peer does not hold the same secret, or the bytes were altered or replayed"};
  return failure_;
}

}  // namespace pvr::proto
