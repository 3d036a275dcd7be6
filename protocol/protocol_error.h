// Wire error codes and the error value every decoding step returns.
//
// The numbers are stable: they travel in Error messages, pvrsh turns them
// into the Tcl error code `PVR REMOTE <code>`, and docs/protocol.md lists
// them. Add new codes at the end; never renumber or reuse one.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pvr::proto {

enum class ErrorCode : std::uint16_t {
  // Framing: the peer does not speak this protocol, or sent a broken frame.
  kBadMagic = 1,           // the first four bytes of a frame are not the magic
  kVersionMismatch = 2,    // header version differs from kProtocolVersion
  kUnknownType = 3,        // header names no message type of this version
  kFrameTooLarge = 4,      // payload length over the limit for its type
  kMalformedPayload = 5,   // a payload that does not parse as its type
  // Conversation and service errors, sent by pvrd or the master rank.
  kAuthFailed = 6,         // the HMAC response did not match the challenge
  kBadArgument = 7,        // a request whose values are wrong (core kInvalidArgument)
  kDatasetNotFound = 8,    // no dataset of that name in the catalog
  kLimitExceeded = 9,      // a count or size over a configured limit
  kRankFailed = 10,        // an MPI rank died or reported an error (core kRemote)
  kTimeout = 11,           // a peer or rank did not answer in time
  kInternal = 12,          // a broken invariant; a bug (core kInternal)
  kCancelled = 13,         // the request was cancelled by a Cancel message
  kTruncatedFrame = 14,    // the byte stream ended inside a frame
  kReservedFlags = 15,     // header flag bits that this version reserves are set
  kUnexpectedMessage = 16, // a valid message at the wrong time or direction
  kBadFile = 17,           // a dataset file whose content is wrong (core kBadFile)
  kIo = 18,                // a file could not be read or written (core kIo)
  kUnsupported = 19,       // a valid request this build cannot serve (core kUnsupported)
};

// "BAD_MAGIC", "VERSION_MISMATCH", ...; "UNKNOWN_ERROR" for a number this
// build does not know (a newer peer may send one).
std::string_view errorCodeName(ErrorCode code);

// What a decoding step answers when the bytes are wrong. `text` names the
// message type, the byte offset and the numbers involved.
struct ProtocolError {
  ErrorCode code = ErrorCode::kInternal;
  std::string text;

  bool operator==(const ProtocolError&) const = default;
};

}  // namespace pvr::proto
