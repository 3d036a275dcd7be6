#include "runtime_settings.h"

#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "strategy.h"

namespace pvr::node {

namespace {

// 1 TiB per rank: more is a typo, not a machine.
constexpr std::int64_t kMaxCacheMegabytes = std::int64_t(1) << 20;

[[noreturn]] void bad(const std::string& key, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, "runtime." + key + ": " + what);
}

std::string text(const nlohmann::json& value, const std::string& key) {
  if (!value.is_string()) bad(key, "must be a string, got " + value.dump());
  return value.get<std::string>();
}

double number(const nlohmann::json& value, const std::string& key) {
  if (!value.is_number()) bad(key, "must be a number, got " + value.dump());
  return value.get<double>();
}

// A value named from a short list; the error lists the names.
template <class T>
T named(const nlohmann::json& value, const std::string& key, const std::vector<std::pair<const char*, T>>& names) {
  const std::string name = text(value, key);
  std::string known;
  for (const auto& [n, v] : names) {
    if (name == n) return v;
    known += (known.empty() ? "" : ", ") + std::string(n);
  }
  bad(key, "unknown value '" + name + "' (known: " + known + ")");
}

}  // namespace

RuntimeSettings settingsFrom(const nlohmann::json& j) {
  if (!j.is_object()) throw Error(ErrorCode::kInvalidArgument, "runtime: must be an object, got " + j.dump());
  RuntimeSettings s;
  for (const auto& [key, value] : j.items()) {
    if (key == "strategy") {
      s.strategy = text(value, key);
      try {
        composite::makeStrategy(s.strategy);
      } catch (const Error& e) {
        bad(key, e.what());  // names the registered strategies
      }
    } else if (key == "decomposition") {
      const std::string name = text(value, key);
      try {
        s.decomposition = decompositionNamed(name);
      } catch (const Error& e) {
        bad(key, e.what());
      }
    } else if (key == "rebalance_threshold") {
      s.rebalanceThreshold = number(value, key);
      if (!(s.rebalanceThreshold >= 1)) bad(key, "must be >= 1, got " + value.dump());
    } else if (key == "pixels") {
      s.format = named<proto::PixelFormat>(value, key, {{"rgb8", proto::PixelFormat::kRgb8},
                                                        {"rgba8", proto::PixelFormat::kRgba8}});
    } else if (key == "compression") {
      s.compression = named<proto::Compression>(value, key, {{"none", proto::Compression::kNone},
                                                             {"rle", proto::Compression::kRle},
                                                             {"zlib", proto::Compression::kZlib}});
    } else if (key == "threads") {
      if (!value.is_number_integer() || value.get<std::int64_t>() < 1 || value.get<std::int64_t>() > 256)
        bad(key, "must be an integer in 1..256, got " + value.dump());
      s.threads = value.get<std::int32_t>();
    } else if (key == "cachemem") {
      if (!value.is_number_integer() || value.get<std::int64_t>() < 0 || value.get<std::int64_t>() > kMaxCacheMegabytes)
        bad(key, "must be an integer number of MB in 0.." + std::to_string(kMaxCacheMegabytes) + ", got " + value.dump());
      s.cacheMegabytes = value.get<std::int32_t>();
    } else {
      bad(key,
          "unknown key (known: strategy, decomposition, rebalance_threshold, pixels, compression, threads, cachemem)");
    }
  }
  return s;
}

}  // namespace pvr::node
