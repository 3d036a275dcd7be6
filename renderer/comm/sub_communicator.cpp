#include "sub_communicator.h"

#include <algorithm>

namespace pvr::comm {

SubCommunicator::SubCommunicator(Communicator& parent, std::vector<int> ranks)
    : parent_(parent), ranks_(std::move(ranks)) {
  const auto it = std::find(ranks_.begin(), ranks_.end(), parent.rank());
  if (it == ranks_.end())
    throw Error(ErrorCode::kInternal, "sub-communicator without rank " + std::to_string(parent.rank()));
  rank_ = int(it - ranks_.begin());
}

void SubCommunicator::send(int to, int tag, std::span<const std::byte> data) {
  parent_.send(parentRank(to), tag, data);
}

Bytes SubCommunicator::receive(int from, int tag) { return parent_.receive(parentRank(from), tag); }

Bytes SubCommunicator::sendReceive(int to, std::span<const std::byte> data, int from, int tag) {
  return parent_.sendReceive(parentRank(to), data, parentRank(from), tag);
}

std::vector<Bytes> SubCommunicator::exchange(std::span<const Outgoing> sends,
                                                        std::span<const int> from, int tag) {
  std::vector<Outgoing> mapped(sends.begin(), sends.end());
  for (auto& s : mapped) s.to = parentRank(s.to);
  std::vector<int> sources(from.begin(), from.end());
  for (int& f : sources) f = parentRank(f);
  return parent_.exchange(mapped, sources, tag);
}

}  // namespace pvr::comm
