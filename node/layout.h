// The session layout (paper 003, Table 1: set -cluster / -group): which
// world ranks form which cluster, which group each rendering cluster
// belongs to, which scanlines it renders and who composites its images.
//
// Rules, pure functions of the client's ClusterSpec list and the world
// size (tested serially):
//   - ranks are handed out in list order. If the clusters cover every rank,
//     rank 0 (master and collector) is the first rank of the first cluster;
//     if they cover all but one, rank 0 is a dedicated master/collector and
//     clusters start at rank 1. A collector entry (at most one, of at most
//     one rank) asks for the dedicated rank 0.
//   - a cluster of 0 ranks takes an equal share of the ranks left over.
//   - render clusters with the same group id form a group: they split the
//     scanlines of one frame, band b of B in list order. Different groups
//     take different frames of a sequence (frame f goes to group f mod G).
//   - a composite cluster composites for the render clusters of its own
//     group (render cluster j of the group goes to composite cluster
//     j mod C); a group without one composites on its rendering ranks.
//   - a cache cluster reads time steps for the render clusters of its own
//     group the same way (render cluster j to cache cluster j mod M); a
//     group without one reads on its rendering ranks (cache_cluster.h).
#pragma once

#include <string>
#include <vector>

#include "image.h"
#include "pvr_protocol.h"

namespace pvr::node {

struct ClusterPlan {
  proto::ClusterRole role = proto::ClusterRole::kRender;
  std::uint32_t groupId = 0;  // as the client named it
  std::vector<int> ranks;     // world ranks
  // Render clusters: the group's index (0..G-1), band b of B, and the
  // composite and cache clusters serving it (-1: does it itself).
  int group = -1, band = 0, bands = 1, compositor = -1, cacheCluster = -1;
  // Composite and cache clusters: the render clusters it serves, in band order.
  std::vector<int> serves;
};

struct Layout {
  std::vector<ClusterPlan> clusters;
  int groups = 1;
  bool dedicatedMaster = false;  // rank 0 renders and composites nothing
  std::vector<int> clusterOfRank;  // -1: rank 0 when dedicated

  // Render clusters of group g, in band order.
  std::vector<int> renderClustersOf(int group) const;
  // What the client sees: one ClusterSpec per cluster, sizes filled in.
  std::vector<proto::ClusterSpec> specs() const;
};

// Throws pvr::Error (kInvalidArgument) for a layout the ranks cannot hold:
// more ranks asked for than started, a cluster left without ranks, no
// render cluster, a composite cluster without render clusters in its group.
Layout makeLayout(const std::vector<proto::ClusterSpec>& specs, int worldSize);

// Scanlines [y0, y1) of band b of B in a frame `height` rows tall.
core::PixelRect bandRect(int width, int height, int band, int bands);

std::string roleName(proto::ClusterRole role);

}  // namespace pvr::node
