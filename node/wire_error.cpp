#include "wire_error.h"

#include "hosts.h"

namespace pvr::node {

namespace {

proto::ErrorCode wireCode(pvr::ErrorCode code) {
  using proto::ErrorCode;
  switch (code) {
    case pvr::ErrorCode::kInvalidArgument: return ErrorCode::kBadArgument;
    case pvr::ErrorCode::kBadFile: return ErrorCode::kBadFile;
    case pvr::ErrorCode::kIo: return ErrorCode::kIo;
    case pvr::ErrorCode::kUnsupported: return ErrorCode::kUnsupported;
    case pvr::ErrorCode::kRemote: return ErrorCode::kRankFailed;
    case pvr::ErrorCode::kInternal: return ErrorCode::kInternal;
    case pvr::ErrorCode::kCancelled: return ErrorCode::kCancelled;
  }
  return ErrorCode::kInternal;
}

}  // namespace

proto::ProtocolError wireError(const pvr::Error& error) { return {wireCode(error.code()), error.what()}; }

proto::ProtocolError wireError(const comm::Failure& failure, const std::vector<std::string>& hosts) {
  return {wireCode(failure.code), describeOnHost(failure, hosts)};
}

}  // namespace pvr::node
