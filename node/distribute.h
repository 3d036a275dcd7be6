// Getting each rank its brick: the decomposition (k-d or content-balanced)
// and the data distribution phase ("dist" of the binary-swap paper's
// Table 1).
//
// When the volume's format reads a box without reading the rest
// (VolumeSource::canReadPartially), every rank reads only its own brick plus
// ghost layers. Otherwise rank 0 reads the volume once and sends each rank
// its brick. Every step that can fail on one rank is followed by an
// agreement, so all ranks fail together with the first failure's message.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <memory>
#include <string_view>
#include <vector>

#include "brick.h"
#include "communicator.h"
#include "decompose/kd_tree.h"
#include "io/volume_io.h"
#include "scene.h"

namespace pvr::node {

enum class Decomposition : std::uint8_t {
  kKd,        // equal cells per rank
  kBalanced,  // equal non-empty content per rank (decompose/content.h)
  kSlabs,     // equal cells per rank in slabs along z: a raw file's bricks
              // are then one run each, held as the file's own pages (no copy)
};
// Action arguments carry a Decomposition (protocol/field_codec.h).
constexpr bool isWireValue(Decomposition d) { return d <= Decomposition::kSlabs; }

// The one list of decompositions and their names, in the order to list
// them: runtime settings, pvr-node --batch, status and reports read it.
struct DecompositionEntry {
  std::string_view name;
  Decomposition value;
};
const std::vector<DecompositionEntry>& decompositions();
std::string_view decompositionName(Decomposition d);
// Throws pvr::Error (kInvalidArgument) naming `name` and the known ones.
Decomposition decompositionNamed(std::string_view name);

// How the k-d trees of a decomposition pick their split axes.
constexpr core::SplitAxisRule splitAxisRule(Decomposition d) {
  return d == Decomposition::kSlabs ? core::SplitAxisRule::kSlowest : core::SplitAxisRule::kAlternating;
}

struct Distribution {
  core::KdTree tree;
  core::Brick brick;             // this rank's owned box plus ghosts
  bool readPartially = false;    // each rank read its own brick (else rank 0 scattered)
  std::uint64_t rootReadBytes = 0;  // bytes rank 0 held at once while scattering (0 if none)
};

// Collective: rank 0 reads the whole volume when its format cannot read a
// box alone (nullopt elsewhere, and everywhere for a partial reader).
std::optional<core::Brick> readWholeOnRoot(const core::VolumeSource& source, comm::Communicator& comm);

// Collective: this rank's brick of `source` owning ownedOf(comm.rank())
// plus `ghostLayers` around it (clipped to the grid): read by the rank
// itself when the format reads a box alone, else cut from `whole` (rank
// 0's, readWholeOnRoot) and sent. ownedOf(r) is the same on every rank; a
// rank whose box is empty gets nullopt and nothing is read or sent for it.
std::optional<core::Brick> obtainBrick(const core::VolumeSource& source,
                                       const std::function<core::NodeBox(int)>& ownedOf, int ghostLayers,
                                       const std::optional<core::Brick>& whole, comm::Communicator& comm);

// Collective: every rank calls with the same arguments. `scene` must be
// resolved (resolveDefaults) for `source`'s grid; it supplies the transfer
// function and step for content balancing.
Distribution distributeBricks(const core::VolumeSource& source, const core::Scene& scene,
                              Decomposition decomposition, int ghostLayers,
                              comm::Communicator& comm);

}  // namespace pvr::node
