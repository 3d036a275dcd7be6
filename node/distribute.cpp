#include "distribute.h"

#include <cstring>
#include <optional>

#include "decompose/content.h"
#include "transfer.h"

namespace pvr::node {

using comm::Communicator;
using comm::runAgreed;
using core::Brick;
using core::KdTree;

namespace {

constexpr int kBrickTag = 20;

}  // namespace

std::optional<Brick> readWholeOnRoot(const core::VolumeSource& source, Communicator& comm) {
  std::optional<Brick> whole;
  if (source.canReadPartially()) return whole;
  runAgreed(comm, [&] {
    if (comm.rank() == 0) whole = source.readAll();
  });
  return whole;
}

std::optional<Brick> obtainBrick(const core::VolumeSource& source, const std::function<core::NodeBox(int)>& ownedOf,
                                 int ghostLayers, const std::optional<Brick>& whole, Communicator& comm) {
  const int me = comm.rank();
  const core::NodeBox owned = ownedOf(me);
  const core::NodeBox stored = owned.grown(ghostLayers).intersect(source.grid().allNodes());
  std::optional<Brick> brick;
  if (source.canReadPartially()) {
    runAgreed(comm, [&] {
      if (!owned.empty()) brick = source.readBox(owned, stored);
    });
    return brick;
  }
  // Scatter from rank 0: it sends every other rank its crop, one at a time;
  // each receiver waits for exactly one message, so nobody can deadlock. A
  // rank owning nothing gets nothing (both sides know).
  if (me == 0) {
    for (int r = 1; r < comm.size(); ++r) {
      const core::NodeBox theirs = ownedOf(r);
      if (theirs.empty()) continue;
      const Brick crop = core::cropBrick(*whole, theirs, ghostLayers);
      comm.send(r, kBrickTag, std::span<const std::byte>(crop.bytes(), crop.byteSize()));
    }
    if (!owned.empty()) brick = core::cropBrick(*whole, owned, ghostLayers);
  } else if (!owned.empty()) {
    const comm::Bytes bytes = comm.receive(0, kBrickTag);
    runAgreed(comm, [&] {
      brick = Brick(source.grid(), source.type(), owned, stored);
      if (bytes.size() != brick->byteSize())
        throw Error(ErrorCode::kInternal, "scatter: brick " + core::toString(stored) + " came with " +
                                              std::to_string(bytes.size()) + " bytes, expected " +
                                              std::to_string(brick->byteSize()));
      std::memcpy(brick->bytes(), bytes.data(), bytes.size());
      brick->updateValueRange();
    });
    return brick;
  }
  runAgreed(comm, [] {});  // the other half of the receivers' agreement
  return brick;
}

const std::vector<DecompositionEntry>& decompositions() {
  static const std::vector<DecompositionEntry> table{{"kd", Decomposition::kKd},
                                                     {"balanced", Decomposition::kBalanced},
                                                     {"slabs", Decomposition::kSlabs}};
  return table;
}

std::string_view decompositionName(Decomposition d) {
  for (const DecompositionEntry& e : decompositions())
    if (e.value == d) return e.name;
  return "unknown";
}

Decomposition decompositionNamed(std::string_view name) {
  std::string known;
  for (const DecompositionEntry& e : decompositions()) {
    if (e.name == name) return e.value;
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw Error(ErrorCode::kInvalidArgument, "unknown decomposition '" + std::string(name) + "' (known: " + known + ")");
}

Distribution distributeBricks(const core::VolumeSource& source, const core::Scene& scene,
                              Decomposition decomposition, int ghostLayers, Communicator& comm) {
  Distribution out;
  out.readPartially = source.canReadPartially();

  // The k-d tree: the same on every rank (it depends only on the grid).
  std::optional<KdTree> tree;
  runAgreed(comm, [&] { tree = KdTree::build(source.grid(), comm.size(), splitAxisRule(decomposition)); });

  // Without a partial reader rank 0 holds the whole volume while it scatters.
  const std::optional<Brick> whole = readWholeOnRoot(source, comm);
  if (whole) out.rootReadBytes = whole->byteSize();
  const auto ownedOf = [&](int rank) { return tree->ownedBox(rank); };
  out.brick = std::move(*obtainBrick(source, ownedOf, ghostLayers, whole, comm));

  if (decomposition == Decomposition::kBalanced) {
    // Count what the transfer function shows in my brick; sum over ranks;
    // every rank builds the same balanced tree and fetches its new brick.
    core::ContentGrid content;
    runAgreed(comm, [&] {
      const core::TransferTable table(scene.volumes.front().transfer, scene.sampling.step);
      content = core::countContent(out.brick, table);
    });
    comm.allReduceSum(content.counts);
    runAgreed(comm, [&] { tree = KdTree::buildBalanced(source.grid(), comm.size(), splitAxisRule(decomposition), content); });
    out.brick = Brick();  // release the first brick before reading the second
    out.brick = std::move(*obtainBrick(source, ownedOf, ghostLayers, whole, comm));
  }
  out.tree = std::move(*tree);
  return out;
}

}  // namespace pvr::node
