// A Communicator over a subset of another communicator's ranks: a cluster
// of the session layout. Rank r of the sub-communicator is parent rank
// ranks[r]; messages keep their tags, so the strategies and the default
// collectives (which talk point to point through sub-rank 0) run on a
// cluster unchanged. Two clusters never share a rank, so their messages
// never meet.
#pragma once

#include <vector>

#include "communicator.h"

namespace pvr::comm {

class SubCommunicator final : public Communicator {
 public:
  // `ranks` are parent ranks in sub-rank order; the parent's rank must be
  // one of them.
  SubCommunicator(Communicator& parent, std::vector<int> ranks);

  int rank() const override { return rank_; }
  int size() const override { return int(ranks_.size()); }
  int worldRank() const override { return parent_.worldRank(); }
  int parentRank(int subRank) const { return ranks_.at(std::size_t(subRank)); }

  void send(int to, int tag, std::span<const std::byte> data) override;
  Bytes receive(int from, int tag) override;
  Bytes sendReceive(int to, std::span<const std::byte> data, int from, int tag) override;
  std::vector<Bytes> exchange(std::span<const Outgoing> sends, std::span<const int> from,
                                         int tag) override;

 private:
  Communicator& parent_;
  std::vector<int> ranks_;
  int rank_ = -1;
};

}  // namespace pvr::comm
