#include "pieces.h"

#include <algorithm>

namespace pvr::composite {

using core::Image;
using core::PixelRect;
using core::Rgba;

namespace {

constexpr int kGatherTag = 999;

bool nonEmpty(const Rgba& p) { return p.a != 0 || p.r != 0 || p.g != 0 || p.b != 0; }

// front stays where it is: accum = front over accum, inside front's rect
// (accum must cover it).
void compositeOver(Image& accum, const Image& front) {
  const PixelRect r = front.rect();
  for (int y = r.y0; y < r.y1; ++y) {
    Rgba* b = &accum.at(r.x0, y);
    const Rgba* f = front.row(y);
    for (int x = 0; x < r.width(); ++x) {
      const float t = 1.0f - f[x].a;
      b[x].r = f[x].r + t * b[x].r;
      b[x].g = f[x].g + t * b[x].g;
      b[x].b = f[x].b + t * b[x].b;
      b[x].a = f[x].a + t * b[x].a;
    }
  }
}

}  // namespace

PixelRect activeBounds(const Image& image, const PixelRect& within) {
  const PixelRect r = image.rect().intersect(within);
  int x0 = r.x1, x1 = r.x0, y0 = r.y1, y1 = r.y0;
  for (int y = r.y0; y < r.y1; ++y) {
    const Rgba* row = &image.at(r.x0, y);
    int first = -1, last = -1;
    for (int x = 0; x < r.width(); ++x)
      if (nonEmpty(row[x])) {
        if (first < 0) first = x;
        last = x;
      }
    if (first < 0) continue;
    x0 = std::min(x0, r.x0 + first);
    x1 = std::max(x1, r.x0 + last + 1);
    y0 = std::min(y0, y);
    y1 = y + 1;
  }
  if (x1 <= x0 || y1 <= y0) return {};
  return {x0, y0, x1, y1};
}

Image cropped(const Image& image, const PixelRect& rect) {
  Image out(image.frameWidth(), image.frameHeight(), image.rect().intersect(rect));
  const PixelRect r = out.rect();
  for (int y = r.y0; y < r.y1; ++y) std::copy_n(&image.at(r.x0, y), r.width(), out.row(y));
  return out;
}

void blend(Image& accum, const Image& other, bool otherInFront) {
  if (other.rect().empty()) return;
  const PixelRect united = accum.rect().unite(other.rect());
  if (united != accum.rect() || accum.frameWidth() != other.frameWidth()) {
    Image grown(other.frameWidth(), other.frameHeight(), united);
    const PixelRect r = accum.rect();
    for (int y = r.y0; y < r.y1; ++y) std::copy_n(accum.row(y), r.width(), &grown.at(r.x0, y));
    accum = std::move(grown);
  }
  if (otherInFront)
    compositeOver(accum, other);
  else
    core::compositeUnder(accum, other);
}

Bytes PieceChannel::encode(const Image& image, const PixelRect& region) {
  const PixelRect bounds = activeBounds(image, region);
  core::EncodedImage code = core::encodeImage(image, bounds, codec_);
  ++stats_.messagesSent;
  stats_.rawBytesSent += code.rawBytes;
  stats_.encodedBytesSent += code.bytes.size();
  stats_.pixelsSent += std::uint64_t(bounds.width()) * std::uint64_t(bounds.height());
  return std::move(code.bytes);
}

Image PieceChannel::decode(std::span<const std::byte> bytes) {
  return core::decodeImage(bytes);
}

void PieceChannel::send(int to, int tag, const Image& image, const PixelRect& region) {
  Stopwatch compute;
  const Bytes code = encode(image, region);
  stats_.computeSeconds += compute.seconds();
  Stopwatch wire;
  comm_.send(to, tag, code);
  stats_.communicationSeconds += wire.seconds();
}

Image PieceChannel::receive(int from, int tag) {
  Stopwatch wire;
  const Bytes code = comm_.receive(from, tag);
  stats_.communicationSeconds += wire.seconds();
  Stopwatch compute;
  Image piece = decode(code);
  stats_.computeSeconds += compute.seconds();
  return piece;
}

Image PieceChannel::swap(int partner, int tag, const Image& image, const PixelRect& give) {
  Stopwatch compute;
  const Bytes code = encode(image, give);
  stats_.computeSeconds += compute.seconds();
  Stopwatch wire;
  const Bytes received = comm_.sendReceive(partner, code, partner, tag);
  stats_.communicationSeconds += wire.seconds();
  Stopwatch decodeTime;
  Image piece = decode(received);
  stats_.computeSeconds += decodeTime.seconds();
  return piece;
}

std::vector<Image> PieceChannel::exchange(int tag, const Image& image,
                                          const std::vector<std::pair<int, PixelRect>>& gives,
                                          const std::vector<int>& from) {
  Stopwatch compute;
  std::vector<Bytes> codes;
  codes.reserve(gives.size());
  for (const auto& [to, region] : gives) codes.push_back(encode(image, region));
  std::vector<Outgoing> sends;
  for (std::size_t i = 0; i < gives.size(); ++i) sends.push_back({gives[i].first, codes[i]});
  stats_.computeSeconds += compute.seconds();
  Stopwatch wire;
  const std::vector<Bytes> received = comm_.exchange(sends, from, tag);
  stats_.communicationSeconds += wire.seconds();
  Stopwatch decodeTime;
  std::vector<Image> pieces;
  pieces.reserve(received.size());
  for (const Bytes& code : received) pieces.push_back(decode(code));
  stats_.computeSeconds += decodeTime.seconds();
  return pieces;
}

bool runReduceSteps(PieceChannel& channel, Image& mine, const std::vector<ReduceStep>& steps,
                    const core::KdTree& tree, const core::Camera& camera, int tag) {
  const PixelRect frame{0, 0, camera.width(), camera.height()};
  for (const ReduceStep& step : steps) {
    if (step.send) {
      channel.send(step.partner, tag, mine, frame);
      mine = Image(camera.width(), camera.height(), {});
      return false;
    }
    // The piece comes from the right subtree; it is in front when the left is not.
    const Image piece = channel.receive(step.partner, tag);
    Stopwatch compute;
    blend(mine, piece, !tree.leftInFront(step.node, camera));
    channel.stats().computeSeconds += compute.seconds();
  }
  return true;
}

CompositeResult finishComposite(PieceChannel& channel, Image mine, const PixelRect& tile,
                                const std::vector<int>& owners, const core::Camera& camera,
                                const CompositeOptions& options) {
  CompositeResult result;
  result.tile = tile;
  Communicator& comm = channel.comm();
  if (options.final == FinalImage::kTiles) {
    result.image = tile.empty() ? Image(camera.width(), camera.height(), {}) : cropped(mine, tile);
    result.stats = channel.stats();
    return result;
  }
  // Gather: owners send their tiles to the root, which pastes them into the frame.
  Stopwatch gather;
  CompositeStats& stats = channel.stats();
  const bool owner = std::find(owners.begin(), owners.end(), comm.rank()) != owners.end();
  if (comm.rank() != options.root && owner) {
    const core::EncodedImage code =
        core::encodeImage(mine, activeBounds(mine, tile), options.codec);
    comm.send(options.root, kGatherTag, code.bytes);
    ++stats.gatherMessagesSent;
    stats.gatherBytesSent += code.bytes.size();
  }
  if (comm.rank() == options.root) {
    Image frame = Image::fullFrame(camera.width(), camera.height());
    auto paste = [&frame](const Image& piece) {
      const PixelRect r = piece.rect();
      for (int y = r.y0; y < r.y1; ++y) std::copy_n(piece.row(y), r.width(), frame.row(y) + r.x0);
    };
    for (int r : owners) {
      if (r == options.root)
        paste(cropped(mine, tile));
      else
        paste(core::decodeImage(comm.receive(r, kGatherTag)));
    }
    result.image = std::move(frame);
  } else {
    result.image = Image(camera.width(), camera.height(), {});
  }
  stats.gatherSeconds += gather.seconds();
  result.stats = stats;
  return result;
}

void checkCompositeCall(const core::KdTree& tree, const Communicator& comm,
                        const CompositeOptions& options) {
  if (tree.rankCount() != comm.size())
    throw Error(ErrorCode::kInternal, "composite: the k-d tree has " + std::to_string(tree.rankCount()) +
                                          " ranks, the communicator " + std::to_string(comm.size()));
  if (options.root < 0 || options.root >= comm.size())
    throw Error(ErrorCode::kInvalidArgument, "composite: root rank " + std::to_string(options.root) +
                                                 " outside 0.." + std::to_string(comm.size() - 1));
}

}  // namespace pvr::composite
