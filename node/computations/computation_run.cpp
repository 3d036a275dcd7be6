#include "computation_run.h"

#include <cstring>
#include <span>

#include "error.h"

namespace pvr::node {

namespace {

using core::IVec3;
using core::NodeBox;

// Copies every field of `box` (inside both blocks) from `from` to `to`.
void copyBox(const FieldBlock& from, FieldBlock& to, const NodeBox& box) {
  const std::size_t row = std::size_t(box.extent(0)) * sizeof(double);
  for (int f = 0; f < from.fields(); ++f)
    for (std::int64_t z = box.lo.z; z <= box.hi.z; ++z)
      for (std::int64_t y = box.lo.y; y <= box.hi.y; ++y)
        std::memcpy(to.field(f) + to.index({box.lo.x, y, z}), from.field(f) + from.index({box.lo.x, y, z}), row);
}

// Every field of `box` as bytes: field 0's nodes x fastest, then field 1's...
comm::Bytes packBox(const FieldBlock& from, const NodeBox& box) {
  comm::Bytes bytes(std::size_t(from.fields()) * std::size_t(box.nodeCount()) * sizeof(double));
  std::byte* out = bytes.data();
  const std::size_t row = std::size_t(box.extent(0)) * sizeof(double);
  for (int f = 0; f < from.fields(); ++f)
    for (std::int64_t z = box.lo.z; z <= box.hi.z; ++z)
      for (std::int64_t y = box.lo.y; y <= box.hi.y; ++y, out += row)
        std::memcpy(out, from.field(f) + from.index({box.lo.x, y, z}), row);
  return bytes;
}

void unpackBox(const comm::Bytes& bytes, FieldBlock& to, const NodeBox& box) {
  if (bytes.size() != std::size_t(to.fields()) * std::size_t(box.nodeCount()) * sizeof(double))
    throw Error(ErrorCode::kInternal, "computation: the nodes " + core::toString(box) + " came with " +
                                          std::to_string(bytes.size()) + " bytes");
  const std::byte* in = bytes.data();
  const std::size_t row = std::size_t(box.extent(0)) * sizeof(double);
  for (int f = 0; f < to.fields(); ++f)
    for (std::int64_t z = box.lo.z; z <= box.hi.z; ++z)
      for (std::int64_t y = box.lo.y; y <= box.hi.y; ++y, in += row)
        std::memcpy(to.field(f) + to.index({box.lo.x, y, z}), in, row);
}

// Collective: every rank r holds valid values on have[r] of `from` and
// wants need[r] of `to` filled. Rank r sends each other rank s the nodes of
// have[r] in need[s], and copies its own share itself when `from` and `to`
// are different blocks. Nodes that several ranks hold (the planes bricks
// share) arrive more than once with the same values.
void exchangeBoxes(comm::Communicator& comm, const FieldBlock& from, const std::vector<NodeBox>& have,
                   FieldBlock& to, const std::vector<NodeBox>& need) {
  const int me = comm.rank();
  std::vector<comm::Bytes> packed;
  std::vector<int> targets;
  for (int s = 0; s < comm.size(); ++s) {
    if (s == me) continue;
    const NodeBox box = have[std::size_t(me)].intersect(need[std::size_t(s)]);
    if (box.empty()) continue;
    packed.push_back(packBox(from, box));
    targets.push_back(s);
  }
  std::vector<comm::Outgoing> sends;
  for (std::size_t i = 0; i < packed.size(); ++i) sends.push_back({targets[i], packed[i]});
  std::vector<int> sources;
  std::vector<NodeBox> boxes;
  for (int r = 0; r < comm.size(); ++r) {
    if (r == me) continue;
    const NodeBox box = have[std::size_t(r)].intersect(need[std::size_t(me)]);
    if (box.empty()) continue;
    sources.push_back(r);
    boxes.push_back(box);
  }
  if (&from != &to) {
    const NodeBox mine = have[std::size_t(me)].intersect(need[std::size_t(me)]);
    if (!mine.empty()) copyBox(from, to, mine);
  }
  const std::vector<comm::Bytes> received = comm.exchange(sends, sources, kComputationTag);
  for (std::size_t i = 0; i < received.size(); ++i) unpackBox(received[i], to, boxes[i]);
}

}  // namespace

FieldBlock::FieldBlock(int fields, const core::NodeBox& box)
    : fields_(fields), box_(box), extents_(box.extents()), nodes_(std::size_t(box.nodeCount())),
      values_(std::size_t(fields) * nodes_, 0.0) {}

NodeBox ComputationRun::grownInGrid(const NodeBox& owned, int layers) const {
  return owned.grown(layers).intersect(grid_.allNodes());
}

void ComputationRun::place(comm::Communicator& comm, const std::vector<int>& members,
                           const std::vector<NodeBox>& owned, int ghost) {
  const int layers = std::max(ghost, entry_.halo);
  const int me = comm.rank();
  const NodeBox block = grownInGrid(owned[std::size_t(me)], layers);
  // Both blocks of every rank, or none: a rank without the memory must not
  // leave the others waiting in the exchange below.
  FieldBlock placed, next;
  comm::runAgreed(comm, [&] {
    placed = FieldBlock(int(entry_.fields.size()), block);
    next = FieldBlock(int(entry_.fields.size()), block);
  });
  if (owned_.empty() || members != members_) {
    steps_ = 0;
    // Step 0 on the owned nodes; the ghost layers come with the first step.
    std::vector<double> values(entry_.fields.size());
    const NodeBox& mine = owned[std::size_t(me)];
    for (std::int64_t z = mine.lo.z; z <= mine.hi.z; ++z)
      for (std::int64_t y = mine.lo.y; y <= mine.hi.y; ++y)
        for (std::int64_t x = mine.lo.x; x <= mine.hi.x; ++x) {
          entry_.initial(grid_, {x, y, z}, values);
          const std::size_t i = placed.index({x, y, z});
          for (std::size_t f = 0; f < values.size(); ++f) placed.field(int(f))[i] = values[f];
        }
  } else {
    // The owned nodes move from the old bricks to the new ones.
    std::vector<NodeBox> need;
    for (const NodeBox& b : owned) need.push_back(b);
    exchangeBoxes(comm, now_, owned_, placed, need);
  }
  members_ = members;
  owned_ = owned;
  rank_ = me;
  ghost_ = layers;
  now_ = std::move(placed);
  next_ = std::move(next);
}

void ComputationRun::exchangeGhosts(comm::Communicator& comm, int layers) {
  std::vector<NodeBox> need;
  for (const NodeBox& b : owned_) need.push_back(grownInGrid(b, layers));
  exchangeBoxes(comm, now_, owned_, now_, need);
}

void ComputationRun::step(comm::Communicator& comm, const Parameters& parameters) {
  exchangeGhosts(comm, entry_.halo);
  entry_.step(StepArgs{now_, next_, owned(), grid_, parameters});
  std::swap(now_, next_);
  ++steps_;
}

core::Brick ComputationRun::brick(comm::Communicator& comm, const Parameters& parameters, const NodeBox& stored) {
  exchangeGhosts(comm, ghost_);
  if (!now_.box().contains(stored))
    throw Error(ErrorCode::kInternal, "computation: brick " + core::toString(stored) + " outside the block " +
                                          core::toString(now_.box()));
  core::Brick brick = core::Brick::forOverwrite(grid_, core::ScalarType::kFloat32, owned(), stored);
  const double* field = now_.field(entry_.shown(parameters));
  float* out = brick.as<float>();
  for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
    for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
      for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x) *out++ = float(field[now_.index({x, y, z})]);
  brick.updateValueRange();
  return brick;
}

}  // namespace pvr::node
