// Persistent brick summaries: what preprocessing learns of a brick of a raw
// file (value range, macrocell bounds, fine counts; preprocess.h), kept on
// disk so that a rank that has summarised the same brick of the same file
// before reads the summary instead of computing it again.
//
// Off unless the environment variable PVR_SUMMARY_CACHE names a directory
// (created if missing). One file per brick: its name is a hash of the data
// file's path and everything that shapes the brick (encoding, offset, byte
// order, scalar type, grid, owned and stored box); inside it, besides that
// key in full, the data file's identity: device, inode, size, modification
// and status-change times in nanoseconds. A summary is used only when the
// key and the identity both match the file as it is now; a file written
// since, renamed over or touched gets a new summary in the same slot.
//
// A summary is written only when the file's identity did not change while
// the brick was read, and its modification time lies at least
// kRacySeconds in the past: a write within the file system's timestamp
// tick after the read could otherwise leave size and times as they were
// (git's "racily clean" index entries). Failing to read or write a summary
// never fails a read: the brick is preprocessed as without the cache.
#pragma once

#include <optional>
#include <string>

#include "preprocess.h"
#include "raw_reader.h"

namespace pvr::core {

// The environment variable naming the summaries' directory.
inline constexpr const char* kSummaryCacheVariable = "PVR_SUMMARY_CACHE";
// How old a file's modification must be before its summaries are kept.
inline constexpr double kRacySeconds = 2.0;

// A file's identity as stat sees it; equal identities, equal contents
// (barring writes that restore size and both times).
struct FileIdentity {
  std::uint64_t device = 0, inode = 0, size = 0;
  std::int64_t modifiedNs = 0, changedNs = 0;
  bool operator==(const FileIdentity&) const = default;
};

// One brick of one raw file, and where its summary lives; disabled (no
// directory) when PVR_SUMMARY_CACHE is unset or empty, or the file is not
// plain raw data.
class BrickSummaryCache {
 public:
  BrickSummaryCache(const RawLayout& layout, const GridGeometry& grid, ScalarType type, const NodeBox& owned,
                    const NodeBox& stored);
  bool enabled() const { return !path_.empty(); }
  const std::string& path() const { return path_; }

  // The stored summary when it matches the file as it is now (and records
  // the identity seen, for store); nullopt otherwise.
  std::optional<Preprocessed> load();
  // Keeps `p` when the file is unchanged since load() and old enough.
  void store(const Preprocessed& p) const;

 private:
  std::string key_;   // everything that shapes the brick, as text
  std::string path_;  // the summary file; empty when disabled
  std::string dataPath_;
  ScalarType type_;
  NodeBox owned_;
  std::optional<FileIdentity> seen_;  // the file's identity at load()
};

}  // namespace pvr::core
