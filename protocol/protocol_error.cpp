#include "protocol_error.h"

namespace pvr::proto {

std::string_view errorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kBadMagic: return "BAD_MAGIC";
    case ErrorCode::kVersionMismatch: return "VERSION_MISMATCH";
    case ErrorCode::kUnknownType: return "UNKNOWN_TYPE";
    case ErrorCode::kFrameTooLarge: return "FRAME_TOO_LARGE";
    case ErrorCode::kMalformedPayload: return "MALFORMED_PAYLOAD";
    case ErrorCode::kAuthFailed: return "AUTH_FAILED";
    case ErrorCode::kBadArgument: return "BAD_ARGUMENT";
    case ErrorCode::kDatasetNotFound: return "DATASET_NOT_FOUND";
    case ErrorCode::kLimitExceeded: return "LIMIT_EXCEEDED";
    case ErrorCode::kRankFailed: return "RANK_FAILED";
    case ErrorCode::kTimeout: return "TIMEOUT";
    case ErrorCode::kInternal: return "INTERNAL";
    case ErrorCode::kCancelled: return "CANCELLED";
    case ErrorCode::kTruncatedFrame: return "TRUNCATED_FRAME";
    case ErrorCode::kReservedFlags: return "RESERVED_FLAGS";
    case ErrorCode::kUnexpectedMessage: return "UNEXPECTED_MESSAGE";
    case ErrorCode::kBadFile: return "BAD_FILE";
    case ErrorCode::kIo: return "IO";
    case ErrorCode::kUnsupported: return "UNSUPPORTED";
  }
  return "UNKNOWN_ERROR";
}

}  // namespace pvr::proto
