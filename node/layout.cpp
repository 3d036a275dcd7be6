#include "layout.h"

#include <algorithm>
#include <map>

#include "error.h"

namespace pvr::node {

namespace {

[[noreturn]] void bad(const std::string& why) { throw Error(ErrorCode::kInvalidArgument, "layout: " + why); }

}  // namespace

std::string roleName(proto::ClusterRole role) {
  switch (role) {
    case proto::ClusterRole::kRender: return "render";
    case proto::ClusterRole::kComposite: return "composite";
    case proto::ClusterRole::kCollector: return "collector";
    case proto::ClusterRole::kCache: return "cache";
  }
  return "unknown";
}

std::vector<int> Layout::renderClustersOf(int group) const {
  std::vector<int> out;
  for (std::size_t c = 0; c < clusters.size(); ++c)
    if (clusters[c].role == proto::ClusterRole::kRender && clusters[c].group == group) out.push_back(int(c));
  return out;
}

std::vector<proto::ClusterSpec> Layout::specs() const {
  std::vector<proto::ClusterSpec> out;
  if (dedicatedMaster) out.push_back({proto::ClusterRole::kCollector, 1, 0});
  for (const ClusterPlan& c : clusters) out.push_back({c.role, std::uint32_t(c.ranks.size()), c.groupId});
  return out;
}

Layout makeLayout(const std::vector<proto::ClusterSpec>& specsIn, int worldSize) {
  if (worldSize < 1) bad("no ranks");
  std::vector<proto::ClusterSpec> specs = specsIn;
  if (specs.empty()) specs.push_back({proto::ClusterRole::kRender, 0, 0});

  // The collector entry only says whether rank 0 is dedicated.
  Layout layout;
  const auto collectors = std::count_if(specs.begin(), specs.end(),
                                        [](const auto& s) { return s.role == proto::ClusterRole::kCollector; });
  if (collectors > 1) bad("at most one collector cluster");
  for (const auto& s : specs)
    if (s.role == proto::ClusterRole::kCollector && s.ranks > 1) bad("the collector is one rank (rank 0)");
  std::erase_if(specs, [](const auto& s) { return s.role == proto::ClusterRole::kCollector; });
  if (specs.empty()) bad("no render cluster");

  // Sizes: fixed ones first, then equal shares of what is left.
  long long fixed = 0;
  int open = 0;
  for (const auto& s : specs) {
    if (s.ranks > std::uint32_t(worldSize)) bad("a cluster of " + std::to_string(s.ranks) + " ranks in a job of " + std::to_string(worldSize));
    fixed += s.ranks;
    open += s.ranks == 0;
  }
  layout.dedicatedMaster = collectors == 1 || (open == 0 && fixed == worldSize - 1);
  const long long available = worldSize - (layout.dedicatedMaster ? 1 : 0);
  if (fixed > available)
    bad("clusters ask for " + std::to_string(fixed) + " ranks, " + std::to_string(available) + " available");
  if (open == 0 && fixed != available)
    bad("clusters cover " + std::to_string(fixed) + " of " + std::to_string(available) + " ranks");
  const long long left = available - fixed;
  if (open > 0 && left < open) bad(std::to_string(left) + " ranks left for " + std::to_string(open) + " clusters");

  int next = layout.dedicatedMaster ? 1 : 0;
  int opened = 0;
  layout.clusterOfRank.assign(std::size_t(worldSize), -1);
  for (const auto& s : specs) {
    ClusterPlan c;
    c.role = s.role;
    c.groupId = s.group;
    int n = int(s.ranks);
    if (n == 0) n = int(left / open + (opened++ < left % open ? 1 : 0));
    for (int i = 0; i < n; ++i) {
      layout.clusterOfRank[std::size_t(next)] = int(layout.clusters.size());
      c.ranks.push_back(next++);
    }
    layout.clusters.push_back(std::move(c));
  }

  // Groups: render clusters by group id, in order of first appearance.
  std::map<std::uint32_t, int> groupIndex;
  for (auto& c : layout.clusters) {
    if (c.role != proto::ClusterRole::kRender) continue;
    const auto [it, added] = groupIndex.try_emplace(c.groupId, int(groupIndex.size()));
    c.group = it->second;
  }
  if (groupIndex.empty()) bad("no render cluster");
  layout.groups = int(groupIndex.size());
  for (int g = 0; g < layout.groups; ++g) {
    const std::vector<int> members = layout.renderClustersOf(g);
    // The composite and cache clusters of the group's id.
    const auto ofGroup = [&](proto::ClusterRole role) {
      std::vector<int> out;
      for (std::size_t c = 0; c < layout.clusters.size(); ++c)
        if (layout.clusters[c].role == role && layout.clusters[c].groupId == layout.clusters[std::size_t(members[0])].groupId)
          out.push_back(int(c));
      return out;
    };
    const std::vector<int> compositors = ofGroup(proto::ClusterRole::kComposite);
    const std::vector<int> caches = ofGroup(proto::ClusterRole::kCache);
    for (std::size_t b = 0; b < members.size(); ++b) {
      ClusterPlan& r = layout.clusters[std::size_t(members[b])];
      r.band = int(b);
      r.bands = int(members.size());
      if (!compositors.empty()) {
        r.compositor = compositors[b % compositors.size()];
        layout.clusters[std::size_t(r.compositor)].serves.push_back(members[b]);
      }
      if (!caches.empty()) {
        r.cacheCluster = caches[b % caches.size()];
        layout.clusters[std::size_t(r.cacheCluster)].serves.push_back(members[b]);
      }
    }
  }
  for (const auto& c : layout.clusters)
    if ((c.role == proto::ClusterRole::kComposite || c.role == proto::ClusterRole::kCache) && c.serves.empty())
      bad(roleName(c.role) + " cluster of group " + std::to_string(c.groupId) + " has no render cluster to serve");
  return layout;
}

core::PixelRect bandRect(int width, int height, int band, int bands) {
  const auto edge = [&](int b) { return int((long long)height * b / bands); };
  return {0, edge(band), width, edge(band + 1)};
}

}  // namespace pvr::node
