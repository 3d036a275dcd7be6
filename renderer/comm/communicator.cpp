#include "communicator.h"

#include <algorithm>
#include <cstring>
#include <exception>

namespace pvr::comm {

namespace {

// Reserved tags of the default collectives; each has its own so a
// collective's messages never match another's.
constexpr int kBroadcastTag = kFirstReservedTag + 1;
constexpr int kGatherTag = kFirstReservedTag + 2;
constexpr int kReduceTag = kFirstReservedTag + 3;

template <typename T>
std::span<const std::byte> bytesOf(std::span<const T> values) {
  return std::as_bytes(values);
}

template <typename T>
void copyInto(std::span<T> values, const Bytes& bytes) {
  if (bytes.size() != values.size_bytes())
    throw Error(ErrorCode::kInternal, "allReduce: ranks passed different numbers of values");
  std::memcpy(values.data(), bytes.data(), bytes.size());
}

// Reduces at rank 0 with `combine`, then broadcasts the result.
template <typename T, typename Combine>
void reduceThroughRoot(Communicator& comm, std::span<T> values, Combine combine) {
  if (comm.rank() == 0) {
    std::vector<T> other(values.size());
    for (int r = 1; r < comm.size(); ++r) {
      copyInto(std::span<T>(other), comm.receive(r, kReduceTag));
      for (std::size_t i = 0; i < values.size(); ++i) values[i] = combine(values[i], other[i]);
    }
  } else {
    comm.send(0, kReduceTag, bytesOf(std::span<const T>(values)));
  }
  Bytes result(values.size_bytes());
  if (comm.rank() == 0) std::memcpy(result.data(), values.data(), result.size());
  comm.broadcast(result, 0);
  copyInto(values, result);
}

}  // namespace

// Wire form: u8 failed; if failed, i32 origin, u16 code, message bytes.
constexpr std::size_t kStatusHead = 1 + 4 + 2;

Bytes encodeFailure(const std::optional<Failure>& failure) {
  Bytes out(1);
  if (!failure) return out;
  out.resize(kStatusHead);
  out[0] = std::byte{1};
  const std::int32_t origin = failure->origin;
  const auto code = std::uint16_t(failure->code);
  std::memcpy(out.data() + 1, &origin, 4);
  std::memcpy(out.data() + 5, &code, 2);
  const auto* text = reinterpret_cast<const std::byte*>(failure->message.data());
  out.insert(out.end(), text, text + failure->message.size());
  return out;
}

std::optional<Failure> decodeFailure(std::span<const std::byte> bytes) {
  if (bytes.empty()) throw Error(ErrorCode::kInternal, "agree: empty status message");
  if (bytes[0] == std::byte{0}) return std::nullopt;
  if (bytes.size() < kStatusHead) throw Error(ErrorCode::kInternal, "agree: short status message");
  Failure f;
  std::int32_t origin = 0;
  std::uint16_t code = 0;
  std::memcpy(&origin, bytes.data() + 1, 4);
  std::memcpy(&code, bytes.data() + 5, 2);
  f.origin = origin;
  f.code = ErrorCode(code);
  f.message.assign(reinterpret_cast<const char*>(bytes.data() + kStatusHead), bytes.size() - kStatusHead);
  return f;
}

std::string Failure::describe() const {
  return "rank " + std::to_string(origin) + ": " + message;
}

void Communicator::broadcast(Bytes& data, int root) {
  if (rank() == root) {
    for (int r = 0; r < size(); ++r)
      if (r != root) send(r, kBroadcastTag, data);
  } else {
    data = receive(root, kBroadcastTag);
  }
}

std::vector<Bytes> Communicator::allGather(std::span<const std::byte> mine) {
  // Gather at rank 0, then rank 0 broadcasts the list as lengths + bytes.
  std::vector<Bytes> all(static_cast<std::size_t>(size()));
  Bytes packed;
  if (rank() == 0) {
    all[0].assign(mine.begin(), mine.end());
    for (int r = 1; r < size(); ++r) all[std::size_t(r)] = receive(r, kGatherTag);
    for (const Bytes& b : all) {
      const std::uint64_t n = b.size();
      const auto* p = reinterpret_cast<const std::byte*>(&n);
      packed.insert(packed.end(), p, p + sizeof n);
      packed.insert(packed.end(), b.begin(), b.end());
    }
  } else {
    send(0, kGatherTag, mine);
  }
  broadcast(packed, 0);
  if (rank() != 0) {
    std::size_t at = 0;
    for (Bytes& b : all) {
      std::uint64_t n = 0;
      if (packed.size() - at < sizeof n) throw Error(ErrorCode::kInternal, "allGather: short message");
      std::memcpy(&n, packed.data() + at, sizeof n);
      at += sizeof n;
      if (packed.size() - at < n) throw Error(ErrorCode::kInternal, "allGather: short message");
      b.assign(packed.begin() + std::ptrdiff_t(at), packed.begin() + std::ptrdiff_t(at + n));
      at += n;
    }
  }
  return all;
}

void Communicator::allReduceSum(std::span<std::uint64_t> values) {
  reduceThroughRoot(*this, values, [](std::uint64_t a, std::uint64_t b) { return a + b; });
}

void Communicator::allReduceMax(std::span<double> values) {
  reduceThroughRoot(*this, values, [](double a, double b) { return std::max(a, b); });
}

void Communicator::barrier() {
  Bytes none;
  allGather(none);
}

std::optional<Failure> Communicator::agree(const std::optional<Failure>& mine) {
  std::optional<Failure> first;
  for (const Bytes& b : allGather(encodeFailure(mine))) {
    auto f = decodeFailure(b);
    if (f && (!first || f->origin < first->origin)) first = std::move(f);
  }
  return first;
}

Failure failureOf(std::exception_ptr error, int worldRank) {
  Failure f;
  f.origin = worldRank;
  try {
    std::rethrow_exception(error);
  } catch (const FailureError& e) {
    f = e.failure();
  } catch (const Error& e) {
    f.code = e.code();
    f.message = e.what();
  } catch (const std::exception& e) {
    f.code = ErrorCode::kInternal;
    f.message = e.what();
  } catch (...) {
    f.code = ErrorCode::kInternal;
    f.message = "unknown exception";
  }
  return f;
}

void runAgreed(Communicator& comm, const std::function<void()>& phase) {
  std::optional<Failure> mine;
  try {
    phase();
  } catch (...) {
    mine = failureOf(std::current_exception(), comm.worldRank());
  }
  if (auto first = comm.agree(mine)) throw FailureError(std::move(*first));
}

}  // namespace pvr::comm
