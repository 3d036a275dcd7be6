#include "agreement.h"

#include <cstring>

namespace pvr::runtime {

RankFailure failureOf(std::exception_ptr error, int worldRank) {
  try {
    std::rethrow_exception(error);
  } catch (const RankError& e) {
    return e.failure();
  } catch (const Error& e) {
    return {worldRank, e.code(), e.what()};
  } catch (const std::exception& e) {
    return {worldRank, ErrorCode::kInternal, e.what()};
  } catch (...) {
    return {worldRank, ErrorCode::kInternal, "unknown exception"};
  }
}

// Wire form: u8 failed; if failed, i32 origin, u16 code, message bytes.
composite::Bytes encodeFailure(const std::optional<RankFailure>& failure) {
  composite::Bytes out(1);
  if (!failure) return out;
  out[0] = std::byte{1};
  const std::int32_t origin = failure->origin;
  const auto code = std::uint16_t(failure->code);
  out.resize(7 + failure->message.size());
  std::memcpy(out.data() + 1, &origin, 4);
  std::memcpy(out.data() + 5, &code, 2);
  std::memcpy(out.data() + 7, failure->message.data(), failure->message.size());
  return out;
}

std::optional<RankFailure> decodeFailure(std::span<const std::byte> bytes) {
  if (bytes.empty()) throw Error(ErrorCode::kInternal, "empty failure status");
  if (bytes[0] == std::byte{0}) return std::nullopt;
  if (bytes.size() < 7) throw Error(ErrorCode::kInternal, "short failure status");
  RankFailure f;
  std::int32_t origin = 0;
  std::uint16_t code = 0;
  std::memcpy(&origin, bytes.data() + 1, 4);
  std::memcpy(&code, bytes.data() + 5, 2);
  f.origin = origin;
  f.code = ErrorCode(code);
  f.message.assign(reinterpret_cast<const char*>(bytes.data() + 7), bytes.size() - 7);
  return f;
}

std::optional<RankFailure> agreeOn(composite::Communicator& comm, const std::optional<RankFailure>& mine) {
  std::optional<RankFailure> first;
  for (const composite::Bytes& b : comm.allGather(encodeFailure(mine))) {
    auto f = decodeFailure(b);
    if (f && (!first || f->origin < first->origin)) first = std::move(f);
  }
  return first;
}

void runAgreedOn(composite::Communicator& comm, int worldRank, const std::function<void()>& phase) {
  std::optional<RankFailure> mine;
  try {
    phase();
  } catch (...) {
    mine = failureOf(std::current_exception(), worldRank);
  }
  if (auto f = agreeOn(comm, mine)) throw RankError(*f);
}

}  // namespace pvr::runtime
