#include "job_hello_check.h"

#include "auth.h"
#include "pvr_protocol.h"
#include "sys.h"

namespace pvr::daemon {

JobHelloCheck::Result JobHelloCheck::feed(std::span<const std::uint8_t> bytes) {
  received_.insert(received_.end(), bytes.begin(), bytes.end());
  const auto header = proto::checkHeaderFields(received_);
  if (const auto* e = std::get_if<proto::ProtocolError>(&header)) return Refused{"not a frame: " + e->text};
  if (const auto* h = std::get_if<proto::CheckedHeader>(&header); h && h->info->type != proto::JobHello::kWire.type)
    return Refused{"its first frame is " + std::string(h->info->name) + ", not JobHello"};
  const auto decoded = proto::decodeFrame(received_);
  if (std::holds_alternative<proto::NeedMore>(decoded)) return Waiting{};
  if (const auto* e = std::get_if<proto::ProtocolError>(&decoded)) return Refused{"bad JobHello: " + e->text};
  const auto& frame = std::get<proto::Decoded>(decoded);
  const auto& secret = std::get<proto::JobHello>(frame.message).secret;
  if (secret.empty()) return Refused{"JobHello without a secret"};
  if (!sameSecret(secret_, secret)) return Refused{"JobHello with a wrong secret"};
  return Accepted{{received_.begin() + std::ptrdiff_t(frame.bytesConsumed), received_.end()}};
}

std::string JobHelloCheck::firstBytes() const { return printable(received_); }

}  // namespace pvr::daemon
