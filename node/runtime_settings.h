// Session settings a client sets through the "runtime" object of a SetScene
// document (docs/runtime.md). The master reads them from the merged object
// and sends them to every rank with the scene (actions::SetScene).
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <tuple>

#include "distribute.h"
#include "pvr_protocol.h"
#include "strategy.h"

namespace pvr::node {

struct RuntimeSettings {
  std::string strategy{composite::kDefaultStrategy};  // self-compositing clusters; a registered strategy
  Decomposition decomposition = Decomposition::kKd;
  double rebalanceThreshold = 1.2;  // max/mean content per rank that triggers a rebalance
  proto::PixelFormat format = proto::PixelFormat::kRgba8;
  proto::Compression compression = proto::Compression::kZlib;
  std::int32_t threads = 1;  // render threads per rank
  // Per render rank, MiB of time steps' bricks the brick cache may hold
  // (brick_cache.h). 256: a few steps of a big series per rank, and a
  // small share of a node's memory even at 8 ranks on one host.
  std::int32_t cacheMegabytes = kDefaultCacheMegabytes;
  static constexpr std::int32_t kDefaultCacheMegabytes = 256;
  static auto fields(auto& self) {
    return std::tie(self.strategy, self.decomposition, self.rebalanceThreshold, self.format, self.compression,
                    self.threads, self.cacheMegabytes);
  }
  bool operator==(const RuntimeSettings&) const = default;
};

// The settings a "runtime" object gives over the defaults. Throws
// pvr::Error (kInvalidArgument) naming the key and what it accepts: an
// unknown key, a wrong type, an unknown strategy (with the registered
// ones), decomposition, pixel format or compression.
RuntimeSettings settingsFrom(const nlohmann::json& runtime);

// settings.cacheMegabytes in bytes (MiB of 2^20 bytes).
constexpr std::uint64_t cacheBudgetBytes(const RuntimeSettings& settings) {
  return std::uint64_t(settings.cacheMegabytes) << 20;
}

}  // namespace pvr::node
