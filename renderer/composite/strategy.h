// Compositing strategies: one interface, one file per strategy, one table.
//
// Every strategy takes this rank's partial image (the premultiplied RGBA of
// its brick over the brick's screen rectangle), the k-d tree the bricks came
// from, the camera (for front/back at each split) and the communicator, and
// returns the composite of all ranks' images in visibility order: the whole
// frame at the root rank, or this rank's tile of it. Preconditions every
// rank must meet, or the strategy throws on every rank alike or deadlocks:
// the tree has comm.size() ranks, every partial image has the camera's frame
// size, and every rank calls with the same options.
//
// Images travel as sparse runs (encodeImage), cut to the bounding rectangle
// of their non-empty pixels, so empty pixels cost neither bytes nor blending.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "camera.h"
#include "communicator.h"
#include "decompose/kd_tree.h"
#include "image.h"
#include "image_codec.h"

namespace pvr::composite {

// Strategies speak only the communicator interface (renderer/comm).
using comm::Bytes;
using comm::Communicator;
using comm::Outgoing;

enum class FinalImage {
  kGatherAtRoot,  // the root receives every tile and returns the whole frame
  kTiles,         // each rank returns its tile; nothing is gathered
};

struct CompositeOptions {
  FinalImage final = FinalImage::kGatherAtRoot;
  int root = 0;
  core::ImageCodec codec = core::ImageCodec::kAuto;
};

// What one rank did. Compositing messages and gathering messages are kept
// apart, as in Table 1 of the binary-swap paper (comp/comm vs send).
struct CompositeStats {
  std::uint64_t messagesSent = 0;
  std::uint64_t rawBytesSent = 0;      // the pieces sent, as float RGBA rectangles
  std::uint64_t encodedBytesSent = 0;  // what went on the wire
  std::uint64_t pixelsSent = 0;        // pixels of the rectangles sent
  double computeSeconds = 0;           // blending, cutting, encoding, decoding
  double communicationSeconds = 0;     // inside the communicator, waiting included
  std::uint64_t gatherMessagesSent = 0;
  std::uint64_t gatherBytesSent = 0;
  double gatherSeconds = 0;
};

struct CompositeResult {
  core::Image image;     // root: the whole frame (gather); tiles: this rank's tile
  core::PixelRect tile;  // the part of the frame this rank finished; empty if none
  CompositeStats stats;
};

class Strategy {
 public:
  virtual ~Strategy() = default;
  virtual CompositeResult composite(const core::Image& partial, const core::KdTree& tree,
                                    const core::Camera& camera, Communicator& comm,
                                    const CompositeOptions& options) const = 0;
};

// Settings a factory may read; each strategy documents which.
struct StrategyParams {
  int radix = 4;  // radix-k: group size k per round
};

struct StrategyEntry {
  std::string_view name;
  std::string_view summary;
  std::unique_ptr<Strategy> (*make)(const StrategyParams&);
};

// The strategy a session or a batch run uses unless told otherwise.
inline constexpr std::string_view kDefaultStrategy = "binary-swap";

// Every registered strategy (strategies.cpp), in the order to list them.
const std::vector<StrategyEntry>& strategies();
// Throws pvr::Error (kInvalidArgument) naming the known strategies.
std::unique_ptr<Strategy> makeStrategy(std::string_view name, const StrategyParams& params = {});

}  // namespace pvr::composite
