#include "communicator.h"

#include <algorithm>
#include <cstring>
#include <exception>

namespace pvr::composite {

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

// Status wire form: u8 failed, u16 code, message bytes.
Bytes encodeStatus(const std::optional<Failure>& failure) {
  Bytes out(3);
  if (!failure) return out;
  out[0] = std::byte{1};
  const auto code = std::uint16_t(failure->code);
  out[1] = std::byte(code & 0xff);
  out[2] = std::byte(code >> 8);
  const auto* text = reinterpret_cast<const std::byte*>(failure->message.data());
  out.insert(out.end(), text, text + failure->message.size());
  return out;
}

std::optional<Failure> decodeStatus(const Bytes& bytes, int rank) {
  if (bytes.size() < 3) throw Error(ErrorCode::kInternal, "agree: short status message");
  if (bytes[0] == std::byte{0}) return std::nullopt;
  Failure f;
  f.rank = rank;
  f.code = ErrorCode(std::uint16_t(bytes[1]) | std::uint16_t(std::uint16_t(bytes[2]) << 8));
  f.message.assign(reinterpret_cast<const char*>(bytes.data() + 3), bytes.size() - 3);
  return f;
}

}  // namespace

std::string Failure::describe() const {
  return "rank " + std::to_string(rank) + ": " + message;
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
  const std::vector<Bytes> all = allGather(encodeStatus(mine));
  for (int r = 0; r < int(all.size()); ++r)
    if (auto f = decodeStatus(all[std::size_t(r)], r)) return f;
  return std::nullopt;
}

Failure failureOf(std::exception_ptr error, int rank) {
  Failure f;
  f.rank = rank;
  try {
    std::rethrow_exception(error);
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
    mine = failureOf(std::current_exception(), comm.rank());
  }
  if (const auto first = comm.agree(mine)) throw Error(first->code, first->describe());
}

}  // namespace pvr::composite
