// A gzip-compressed stream inside a file (NRRD gzip encoding, .nii.gz),
// decoded forward on demand.
//
// Memory stays bounded by two small buffers whatever the volume size: a box
// read copies its runs straight out of the decoder and discards the rest, so
// a brick of a gzip volume costs its own size in memory (but the whole
// stream up to the box in time).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "byte_stream.h"

namespace pvr::core {

class GzipStream final : public ByteStream {
 public:
  // The compressed data starts `start` bytes into `path` (after an attached
  // header); concatenated gzip members decode as one stream.
  GzipStream(const std::string& path, std::uint64_t start);
  ~GzipStream() override;

  void read(std::uint64_t offset, std::byte* dst, std::size_t n) override;
  // Decodes to the end of the data; returns the total decoded byte count.
  std::uint64_t decodeToEnd();

 private:
  struct State;
  // Decodes up to n bytes into dst (discarding them when dst is null);
  // returns how many, fewer than n only at the end of the data.
  std::size_t decode(std::byte* dst, std::size_t n);
  void refill();

  std::unique_ptr<State> s_;
};

// The decoded size of the gzip data at `start` in `path`. When the trailer's
// ISIZE (size mod 2^32) agrees with `expected` that is trusted without
// decoding (reading checks the stream again); otherwise the data is decoded
// once to count it exactly, so a message can say what the file holds.
std::uint64_t gzipDecodedSize(const std::string& path, std::uint64_t start, std::uint64_t expected);

}  // namespace pvr::core
