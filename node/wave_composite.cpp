#include "wave_composite.h"

#include <chrono>
#include <cstring>
#include <numeric>
#include <span>
#include <vector>

#include "wave_io.h"

namespace pvr::node {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void keepFirst(std::optional<comm::Failure>& first, const std::optional<comm::Failure>& next) {
  if (next && !first) first = next;
}

// A finished band: kept (moved, not copied) if this is the collector, else
// sent to it.
void deliver(NodeState& state, int slot, int band, SubImage&& message, double& comm,
             std::optional<comm::Failure>& failure) {
  if (state.world.rank() == 0) {
    keepFirst(failure, message.failure);
    if (!message.failure) state.bands[{slot, band}] = std::move(message.image);
    return;
  }
  const auto t = Clock::now();
  sendSubImage(state.world, 0, kBandTag, message);
  comm += secondsSince(t);
}

int runOf(int position, int n, int m) {
  // Run j holds positions [j*n/m, (j+1)*n/m).
  int j = 0;
  while (j + 1 < m && (long long)(j + 1) * n / m <= position) ++j;
  return j;
}

void compositeSelf(NodeState& state, int slot, WaveFrame& w, std::optional<comm::Failure>& failure) {
  const ClusterPlan& me = *state.myCluster();
  comm::SubCommunicator& cluster = *state.clusterComm;
  const int width = state.scene.image.width, height = state.scene.image.height;
  composite::CompositeResult result;
  // Without a tree (the cluster's bricks could not be read) every rank of
  // the cluster failed its render alike: there is nothing to composite.
  if (state.tree) {
    try {
      const core::Camera camera(w.camera, width, height);
      const auto strategy = composite::makeStrategy(state.settings.strategy);
      composite::CompositeOptions options;
      options.codec = kSubImageCodec;
      // Strategies want full-frame partials; the band crop keeps them sparse.
      result = strategy->composite(w.partial, *state.tree, camera, cluster, options);
    } catch (...) {
      keepFirst(failure, comm::failureOf(std::current_exception(), state.world.rank()));
    }
  }
  failure = cluster.agree(failure);
  w.comp += result.stats.computeSeconds;
  w.comm += result.stats.communicationSeconds + result.stats.gatherSeconds;
  state.compositeLog.seconds += result.stats.computeSeconds + result.stats.communicationSeconds;
  state.compositeLog.frames += 1;
  state.compositeLog.last = result.stats;
  if (cluster.rank() != 0) return;
  SubImage band{failure, {}};
  if (!failure) band.image = cropToRect(std::move(result.image), bandRect(width, height, me.band, me.bands));
  deliver(state, slot, me.band, std::move(band), w.comm, failure);
}

// A coarse wave's small frame, in a cluster that composites itself: every
// rank sends its sub-image (or its failure) straight to the cluster's rank
// 0, which blends them front to back in visibility order. One message per
// rank and no agreement, where the strategy's rounds, gather and
// agreement would each wait for a rank to be scheduled: with few pixels
// the messages' latency is all the compositing costs. The failure travels
// with the sub-image, as to a composite cluster.
void compositeAtRoot(NodeState& state, int slot, WaveFrame& w, std::optional<comm::Failure>& failure) {
  const ClusterPlan& me = *state.myCluster();
  comm::SubCommunicator& cluster = *state.clusterComm;
  const int width = state.scene.image.width, height = state.scene.image.height;
  if (cluster.rank() != 0) {
    const auto t = Clock::now();
    sendSubImage(cluster, 0, kPartialTag, {failure, failure ? core::Image() : w.partial});
    w.comm += secondsSince(t);
    return;
  }
  // Without a tree (the cluster's bricks could not be read, on all its
  // ranks alike) the identity order keeps the receives matched.
  std::vector<int> order(static_cast<std::size_t>(cluster.size()));
  std::iota(order.begin(), order.end(), 0);
  if (state.tree) {
    try {
      order = state.tree->visibilityOrder(core::Camera(w.camera, width, height));
    } catch (...) {
      keepFirst(failure, comm::failureOf(std::current_exception(), state.world.rank()));
    }
  }
  core::Image acc(width, height, core::PixelRect{});
  for (int r : order) {
    auto t = Clock::now();
    SubImage in = r == 0 ? SubImage{std::nullopt, std::move(w.partial)} : receiveSubImage(cluster, r, kPartialTag);
    w.comm += secondsSince(t);
    t = Clock::now();
    keepFirst(failure, in.failure);
    if (!failure) blendOver(acc, in.image);
    w.comp += secondsSince(t);
  }
  SubImage band{failure, {}};
  if (!failure) band.image = cropToRect(std::move(acc), bandRect(width, height, me.band, me.bands));
  deliver(state, slot, me.band, std::move(band), w.comm, failure);
}

void sendToCompositors(NodeState& state, WaveFrame& w, std::optional<comm::Failure>& failure) {
  const ClusterPlan& me = *state.myCluster();
  const ClusterPlan& comp = state.layout.clusters[std::size_t(me.compositor)];
  comm::SubCommunicator& cluster = *state.clusterComm;
  const int n = cluster.size(), m = int(comp.ranks.size());
  const auto t = Clock::now();
  // The order is a pure function of the tree and camera, the same on every
  // rank of the cluster; without a tree (the cluster's bricks could not be
  // read, on all its ranks alike) the identity order keeps the sends matched.
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  if (state.tree) {
    try {
      order = state.tree->visibilityOrder(core::Camera(w.camera, state.scene.image.width, state.scene.image.height));
    } catch (...) {
      keepFirst(failure, comm::failureOf(std::current_exception(), state.world.rank()));
    }
  }
  if (cluster.rank() == 0) {
    std::vector<std::int32_t> wire(order.begin(), order.end());
    const auto bytes = std::as_bytes(std::span(wire));
    for (int r : comp.ranks) state.world.send(r, kOrderTag, bytes);
  }
  int position = 0;
  while (order[std::size_t(position)] != cluster.rank()) ++position;
  std::uint64_t sent = 0;
  sendSubImage(state.world, comp.ranks[std::size_t(runOf(position, n, m))], kPartialTag,
               {failure, failure ? core::Image() : w.partial}, &sent);
  w.comm += secondsSince(t);
  state.compositeLog.last = {};
  state.compositeLog.last.messagesSent = 1;
  state.compositeLog.last.encodedBytesSent = sent;
}

void compositeServed(NodeState& state, std::optional<comm::Failure>& rankFailure) {
  const ClusterPlan& me = *state.myCluster();
  comm::SubCommunicator& comp = *state.clusterComm;
  const int j = comp.rank(), m = comp.size();
  const int width = state.scene.image.width, height = state.scene.image.height;
  for (int s : me.serves) {
    const ClusterPlan& render = state.layout.clusters[std::size_t(s)];
    if (render.group >= int(state.wave.size())) continue;
    const int slot = render.group;
    WaveFrame& w = state.wave[std::size_t(slot)];
    const int n = int(render.ranks.size());
    // The band's failure: a sub-image's, or this rank's own; a failed rank
    // still receives its run, so no render rank waits on its send.
    std::optional<comm::Failure> failure;
    try {
      state.maybeFail("composite");
    } catch (...) {
      failure = comm::failureOf(std::current_exception(), state.world.rank());
    }
    core::Image acc(width, height, core::PixelRect{});
    // Traffic this rank received and blended: the work on its critical path.
    composite::CompositeStats stats;
    // Receives one sub-image and blends it behind what acc holds.
    auto blendNext = [&](comm::Communicator& from, int rank, int tag) {
      auto start = Clock::now();
      SubImage in = receiveSubImage(from, rank, tag, &stats.encodedBytesSent);
      w.comm += secondsSince(start);
      stats.messagesSent += 1;
      stats.pixelsSent += std::uint64_t(in.image.rect().width()) * std::uint64_t(in.image.rect().height());
      start = Clock::now();
      keepFirst(failure, in.failure);
      if (!failure) blendOver(acc, in.image);
      w.comp += secondsSince(start);
    };

    // My run of the visibility order, blended front to back as it arrives.
    auto t = Clock::now();
    const comm::Bytes orderBytes = state.world.receive(render.ranks[0], kOrderTag);
    std::vector<std::int32_t> order(orderBytes.size() / sizeof(std::int32_t));
    std::memcpy(order.data(), orderBytes.data(), order.size() * sizeof(std::int32_t));
    w.comm += secondsSince(t);
    for (int p = 0; p < n; ++p) {
      if (runOf(p, n, m) != j) continue;
      blendNext(state.world, render.ranks[std::size_t(order[std::size_t(p)])], kPartialTag);
    }

    // Binary tree over the composite ranks: j keeps the front, j + stride
    // sends its (back) result and is done.
    for (int stride = 1; stride < m; stride *= 2) {
      if (j % (2 * stride) == stride) {
        t = Clock::now();
        std::uint64_t sent = 0;
        sendSubImage(comp, j - stride, kTreeTag, {failure, failure ? core::Image() : acc}, &sent);
        w.comm += secondsSince(t);
        break;
      }
      if (j % (2 * stride) == 0 && j + stride < m) blendNext(comp, j + stride, kTreeTag);
    }
    state.compositeLog.seconds += w.comp + w.comm;
    state.compositeLog.frames += 1;
    state.compositeLog.last = stats;
    if (j == 0) {
      SubImage band{failure, {}};
      if (!failure) band.image = cropToRect(std::move(acc), bandRect(width, height, render.band, render.bands));
      deliver(state, slot, render.band, std::move(band), w.comm, failure);
    }
    keepFirst(rankFailure, failure);
  }
}

// The collector takes every band of the wave from whoever finished it.
void receiveBands(NodeState& state, std::optional<comm::Failure>& failure) {
  for (int slot = 0; slot < int(state.wave.size()); ++slot) {
    for (int c : state.layout.renderClustersOf(slot)) {
      const ClusterPlan& render = state.layout.clusters[std::size_t(c)];
      const int sender = render.compositor < 0 ? render.ranks[0]
                                               : state.layout.clusters[std::size_t(render.compositor)].ranks[0];
      if (sender == 0) continue;  // delivered locally
      SubImage in = receiveSubImage(state.world, sender, kBandTag);
      keepFirst(failure, in.failure);
      if (!in.failure) state.bands[{slot, render.band}] = std::move(in.image);
    }
  }
}

}  // namespace

void compositeWave(NodeState& state, bool coarse, std::optional<comm::Failure>& failure) {
  state.bands.clear();
  const ClusterPlan* me = state.myCluster();
  if (me && me->role == proto::ClusterRole::kRender && me->group < int(state.wave.size())) {
    WaveFrame& w = state.wave[std::size_t(me->group)];
    if (me->compositor < 0 && coarse) compositeAtRoot(state, me->group, w, failure);
    else if (me->compositor < 0) compositeSelf(state, me->group, w, failure);
    else sendToCompositors(state, w, failure);
  } else if (me && me->role == proto::ClusterRole::kComposite) {
    compositeServed(state, failure);
  }
  if (state.world.rank() == 0) receiveBands(state, failure);
}

}  // namespace pvr::node
